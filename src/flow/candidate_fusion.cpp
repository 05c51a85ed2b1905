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
                     cv::Mat& v, const Executor* executor, std::vector<float>* scratch) {
  if (i0.empty() || i0.type() != CV_32FC1 || i1.type() != CV_32FC1 || i1.size() != i0.size() ||
      u.type() != CV_32FC1 || v.type() != CV_32FC1 || u.size() != i0.size() ||
      v.size() != i0.size()) {
    throw Error("candidate fusion: images and flow must be non-empty CV_32FC1 of one size");
  }
  if (step < 1 || window < 3 || window > 15 || window % 2 == 0) {
    throw Error("candidate fusion: step must be >= 1 and the window odd in 3..15, got step " +
                std::to_string(step) + ", window " + std::to_string(window));
  }
  const int w = i0.cols, h = i0.rows;
  const cv::Mat u0 = u.clone(), v0 = v.clone();
  // The pixel's own flow first: a tie keeps it.
  constexpr int kCandidates = 9;
  constexpr int kOffsets[kCandidates][2] = {{0, 0},   {-1, 0}, {1, 0},  {0, -1}, {0, 1},
                                            {-1, -1}, {1, -1}, {-1, 1}, {1, 1}};
  // The candidate field k: the flow of the pixel `step` away in direction kOffsets[k]; its
  // window costs stream through `z` row by row into use(y, cost).
  const auto stream = [&](int k, detail::StreamingZssd& z, std::vector<float>& cu,
                          std::vector<float>& cv_, std::vector<float>& cost_row, auto&& use) {
    const int ox = kOffsets[k][0] * step, oy = kOffsets[k][1] * step;
    const auto fill = [&](int y, float* d) {
      shifted_row(u0, y, ox, oy, cu.data());
      shifted_row(v0, y, ox, oy, cv_.data());
      detail::warp_difference_row(i1, i0.ptr<float>(y), y, w, cu.data(), cv_.data(), d);
    };
    detail::for_each_cost_row(z, fill, use, cost_row);
  };
  // Row y of the fold: each candidate replaces the kept one where its cost is smaller.
  const auto keep_better = [&](int k, int y, const float* __restrict c, float* __restrict b,
                               std::vector<float>& cu, std::vector<float>& cv_) {
    const int ox = kOffsets[k][0] * step, oy = kOffsets[k][1] * step;
    shifted_row(u0, y, ox, oy, cu.data());
    shifted_row(v0, y, ox, oy, cv_.data());
    const float* __restrict su = cu.data();
    const float* __restrict sv = cv_.data();
    float* __restrict pu = u.ptr<float>(y);
    float* __restrict pv = v.ptr<float>(y);
    for (int x = 0; x < w; ++x) {
      const bool better = c[x] < b[x];
      b[x] = better ? c[x] : b[x];
      pu[x] = better ? su[x] : pu[x];
      pv[x] = better ? sv[x] : pv[x];
    }
  };
  const std::size_t plane = static_cast<std::size_t>(w) * h;
  if (!executor || executor->concurrency() < 2) {
    std::vector<float> best(plane, std::numeric_limits<float>::infinity());
    std::vector<float> cu(w), cv_(w), cost_row;
    detail::StreamingZssd z(w, h, window);
    for (int k = 0; k < kCandidates; ++k) {
      stream(k, z, cu, cv_, cost_row, [&](int y, const float* c) {
        keep_better(k, y, c, best.data() + static_cast<std::size_t>(y) * w, cu, cv_);
      });
    }
    return;
  }
  // With threads: every candidate's costs side by side (each streams over all rows, as above),
  // then the rows folded in the same candidate order, so the result is the one-thread result.
  std::vector<float> local;
  std::vector<float>& kept = scratch ? *scratch : local;
  if (kept.size() < plane * kCandidates) kept.resize(plane * kCandidates);
  float* const costs = kept.data();
  executor->for_range(0, kCandidates, 1, [&](int k0, int k1) {
    std::vector<float> cu(w), cv_(w), cost_row;
    detail::StreamingZssd z(w, h, window);
    for (int k = k0; k < k1; ++k) {
      float* out = costs + plane * k;
      stream(k, z, cu, cv_, cost_row, [&](int y, const float* c) {
        std::copy_n(c, w, out + static_cast<std::size_t>(y) * w);
      });
    }
  });
  executor->for_range(0, h, 16, [&](int y0, int y1) {
    std::vector<float> cu(w), cv_(w), best(w);
    for (int y = y0; y < y1; ++y) {
      std::fill(best.begin(), best.end(), std::numeric_limits<float>::infinity());
      for (int k = 0; k < kCandidates; ++k) {
        const float* c = costs + plane * k + static_cast<std::size_t>(y) * w;
        keep_better(k, y, c, best.data(), cu, cv_);
      }
    }
  });
}

}  // namespace roiflow::flow
