// Optimal assignment for rectangular cost matrices with a gate: the pairing of rows to columns,
// each used at most once, that first holds as many allowed pairs as possible (a pair is allowed
// when its cost is finite and not above `max_cost`) and then has the smallest total cost among
// those. It is how py-motmetrics matches ground truth to hypotheses and how a tracker assigns
// detections to tracks without going greedy. Hungarian method with potentials, O(n^2 m) for
// n = min(rows, cols), m = max(rows, cols). To maximise weights, pass them negated, no gate.
//
//   const std::vector<double> cost = {0.1, 0.9,   // rows: tracks, cols: detections (1 - IoU)
//                                     0.8, 0.2};
//   const roiflow::Assignment a = roiflow::solve_assignment(cost, 2, 2, /*max_cost=*/0.7);
//   std::cout << a.row_to_col[0] << " " << a.row_to_col[1] << "\n";  // 0 1
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
