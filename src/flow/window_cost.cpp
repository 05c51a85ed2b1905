#include "flow/window_cost.hpp"

#include <algorithm>
#include <cstddef>

namespace roiflow::flow::detail {

StreamingZssd::StreamingZssd(int w, int h, int window)
    : w_(w),
      h_(h),
      r_(window / 2),
      ring_(static_cast<std::size_t>(2 * r_ + 1) * w),
      squares_(ring_.size()),
      c1_(w + 2 * r_, 0.f),
      c2_(w + 2 * r_, 0.f),
      inv_nx_(w),
      inv_ny_(h) {
  for (int x = 0; x < w; ++x)
    inv_nx_[x] = 1.f / static_cast<float>(std::min(w - 1, x + r_) - std::max(0, x - r_) + 1);
  for (int y = 0; y < h; ++y)
    inv_ny_[y] = 1.f / static_cast<float>(std::min(h - 1, y + r_) - std::max(0, y - r_) + 1);
}

void StreamingZssd::reset() {
  std::fill(c1_.begin(), c1_.end(), 0.f);
  std::fill(c2_.begin(), c2_.end(), 0.f);
}

float* StreamingZssd::row(int y) {
  return ring_.data() + static_cast<std::size_t>(y % (2 * r_ + 1)) * w_;
}

void StreamingZssd::add(int y) {
  const float* __restrict d = row(y);
  float* __restrict sq = squares_.data() + (d - ring_.data());
  float* __restrict c1 = c1_.data() + r_;
  float* __restrict c2 = c2_.data() + r_;
  for (int x = 0; x < w_; ++x) {
    sq[x] = d[x] * d[x];
    c1[x] += d[x];
    c2[x] += sq[x];
  }
}

void StreamingZssd::remove(int y) {
  const float* __restrict d = row(y);
  const float* __restrict sq = squares_.data() + (d - ring_.data());
  float* __restrict c1 = c1_.data() + r_;
  float* __restrict c2 = c2_.data() + r_;
  for (int x = 0; x < w_; ++x) {
    c1[x] -= d[x];
    c2[x] -= sq[x];
  }
}

void StreamingZssd::costs(int y, float* out) {
  // The search and the fusion use 7x7 windows: with the radius known at compile time the taps
  // unroll and the loop vectorises along x.
  if (r_ == 3) {
    costs_impl<3>(y, out);
  } else {
    costs_impl<-1>(y, out);
  }
}

template <int kR>
void StreamingZssd::costs_impl(int y, float* __restrict out) {
  const int r = kR >= 0 ? kR : r_;
  const float* __restrict c1 = c1_.data();
  const float* __restrict c2 = c2_.data();
  const float* __restrict inx = inv_nx_.data();
  const float iny = inv_ny_[y];
  for (int x = 0; x < w_; ++x) {
    float s1 = 0.f, s2 = 0.f;
#pragma GCC unroll 16
    for (int k = 0; k <= 2 * r; ++k) {
      s1 += c1[x + k];
      s2 += c2[x + k];
    }
    out[x] = s2 - s1 * s1 * (inx[x] * iny);
  }
}

void warp_difference_row(const cv::Mat& i1, const float* __restrict i0, int y, int w,
                         const float* __restrict u, const float* __restrict v,
                         float* __restrict d) {
  const float xhi = static_cast<float>(i1.cols - 1), yhi = static_cast<float>(i1.rows - 1);
  const int ixmax = std::max(0, i1.cols - 2), iymax = std::max(0, i1.rows - 2);
  const int dx1 = i1.cols > 1 ? 1 : 0;
  const std::ptrdiff_t step = static_cast<std::ptrdiff_t>(i1.step1());
  const std::ptrdiff_t dy1 = i1.rows > 1 ? step : 0;
  const float* __restrict base = i1.ptr<float>(0);
  const float fy0 = static_cast<float>(y);
  for (int x = 0; x < w; ++x) {
    const float sx = std::min(std::max(static_cast<float>(x) + u[x], 0.f), xhi);
    const float sy = std::min(std::max(fy0 + v[x], 0.f), yhi);
    const int ix = std::min(static_cast<int>(sx), ixmax);
    const int iy = std::min(static_cast<int>(sy), iymax);
    const float fx = sx - static_cast<float>(ix), fy = sy - static_cast<float>(iy);
    const float* p = base + iy * step + ix;
    const float top = p[0] + fx * (p[dx1] - p[0]);
    const float bot = p[dy1] + fx * (p[dy1 + dx1] - p[dy1]);
    d[x] = top + fy * (bot - top) - i0[x];
  }
}

void field_costs(const cv::Mat& i0, const cv::Mat& i1, const cv::Mat& u, const cv::Mat& v,
                 int window, std::vector<float>& cost) {
  const int w = i0.cols;
  StreamingZssd z(w, i0.rows, window);
  std::vector<float> cost_row;
  cost.resize(static_cast<std::size_t>(w) * i0.rows);
  for_each_cost_row(
      z,
      [&](int y, float* d) {
        warp_difference_row(i1, i0.ptr<float>(y), y, w, u.ptr<float>(y), v.ptr<float>(y), d);
      },
      [&](int y, const float* c) {
        std::copy_n(c, w, cost.data() + static_cast<std::size_t>(y) * w);
      },
      cost_row);
}

}  // namespace roiflow::flow::detail
