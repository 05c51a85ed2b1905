// The zero-mean SSD of windows over small images, streamed row by row (internal to
// roiflow::flow: the coarse search and the candidate fusion of large_motion.hpp).
//
//   using namespace roiflow::flow;
//   detail::StreamingZssd z(frame_t.cols, frame_t.rows, 7);
//   std::vector<float> cost_row;
//   const auto fill = [&](int y, float* d) {  // row y of the differences
//     for (int x = 0; x < frame_t.cols; ++x)
//       d[x] = float(frame_t1.at<uchar>(y, x)) - float(frame_t.at<uchar>(y, x));
//   };
//   const auto use = [&](int y, const float* cost) { std::cout << y << " " << cost[0] << "\n"; };
//   detail::for_each_cost_row(z, fill, use, cost_row);
//
// A window's zero-mean SSD is sum d^2 - (sum d)^2 / n over its n pixels (clipped at the image
// border) for the differences d = I1(x + f) - I0(x): a brightness offset between the frames
// inside the window leaves it unchanged. Rows of d enter running column sums (and leave them
// 2r + 1 rows later, from a ring), and each row's window sums are the sums of 2r + 1 columns,
// so no full-size temporary is made and the cost per pixel does not depend on the window.
#pragma once

#include <opencv2/core.hpp>
#include <vector>

namespace roiflow::flow::detail {

class StreamingZssd {
 public:
  StreamingZssd(int w, int h, int window);
  int width() const { return w_; }
  int height() const { return h_; }
  int radius() const { return r_; }

  void reset();                   // empties the column sums, before a new image
  float* row(int y);              // where row y of d goes, then add(y)
  void add(int y);                // row y (as written into row(y)) enters the column sums
  void remove(int y);             // row y leaves them (its ring slot is reused from here)
  void costs(int y, float* out);  // the window costs of row y (rows y - r .. y + r added)

 private:
  template <int kR>
  void costs_impl(int y, float* out);

  int w_, h_, r_;
  std::vector<float> ring_, squares_, c1_, c2_, inv_nx_, inv_ny_;
};

// Streams an image through `z`: fill(y, d) writes row y of the differences into d (w floats),
// use(y, cost) receives the window costs of row y, rows in order.
template <class Fill, class Use>
void for_each_cost_row(StreamingZssd& z, Fill&& fill, Use&& use, std::vector<float>& cost_row) {
  const int h = z.height(), r = z.radius();
  cost_row.resize(static_cast<std::size_t>(z.width()));
  z.reset();
  const auto enter = [&](int y) {
    fill(y, z.row(y));
    z.add(y);
  };
  for (int y = 0; y < std::min(r, h); ++y)
    enter(y);
  for (int y = 0; y < h; ++y) {
    // The leaving row's ring slot is the entering row's: remove first.
    if (y - r - 1 >= 0) z.remove(y - r - 1);
    if (y + r < h) enter(y + r);
    z.costs(y, cost_row.data());
    use(y, static_cast<const float*>(cost_row.data()));
  }
}

// Row y of d = I1(x + u[x], y + v[x]) - i0[x], x < w: frame t+1 (`i1`, CV_32FC1) sampled
// bilinearly, coordinates clamped to the frame (its border replicated).
void warp_difference_row(const cv::Mat& i1, const float* i0, int y, int w, const float* u,
                         const float* v, float* d);

// The window costs of every pixel when the whole candidate field (u, v) (level pixels, i0's
// size) carries frame t+1 onto frame t `i0`: a pixel's cost also says how well the field fits
// its neighbours, so choosing per pixel between fields by this cost switches coherent pieces
// of flow, not lone pixels.
void field_costs(const cv::Mat& i0, const cv::Mat& i1, const cv::Mat& u, const cv::Mat& v,
                 int window, std::vector<float>& cost);

}  // namespace roiflow::flow::detail
