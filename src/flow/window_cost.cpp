#include "flow/window_cost.hpp"

#include <algorithm>
#include <cstddef>

#include "flow/lk_rows.hpp"

namespace roiflow::flow::detail {

BoxSum::BoxSum(int w, int h, int r) : w_(w), h_(h), r_(r), column_(w), padded_(w + 2 * r, 0.f) {}

void BoxSum::operator()(const float* src, float* dst) {
  const int w = w_, h = h_, r = r_;
  std::fill(column_.begin(), column_.end(), 0.f);
  float* __restrict a = column_.data();
  for (int y = 0; y < std::min(r, h); ++y) {
    const float* __restrict in = src + static_cast<std::size_t>(y) * w;
    for (int x = 0; x < w; ++x)
      a[x] += in[x];
  }
  for (int y = 0; y < h; ++y) {
    if (y + r < h) {
      const float* __restrict in = src + static_cast<std::size_t>(y + r) * w;
      for (int x = 0; x < w; ++x)
        a[x] += in[x];
    }
    if (y - r - 1 >= 0) {
      const float* __restrict out = src + static_cast<std::size_t>(y - r - 1) * w;
      for (int x = 0; x < w; ++x)
        a[x] -= out[x];
    }
    // Zeros on both sides of the row make the clipped window a plain sum of 2r + 1 taps.
    float* __restrict p = padded_.data() + r;
    std::copy_n(a, w, p);
    float* __restrict o = dst + static_cast<std::size_t>(y) * w;
    for (int x = 0; x < w; ++x) {
      float s = 0.f;
      for (int k = -r; k <= r; ++k)
        s += p[x + k];
      o[x] = s;
    }
  }
}

ZssdWindow::ZssdWindow(int w, int h, int window)
    : w_(w),
      h_(h),
      box_(w, h, window / 2),
      inv_count_(static_cast<std::size_t>(w) * h),
      squares_(inv_count_.size()),
      s1_(inv_count_.size()),
      s2_(inv_count_.size()) {
  const int r = window / 2;
  for (int y = 0; y < h; ++y) {
    const int ny = std::min(h - 1, y + r) - std::max(0, y - r) + 1;
    for (int x = 0; x < w; ++x) {
      const int nx = std::min(w - 1, x + r) - std::max(0, x - r) + 1;
      inv_count_[static_cast<std::size_t>(y) * w + x] = 1.f / static_cast<float>(nx * ny);
    }
  }
}

void ZssdWindow::operator()(const float* d, float* cost) {
  const std::size_t n = inv_count_.size();
  float* __restrict sq = squares_.data();
  for (std::size_t i = 0; i < n; ++i)
    sq[i] = d[i] * d[i];
  box_(d, s1_.data());
  box_(sq, s2_.data());
  const float* __restrict s1 = s1_.data();
  const float* __restrict s2 = s2_.data();
  const float* __restrict inv = inv_count_.data();
  for (std::size_t i = 0; i < n; ++i)
    cost[i] = s2[i] - s1[i] * s1[i] * inv[i];
}

FieldCost::FieldCost(int w, int h, int window)
    : zssd_(w, h, window), d_(static_cast<std::size_t>(w) * h), mean_(w) {}

void FieldCost::operator()(const cv::Mat& i0, const cv::Mat& i1, const cv::Mat& u, const cv::Mat& v,
                           std::vector<float>& cost) {
  const int w = i0.cols;
  for (int y = 0; y < i0.rows; ++y) {
    warp_row(i1, i0.ptr<float>(y), 0, y, w, u.ptr<float>(y), v.ptr<float>(y), mean_.data(),
             d_.data() + static_cast<std::size_t>(y) * w);
  }
  cost.resize(d_.size());
  zssd_(d_.data(), cost.data());
}

}  // namespace roiflow::flow::detail
