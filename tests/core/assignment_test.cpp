#include "core/assignment.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "test_util.hpp"

namespace {

using namespace roiflow;

constexpr double kInf = std::numeric_limits<double>::infinity();

struct Best {
  int pairs = 0;
  double cost = 0;
};

// Every partial matching of rows to columns: the most allowed pairs, then the least cost.
void brute_force(const std::vector<double>& cost, int rows, int cols, double max_cost, int row,
                 std::vector<char>& used, int pairs, double total, Best& best) {
  if (row == rows) {
    if (pairs > best.pairs || (pairs == best.pairs && total < best.cost - 1e-12)) {
      best = {pairs, total};
    }
    return;
  }
  brute_force(cost, rows, cols, max_cost, row + 1, used, pairs, total, best);
  for (int c = 0; c < cols; ++c) {
    const double v = cost[row * cols + c];
    if (used[c] || !std::isfinite(v) || v > max_cost) continue;
    used[c] = 1;
    brute_force(cost, rows, cols, max_cost, row + 1, used, pairs + 1, total + v, best);
    used[c] = 0;
  }
}

void expect_consistent(const Assignment& a, const std::vector<double>& cost, int rows, int cols,
                       double max_cost) {
  ASSERT_EQ(a.row_to_col.size(), static_cast<std::size_t>(rows));
  ASSERT_EQ(a.col_to_row.size(), static_cast<std::size_t>(cols));
  int pairs = 0;
  double total = 0;
  for (int r = 0; r < rows; ++r) {
    const int c = a.row_to_col[r];
    if (c < 0) continue;
    ASSERT_LT(c, cols);
    EXPECT_EQ(a.col_to_row[c], r);
    const double v = cost[r * cols + c];
    EXPECT_TRUE(std::isfinite(v) && v <= max_cost) << "gated pair " << r << "," << c;
    ++pairs;
    total += v;
  }
  for (int c = 0; c < cols; ++c) {
    if (a.col_to_row[c] >= 0) {
      EXPECT_EQ(a.row_to_col[a.col_to_row[c]], c);
    }
  }
  EXPECT_EQ(a.pairs, pairs);
  EXPECT_NEAR(a.cost, total, 1e-9);
}

TEST(Assignment, MatchesBruteForceOnRandomMatrices) {
  std::mt19937 rng(17);
  std::uniform_int_distribution<int> size(0, 6);
  std::uniform_real_distribution<double> value(-5.0, 10.0);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  int checked_gated = 0;
  for (int trial = 0; trial < 3000; ++trial) {
    const int rows = size(rng);
    const int cols = size(rng);
    const double gate_share = unit(rng) * 0.7;
    std::vector<double> cost(static_cast<std::size_t>(rows) * cols);
    for (double& v : cost) {
      v = value(rng);
      if (trial % 3 == 0) v = std::round(v);  // ties
      if (unit(rng) < gate_share) v = (trial % 2 == 0) ? kInf : std::nan("");
    }
    const double max_cost = (trial % 4 == 0) ? 4.0 : kInf;
    const Assignment a = solve_assignment(cost, rows, cols, max_cost);
    expect_consistent(a, cost, rows, cols, max_cost);
    std::vector<char> used(cols, 0);
    Best best;
    brute_force(cost, rows, cols, max_cost, 0, used, 0, 0.0, best);
    ASSERT_EQ(a.pairs, best.pairs) << "trial " << trial << " " << rows << "x" << cols;
    ASSERT_NEAR(a.cost, best.cost, 1e-9) << "trial " << trial << " " << rows << "x" << cols;
    if (best.pairs < std::min(rows, cols)) ++checked_gated;
  }
  EXPECT_GT(checked_gated, 100);  // the gate mattered in many trials
}

TEST(Assignment, PrefersMorePairsOverLowerCost) {
  // Row 0 alone would take column 0 (cost 0); taking column 1 lets row 1 have column 0.
  const std::vector<double> cost = {0.0, 0.9, 0.8, kInf};
  const Assignment a = solve_assignment(cost, 2, 2);
  EXPECT_EQ(a.pairs, 2);
  EXPECT_EQ(a.row_to_col[0], 1);
  EXPECT_EQ(a.row_to_col[1], 0);
  EXPECT_NEAR(a.cost, 1.7, 1e-12);
}

TEST(Assignment, GateLeavesRowsAndColumnsFree) {
  // 3 tracks x 2 detections; track 1 is too far from both.
  const std::vector<double> cost = {0.1, 0.9, 0.95, 0.99, 0.8, 0.2};
  const Assignment a = solve_assignment(cost, 3, 2, 0.5);
  EXPECT_EQ(a.pairs, 2);
  EXPECT_EQ(a.row_to_col, (std::vector<int>{0, -1, 1}));
  EXPECT_EQ(a.col_to_row, (std::vector<int>{0, 2}));
}

TEST(Assignment, MaximisesWeightWithNegatedCostsAndNoGate) {
  // gt A overlaps h0 in 100 frames and h1 in 1; gt B overlaps h0 in 1. The largest total is
  // A-h0 alone (100), not the two pairs A-h1, B-h0 (2).
  const std::vector<double> cost = {-100, -1, -1, 0};
  const Assignment a = solve_assignment(cost, 2, 2);
  EXPECT_EQ(a.row_to_col[0], 0);
  EXPECT_DOUBLE_EQ(a.cost, -100);
}

TEST(Assignment, EmptyAndAllGated) {
  EXPECT_EQ(solve_assignment({}, 0, 5).pairs, 0);
  EXPECT_EQ(solve_assignment({}, 4, 0).row_to_col, (std::vector<int>(4, -1)));
  const std::vector<double> gated = {kInf, std::nan(""), 3.0, 7.0};
  const Assignment a = solve_assignment(gated, 2, 2, 1.0);
  EXPECT_EQ(a.pairs, 0);
  EXPECT_EQ(a.row_to_col, (std::vector<int>{-1, -1}));
}

TEST(Assignment, RejectsBadSizes) {
  const std::vector<double> cost(5, 1.0);
  EXPECT_NE(test::error_message([&] { solve_assignment(cost, 2, 3); }).find("5 costs"),
            std::string::npos);
  EXPECT_NE(test::error_message([&] { solve_assignment(cost, -1, 3); }).find("negative"),
            std::string::npos);
  const std::vector<double> huge = {1e200};
  EXPECT_NE(test::error_message([&] { solve_assignment(huge, 1, 1); }).find("1e150"),
            std::string::npos);
}

}  // namespace
