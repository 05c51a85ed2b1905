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
  const int w = i0.cols, h = i0.rows;
  const cv::Mat u0 = u.clone(), v0 = v.clone();
  cv::Mat cu(h, w, CV_32F), cv_(h, w, CV_32F);
  std::vector<float> best(static_cast<std::size_t>(w) * h, std::numeric_limits<float>::infinity());
  std::vector<float> cost;
  detail::FieldCost field_cost(w, h, window);
  // The pixel's own flow first: a tie keeps it.
  constexpr int kOffsets[9][2] = {{0, 0},   {-1, 0}, {1, 0},  {0, -1}, {0, 1},
                                  {-1, -1}, {1, -1}, {-1, 1}, {1, 1}};
  for (const auto& o : kOffsets) {
    // Candidate field: the flow of the pixel `step` away in direction o (clamped at the edge).
    const int ox = o[0] * step, oy = o[1] * step;
    for (int y = 0; y < h; ++y) {
      const float* su = u0.ptr<float>(std::clamp(y + oy, 0, h - 1));
      const float* sv = v0.ptr<float>(std::clamp(y + oy, 0, h - 1));
      float* pu = cu.ptr<float>(y);
      float* pv = cv_.ptr<float>(y);
      for (int x = 0; x < w; ++x) {
        const int sx = std::clamp(x + ox, 0, w - 1);
        pu[x] = su[sx];
        pv[x] = sv[sx];
      }
    }
    field_cost(i0, i1, cu, cv_, cost);
    for (int y = 0; y < h; ++y) {
      float* pu = u.ptr<float>(y);
      float* pv = v.ptr<float>(y);
      const float* su = cu.ptr<float>(y);
      const float* sv = cv_.ptr<float>(y);
      float* b = best.data() + static_cast<std::size_t>(y) * w;
      const float* c = cost.data() + static_cast<std::size_t>(y) * w;
      for (int x = 0; x < w; ++x) {
        const bool better = c[x] < b[x];
        b[x] = better ? c[x] : b[x];
        pu[x] = better ? su[x] : pu[x];
        pv[x] = better ? sv[x] : pv[x];
      }
    }
  }
}

}  // namespace roiflow::flow
