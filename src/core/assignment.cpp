#include "core/assignment.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "core/error.hpp"

namespace roiflow {
namespace {

constexpr double kLargestCost = 1e150;

bool allowed(double c, double max_cost) {
  return std::isfinite(c) && c <= max_cost;
}

// Hungarian method with potentials on an n x m matrix, n <= m, every pair usable. Returns, per
// row, its column. `a(i, j)` reads row i, column j (0-based).
template <class Cost>
std::vector<int> hungarian(int n, int m, const Cost& a) {
  const double inf = std::numeric_limits<double>::infinity();
  std::vector<double> u(n + 1, 0.0), v(m + 1, 0.0), minv(m + 1);
  std::vector<int> p(m + 1, 0), way(m + 1, 0);
  std::vector<char> used(m + 1);
  for (int i = 1; i <= n; ++i) {
    p[0] = i;
    int j0 = 0;
    std::fill(minv.begin(), minv.end(), inf);
    std::fill(used.begin(), used.end(), 0);
    do {
      used[j0] = 1;
      const int i0 = p[j0];
      double delta = inf;
      int j1 = 0;
      for (int j = 1; j <= m; ++j) {
        if (used[j]) continue;
        const double cur = a(i0 - 1, j - 1) - u[i0] - v[j];
        if (cur < minv[j]) {
          minv[j] = cur;
          way[j] = j0;
        }
        if (minv[j] < delta) {
          delta = minv[j];
          j1 = j;
        }
      }
      for (int j = 0; j <= m; ++j) {
        if (used[j]) {
          u[p[j]] += delta;
          v[j] -= delta;
        } else {
          minv[j] -= delta;
        }
      }
      j0 = j1;
    } while (p[j0] != 0);
    do {
      const int j1 = way[j0];
      p[j0] = p[j1];
      j0 = j1;
    } while (j0 != 0);
  }
  std::vector<int> row_to_col(n, -1);
  for (int j = 1; j <= m; ++j) {
    if (p[j] != 0) row_to_col[p[j] - 1] = j - 1;
  }
  return row_to_col;
}

}  // namespace

Assignment solve_assignment(std::span<const double> cost, int rows, int cols, double max_cost) {
  if (rows < 0 || cols < 0) {
    throw Error("assignment: negative size " + std::to_string(rows) + " x " + std::to_string(cols));
  }
  if (cost.size() != static_cast<std::size_t>(rows) * static_cast<std::size_t>(cols)) {
    throw Error("assignment: " + std::to_string(cost.size()) + " costs for a " +
                std::to_string(rows) + " x " + std::to_string(cols) + " matrix");
  }
  Assignment result;
  result.row_to_col.assign(rows, -1);
  result.col_to_row.assign(cols, -1);

  double largest = 0;
  bool any_allowed = false;
  bool all_allowed = true;
  for (double c : cost) {
    if (allowed(c, max_cost)) {
      any_allowed = true;
      largest = std::max(largest, std::abs(c));
    } else {
      all_allowed = false;
    }
  }
  if (!any_allowed) return result;
  if (largest > kLargestCost) {
    throw Error("assignment: cost magnitude beyond 1e150");
  }
  // A pair not allowed costs more than any pairing of allowed pairs could save: with at most
  // k = min(rows, cols) pairs, each within [-c, c], swapping one gated pair for allowed ones
  // changes the total by less than 2kc + 1 (py-motmetrics' lap.add_expensive_edges).
  const int k = std::min(rows, cols);
  const double c = largest + 1;
  const double gated = all_allowed ? 0 : 2.0 * k * c + 1;
  const bool transpose = rows > cols;
  auto at = [&](int r, int col) {
    const double v = cost[static_cast<std::size_t>(r) * cols + col];
    return allowed(v, max_cost) ? v : gated;
  };
  std::vector<int> match;
  if (transpose) {
    match = hungarian(cols, rows, [&](int i, int j) { return at(j, i); });
  } else {
    match = hungarian(rows, cols, at);
  }
  for (int i = 0; i < static_cast<int>(match.size()); ++i) {
    const int j = match[i];
    if (j < 0) continue;
    const int r = transpose ? j : i;
    const int col = transpose ? i : j;
    const double v = cost[static_cast<std::size_t>(r) * cols + col];
    if (!allowed(v, max_cost)) continue;
    result.row_to_col[r] = col;
    result.col_to_row[col] = r;
    ++result.pairs;
    result.cost += v;
  }
  return result;
}

}  // namespace roiflow
