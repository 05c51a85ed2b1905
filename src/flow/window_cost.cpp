#include "flow/window_cost.hpp"

#include <algorithm>
#include <cstddef>

#include <opencv2/imgproc.hpp>

namespace roiflow::flow::detail {

BoxSum::BoxSum(int w, int h, int r) : w_(w), h_(h), r_(r) {}

void BoxSum::operator()(const float* src, float* dst) {
  // OpenCV's box filter (running sums, vectorised); zeros outside make the clipped window.
  const cv::Mat in(h_, w_, CV_32F, const_cast<float*>(src));
  cv::Mat out(h_, w_, CV_32F, dst);
  cv::boxFilter(in, out, CV_32F, cv::Size(2 * r_ + 1, 2 * r_ + 1), cv::Point(-1, -1), false,
                cv::BORDER_CONSTANT);
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

FieldCost::FieldCost(int w, int h, int window)
    : zssd_(w, h, window), d_(static_cast<std::size_t>(w) * h) {}

void FieldCost::operator()(const cv::Mat& i0, const cv::Mat& i1, const cv::Mat& u, const cv::Mat& v,
                           std::vector<float>& cost) {
  const int w = i0.cols;
  for (int y = 0; y < i0.rows; ++y) {
    warp_difference_row(i1, i0.ptr<float>(y), y, w, u.ptr<float>(y), v.ptr<float>(y),
                        d_.data() + static_cast<std::size_t>(y) * w);
  }
  cost.resize(d_.size());
  zssd_(d_.data(), cost.data());
}

}  // namespace roiflow::flow::detail
