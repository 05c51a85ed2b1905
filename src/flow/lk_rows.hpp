// Row kernels of dense LK (internal to roiflow::flow): the warp of frame t+1 along one row, the
// derivative products of one row entering the vertical window sums, the prefix scan that turns
// column sums into horizontal window sums, and the regularised 2x2 solve of one row. Each works
// on raw float rows, so the level iteration (lk_level.hpp) streams rows through them with a
// working set of a few rows.
//
//   WarpedRow r;  // m, d: w + 2 floats (one replicated column each side)
//   warp_row(i1, i0_row, x0, y, w, u_row, v_row, r.m.data() + 1, r.d.data() + 1);
#pragma once

#include <cstddef>
#include <opencv2/core.hpp>
#include <vector>

#include "flow/dense_lk.hpp"

namespace roiflow::flow::detail {

inline constexpr int kChannels = 5;  // gxx, gxy, gyy, bx, by

// One row of the computed rectangle after the warp: the mean image m = (I0 + I1w) / 2 and the
// difference d = I1w - I0, padded by one replicated column on each side, and the flow it was
// warped with.
struct WarpedRow {
  int row = -1;
  std::vector<float> m, d;
  const float* u = nullptr;  // the row's current flow, not padded
  const float* v = nullptr;
};

// Frame t+1 (`i1`, a whole level) sampled bilinearly at (x0 + x + u[x], y + v[x]) for x < w
// (border replicated), written as m[x] = (i0[x] + I1w) / 2 and d[x] = I1w - i0[x].
void warp_row(const cv::Mat& i1, const float* __restrict i0, int x0, int y, int w,
              const float* __restrict u, const float* __restrict v, float* __restrict m,
              float* __restrict d);

// The five window terms Ix², IxIy, Iy², Ix·r, Iy·r (r = Ix·ū + Iy·v̄ − It, weighted by the Cauchy
// weight of It when inv_s2 > 0) of one derivative-grid row from the warped rows around it
// (Horn–Schunck reads `centre` and `down`, the grid stencils all three). They are stored in
// `ring` (kChannels rows of w) and added to the vertical sums `acc`; with `leaving`, the values
// `ring` held before (the row that leaves the window) are subtracted first.
void row_window_terms(Derivative derivative, const WarpedRow& up, const WarpedRow& centre,
                      const WarpedRow& down, int w, float inv_s2, bool leaving, float* ring,
                      float* acc);

// Inclusive prefix sums of the kChannels rows in[c * in_stride + i], i < n, into
// out[c * out_stride + i].
void prefix_scan(const float* __restrict in, int in_stride, int n, float* __restrict out,
                 std::size_t out_stride);

// Everything the per-row solve needs: prefix sums (padded, see RowIterator) from which each
// window sum is one difference, the half-weight end columns when the window has them, and
// the window weights.
struct WindowSolve {
  int w;
  const float* prefix;
  std::size_t prefix_stride;
  const float* columns;  // non-null: subtract half of the end columns (zero-padded)
  int column_stride;
  int lo, hi;
  const float* inv_cx;
  float inv_cy;
  float lambda;
};

// The regularised 2x2 solve of one row: (G + lambda I) w = b + lambda w_old, with G and b the
// window means; the smallest eigenvalue of G into `confidence` when it is not null.
void solve_pixels(const WindowSolve& ws, const float* uo, const float* vo, float* un, float* vn,
                  float* confidence);

}  // namespace roiflow::flow::detail
