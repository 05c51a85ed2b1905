// Candidate fusion (large_motion.hpp): each pixel keeps its flow or takes a neighbour's.
#include <algorithm>
#include <cstddef>
#include <limits>
#include <string>
#include <vector>

#include "core/error.hpp"
#include "flow/large_motion.hpp"
#include "flow/window_cost.hpp"

namespace roiflow::flow {

namespace {

// Row y of the candidate field "the flow `(ox, oy)` pixels away" (clamped at the edges).
void shifted_row(const cv::Mat& plane, int y, int ox, int oy, float* out) {
  const int w = plane.cols;
  const float* in = plane.ptr<float>(std::clamp(y + oy, 0, plane.rows - 1));
  const int lo = std::clamp(-ox, 0, w), hi = std::clamp(w - ox, 0, w);  // x + ox in [0, w)
  std::fill(out, out + lo, in[0]);
  if (hi > lo) std::copy(in + lo + ox, in + hi + ox, out + lo);
  std::fill(out + std::max(lo, hi), out + w, in[w - 1]);
}

}  // namespace

void fuse_candidates(const cv::Mat& i0, const cv::Mat& i1, int step, int window, cv::Mat& u,
                     cv::Mat& v) {
  if (i0.empty() || i0.type() != CV_32FC1 || i1.type() != CV_32FC1 || i1.size() != i0.size() ||
      u.type() != CV_32FC1 || v.type() != CV_32FC1 || u.size() != i0.size() ||
      v.size() != i0.size()) {
    throw Error("candidate fusion: images and flow must be non-empty CV_32FC1 of one size");
  }
  if (step < 1 || window < 3 || window > 15 || window % 2 == 0) {
    throw Error("candidate fusion: step must be >= 1 and the window odd in 3..15, got step " +
                std::to_string(step) + ", window " + std::to_string(window));
  }
  const int w = i0.cols;
  const cv::Mat u0 = u.clone(), v0 = v.clone();
  std::vector<float> best(static_cast<std::size_t>(w) * i0.rows,
                          std::numeric_limits<float>::infinity());
  std::vector<float> cu(w), cv_(w), cost_row;
  detail::StreamingZssd z(w, i0.rows, window);
  // The pixel's own flow first: a tie keeps it.
  constexpr int kOffsets[9][2] = {{0, 0},   {-1, 0}, {1, 0},  {0, -1}, {0, 1},
                                  {-1, -1}, {1, -1}, {-1, 1}, {1, 1}};
  for (const auto& o : kOffsets) {
    // The candidate field: the flow of the pixel `step` away in direction o.
    const int ox = o[0] * step, oy = o[1] * step;
    const auto fill = [&](int y, float* d) {
      shifted_row(u0, y, ox, oy, cu.data());
      shifted_row(v0, y, ox, oy, cv_.data());
      detail::warp_difference_row(i1, i0.ptr<float>(y), y, w, cu.data(), cv_.data(), d);
    };
    const auto use = [&](int y, const float* __restrict c) {
      shifted_row(u0, y, ox, oy, cu.data());
      shifted_row(v0, y, ox, oy, cv_.data());
      const float* __restrict su = cu.data();
      const float* __restrict sv = cv_.data();
      float* __restrict b = best.data() + static_cast<std::size_t>(y) * w;
      float* __restrict pu = u.ptr<float>(y);
      float* __restrict pv = v.ptr<float>(y);
      for (int x = 0; x < w; ++x) {
        const bool better = c[x] < b[x];
        b[x] = better ? c[x] : b[x];
        pu[x] = better ? su[x] : pu[x];
        pv[x] = better ? sv[x] : pv[x];
      }
    };
    detail::for_each_cost_row(z, fill, use, cost_row);
  }
}

}  // namespace roiflow::flow
