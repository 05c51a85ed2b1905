// Window sums and the zero-mean SSD of windows over whole small images (internal to
// roiflow::flow: the coarse search and the candidate fusion of large_motion.hpp).
//
//   detail::ZssdWindow cost(w, h, 7);
//   cost(diff, out);   // out[i] = sum d^2 - (sum d)^2 / n over the 7x7 window of pixel i
//   detail::FieldCost field(w, h, 7);
//   field(i0, i1, u, v, costs);   // the same for d = I1(x + (u, v)(x)) - I0(x)
#pragma once

#include <opencv2/core.hpp>
#include <vector>

namespace roiflow::flow::detail {

// Sums of `src` (w x h, row-major) over (2r + 1)^2 windows clipped at the border, into `dst`.
class BoxSum {
 public:
  BoxSum(int w, int h, int r);
  void operator()(const float* src, float* dst);

 private:
  int w_, h_, r_;
};

// Zero-mean SSD of each pixel's window from the differences d = I1(x + f) - I0(x):
// sum d^2 - (sum d)^2 / n, n the pixels of the clipped window. A brightness offset between the
// frames inside a window leaves it unchanged.
class ZssdWindow {
 public:
  ZssdWindow(int w, int h, int window);
  // d: w x h differences; cost: w x h out.
  void operator()(const float* d, float* cost);
  int size() const { return w_ * h_; }

 private:
  int w_, h_;
  BoxSum box_;
  std::vector<float> inv_count_, squares_, s1_, s2_;
};

// Row y of d = I1(x + u[x], y + v[x]) - i0[x], x < w: frame t+1 (`i1`, CV_32FC1) sampled
// bilinearly, coordinates clamped to the frame (its border replicated).
void warp_difference_row(const cv::Mat& i1, const float* i0, int y, int w, const float* u,
                         const float* v, float* d);

// The zero-mean SSD of every pixel's window when the whole candidate field (u, v) (level
// pixels, i0's size) carries frame t+1 (bilinear, borders replicated) onto frame t `i0`: a
// pixel's cost also says how well the field fits its neighbours, so choosing per pixel between
// fields by this cost switches coherent pieces of flow, not lone pixels.
class FieldCost {
 public:
  FieldCost(int w, int h, int window);
  void operator()(const cv::Mat& i0, const cv::Mat& i1, const cv::Mat& u, const cv::Mat& v,
                  std::vector<float>& cost);

 private:
  ZssdWindow zssd_;
  std::vector<float> d_;
};

}  // namespace roiflow::flow::detail
