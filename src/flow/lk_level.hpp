// One pyramid level of dense LK (internal to roiflow::flow): the window geometry, the level's
// problem (images, computed rectangle, weights), the `iterations` refinement passes over it and
// the x2 upsampling of a level's flow onto the next finer one. dense_lk.cpp plans the levels and
// calls these coarse to fine; the row kernels are in lk_rows.hpp.
//
//   LevelScratch scratch;  // row buffers, kept across levels and calls
//   iterate_level(problem, u, v, u_next, v_next, &confidence, 3, SerialExecutor(), scratch);
#pragma once

#include <atomic>
#include <memory>
#include <opencv2/core.hpp>
#include <vector>

#include "core/executor.hpp"
#include "flow/dense_lk.hpp"
#include "flow/lk_rows.hpp"

namespace roiflow::flow::detail {

// A window along one axis, as offsets from the pixel into the derivative grid. Outermost taps
// carry weight 1/2 when `half` (see dense_lk.hpp on patch centring).
struct Window {
  int lo = 0;
  int hi = 0;
  bool half = false;
  int reach() const { return std::max(-lo, hi); }
};

Window make_window(int patch, bool half_pixel_grid);

// Sum of the window's weights at index i of an axis of n samples (the clipped window).
float window_weight(const Window& win, int i, int n);

struct LevelProblem {
  const cv::Mat* i0 = nullptr;  // level images, full size
  const cv::Mat* i1 = nullptr;
  cv::Rect comp;  // where the flow is computed, level pixels
  Derivative derivative = Derivative::HornSchunck;
  Window win;
  float lambda = 0.f;
  float robust_inv_scale2 = 0.f;  // 1 / robust_scale^2, 0 = least squares
  bool mask_outside = false;      // LkParams::mask_outside
  std::vector<float> inv_cx;      // 1 / horizontal window weight per column
  std::vector<float> cy;          // vertical window weight per row
};

// Row buffers of one pass over rows; they keep their capacity, so the levels and calls that
// reuse them allocate nothing.
struct RowScratch {
  WarpedRow warp_cache[4];
  std::vector<float> ring, colsum, col, prefix;
  std::size_t bytes() const;
};

// The row buffers of a level's passes: one per iteration of the serial wavefront, and a pool
// that concurrent stripes borrow from.
class LevelScratch {
 public:
  RowScratch& wavefront(int iteration);
  // A pool of at least `n` free scratches for stripes running at once; call before they start.
  void reserve_stripes(int n);
  std::size_t bytes() const;

  // A stripe's scratch for as long as it lives (bodies never share one).
  class Lease {
   public:
    explicit Lease(LevelScratch& owner);
    ~Lease();
    Lease(const Lease&) = delete;
    Lease& operator=(const Lease&) = delete;
    RowScratch& operator*() const { return *scratch_; }

   private:
    LevelScratch& owner_;
    int slot_ = -1;
    std::unique_ptr<RowScratch> own_;  // when the pool is exhausted
    RowScratch* scratch_ = nullptr;
  };

 private:
  std::vector<std::unique_ptr<RowScratch>> wavefront_;
  std::vector<std::unique_ptr<RowScratch>> stripes_;
  std::unique_ptr<std::atomic<bool>[]> busy_;
  int busy_size_ = 0;
};

// `iterations` refinement passes over the level: reads the flow (u, v: planar, comp-sized),
// leaves the refined flow in (u, v) (u_next, v_next are the ping-pong buffers), and the
// smallest eigenvalue of each window's structure tensor in `confidence` when it is not null.
void iterate_level(const LevelProblem& p, cv::Mat& u, cv::Mat& v, cv::Mat& u_next, cv::Mat& v_next,
                   cv::Mat* confidence, int iterations, const Executor& executor,
                   LevelScratch& scratch);

// Flow component of the coarser level (origin `src_origin` in its level) resampled onto
// rectangle `dst` of the finer level and doubled.
void upsample_flow(const cv::Mat& src, cv::Point src_origin, const cv::Rect& dst, cv::Mat& out);

}  // namespace roiflow::flow::detail
