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

// One candidate field streamed row by row: frame t+1 warped by it, the differences d entering
// and leaving the window's rows (a ring of 2r + 1 rows), running column sums of d and d^2, the
// zero-mean SSD of each window, and the running best, all without a full-size temporary.
class CandidatePass {
 public:
  CandidatePass(const cv::Mat& i0, const cv::Mat& i1, int window)
      : i0_(i0), i1_(i1), w_(i0.cols), h_(i0.rows), r_(window / 2) {
    ring_.resize(static_cast<std::size_t>(2 * r_ + 1) * w_);
    c1_.assign(w_ + 2 * r_, 0.f);
    c2_.assign(w_ + 2 * r_, 0.f);
    cu_.resize(w_);
    cv_.resize(w_);
    inv_ny_.resize(h_);
    inv_nx_.resize(w_);
    for (int y = 0; y < h_; ++y)
      inv_ny_[y] = 1.f / static_cast<float>(std::min(h_ - 1, y + r_) - std::max(0, y - r_) + 1);
    for (int x = 0; x < w_; ++x)
      inv_nx_[x] = 1.f / static_cast<float>(std::min(w_ - 1, x + r_) - std::max(0, x - r_) + 1);
  }

  // Candidate (ox, oy) of the fields (u0, v0): where its window cost beats `best`, the pixel
  // takes it (into u, v).
  void run(const cv::Mat& u0, const cv::Mat& v0, int ox, int oy, std::vector<float>& best,
           cv::Mat& u, cv::Mat& v) {
    const int h = h_, r = r_;
    std::fill(c1_.begin(), c1_.end(), 0.f);
    std::fill(c2_.begin(), c2_.end(), 0.f);
    for (int y = 0; y < std::min(r, h); ++y)
      enter(u0, v0, ox, oy, y);
    for (int y = 0; y < h; ++y) {
      // The leaving row's ring slot is the entering row's: leave first.
      if (y - r - 1 >= 0) leave(y - r - 1);
      if (y + r < h) enter(u0, v0, ox, oy, y + r);
      shifted_row(u0, y, ox, oy, cu_.data());
      shifted_row(v0, y, ox, oy, cv_.data());
      if (r == 3) {
        select_row<3>(y, best, u, v);
      } else {
        select_row<-1>(y, best, u, v);
      }
    }
  }

 private:
  // The window sums of row y from the column sums, the cost, and where it beats `best`, the
  // candidate's flow (cu_, cv_) into (u, v): one loop along x, vectorised when the radius is
  // known at compile time (kR >= 0: the taps unroll).
  template <int kR>
  void select_row(int y, std::vector<float>& best, cv::Mat& u, cv::Mat& v) {
    const int w = w_, r = kR >= 0 ? kR : r_;
    const float* __restrict c1 = c1_.data();
    const float* __restrict c2 = c2_.data();
    const float* __restrict inx = inv_nx_.data();
    const float* __restrict cu = cu_.data();
    const float* __restrict cvv = cv_.data();
    const float iny = inv_ny_[y];
    float* __restrict b = best.data() + static_cast<std::size_t>(y) * w;
    float* __restrict pu = u.ptr<float>(y);
    float* __restrict pv = v.ptr<float>(y);
    for (int x = 0; x < w; ++x) {
      float s1 = 0.f, s2 = 0.f;
#pragma GCC unroll 16
      for (int k = 0; k <= 2 * r; ++k) {
        s1 += c1[x + k];
        s2 += c2[x + k];
      }
      const float c = s2 - s1 * s1 * (inx[x] * iny);
      const bool better = c < b[x];
      b[x] = better ? c : b[x];
      pu[x] = better ? cu[x] : pu[x];
      pv[x] = better ? cvv[x] : pv[x];
    }
  }

  float* ring_row(int y) {
    return ring_.data() + static_cast<std::size_t>(y % (2 * r_ + 1)) * w_;
  }

  // Row y of d = I1(x + candidate) - I0(x) into its ring slot and the column sums.
  void enter(const cv::Mat& u0, const cv::Mat& v0, int ox, int oy, int y) {
    shifted_row(u0, y, ox, oy, cu_.data());
    shifted_row(v0, y, ox, oy, cv_.data());
    float* __restrict d = ring_row(y);
    detail::warp_difference_row(i1_, i0_.ptr<float>(y), y, w_, cu_.data(), cv_.data(), d);
    float* __restrict c1 = c1_.data() + r_;
    float* __restrict c2 = c2_.data() + r_;
    for (int x = 0; x < w_; ++x) {
      c1[x] += d[x];
      c2[x] += d[x] * d[x];
    }
  }

  void leave(int y) {
    const float* __restrict d = ring_row(y);
    float* __restrict c1 = c1_.data() + r_;
    float* __restrict c2 = c2_.data() + r_;
    for (int x = 0; x < w_; ++x) {
      c1[x] -= d[x];
      c2[x] -= d[x] * d[x];
    }
  }

  const cv::Mat& i0_;
  const cv::Mat& i1_;
  int w_, h_, r_;
  std::vector<float> ring_, c1_, c2_, cu_, cv_, inv_ny_, inv_nx_;
};

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
  const cv::Mat u0 = u.clone(), v0 = v.clone();
  std::vector<float> best(static_cast<std::size_t>(i0.cols) * i0.rows,
                          std::numeric_limits<float>::infinity());
  CandidatePass pass(i0, i1, window);
  // The pixel's own flow first: a tie keeps it.
  constexpr int kOffsets[9][2] = {{0, 0},   {-1, 0}, {1, 0},  {0, -1}, {0, 1},
                                  {-1, -1}, {1, -1}, {-1, 1}, {1, 1}};
  for (const auto& o : kOffsets)
    pass.run(u0, v0, o[0] * step, o[1] * step, best, u, v);
}

}  // namespace roiflow::flow
