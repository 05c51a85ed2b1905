// Optimal assignment (the linear assignment problem) for rectangular cost matrices with a gate:
// the pairing of rows to columns, each used at most once, that first holds as many allowed
// pairs as possible and then has the smallest total cost among those. A pair is allowed when
// its cost is finite and not above `max_cost`. This is how py-motmetrics matches ground truth
// to hypotheses (scipy's linear_sum_assignment after replacing the gated pairs by a cost so
// large that no optimum uses one while an allowed pairing exists) and how a tracker assigns
// detections to predicted tracks without going greedy. The solver is the shortest augmenting
// path form of the Hungarian method (Kuhn-Munkres with potentials, as Jonker-Volgenant
// arrange it): O(n^2 m) for n = min(rows, cols), m = max(rows, cols).
//
//   // rows: tracks, cols: detections; cost = 1 - IoU, pairs under IoU 0.3 not allowed
//   std::vector<double> cost(tracks * detections);
//   ...
//   const roiflow::Assignment a = roiflow::solve_assignment(cost, tracks, detections, 0.7);
//   for (int t = 0; t < tracks; ++t)
//     if (a.row_to_col[t] >= 0) { /* track t takes detection a.row_to_col[t] */ }
//
// To maximise a total weight instead (every pair allowed, zero weight meaning "no gain"),
// pass the negated weights and no gate: with every pair allowed the most pairs is always
// min(rows, cols), so only the total counts.
#pragma once

#include <limits>
#include <span>
#include <vector>

namespace roiflow {

struct Assignment {
  std::vector<int> row_to_col;  // per row, its column or -1
  std::vector<int> col_to_row;  // per column, its row or -1
  int pairs = 0;                // allowed pairs made
  double cost = 0;              // sum of their costs
};

// `cost` holds rows * cols values, row-major. Throws roiflow::Error when the sizes disagree or
// are negative, or when an allowed cost is so large (beyond 1e150 in magnitude) that the gate
// could not be represented. NaN and infinities mark pairs not allowed. Ties are broken
// deterministically (the same input gives the same answer).
Assignment solve_assignment(std::span<const double> cost, int rows, int cols,
                            double max_cost = std::numeric_limits<double>::infinity());

}  // namespace roiflow
