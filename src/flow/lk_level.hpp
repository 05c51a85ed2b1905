// One pyramid level of dense LK (internal to roiflow::flow): the window geometry, the level's
// problem (images, computed rectangle, weights), where its first iteration's flow comes from,
// and the `iterations` refinement passes over it, split in row bands for the executor. The row
// kernels are lk_kernels.hpp's; dense_lk.cpp plans the levels and calls these coarse to fine.
//
//   using namespace roiflow::flow::detail;
//   const Window w = make_window(10, /*half_pixel_grid=*/true);  // Horn–Schunck: lo -5, hi 4
//   LevelScratch scratch;  // band buffers, kept across levels and calls by iterate_level
//   std::cout << "reach " << w.reach() << " px, scratch " << scratch.bytes() << " bytes\n";
#pragma once

#include <cstddef>
#include <memory>
#include <opencv2/core.hpp>
#include <vector>

#include "core/executor.hpp"
#include "flow/dense_lk.hpp"
#include "flow/lk_kernels.hpp"

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
};

// The flow the first iteration of a level starts from, over its computed rectangle.
struct LevelInput {
  enum class Kind { Constant, Planes, Coarser };
  Kind kind = Kind::Constant;
  float u = 0.f, v = 0.f;       // Constant
  const cv::Mat* pu = nullptr;  // Planes: CV_32F, the computed rectangle's size;
  const cv::Mat* pv = nullptr;  // Coarser: the coarser level's flow, upsampled x2
  cv::Point coarse_origin;      // Coarser: where pu, pv lie in their level

  static LevelInput constant(float u, float v);
  static LevelInput planes(const cv::Mat& u, const cv::Mat& v);
  static LevelInput coarser(const cv::Mat& u, const cv::Mat& v, cv::Point origin);
};

// 64-byte aligned floats, zero when first allocated; they keep their capacity.
class AlignedFloats {
 public:
  float* reserve(std::size_t n);
  std::size_t bytes() const { return capacity_ * sizeof(float); }

 private:
  std::unique_ptr<float[]> storage_;
  float* data_ = nullptr;
  std::size_t capacity_ = 0;
};

// The buffers of the row bands of a level (one set per band), kept across levels and calls.
struct LevelScratch {
  struct Band {
    AlignedFloats input, rings, rows;
  };
  std::vector<Band> bands;
  std::vector<float> inv_cx, cy;
  // iterate_levels_chained's: each level's window weights and the splits, for the geometry
  // chain_key describes.
  std::vector<std::vector<float>> chain_inv_cx, chain_cy;
  std::vector<int> chain_key, chain_splits;
  AlignedFloats chain_shared;  // the rows the two chains share
  std::size_t bytes() const;
};

// Length of the rows of every flow plane of a level `w` wide (its padding, see FlowRows).
int padded_width(int w);

// `iterations` refinement passes over the level from `input`, into u and v (CV_32F planes of
// comp.height rows padded_width(comp.width) long, created here: view the first comp.width
// columns) and, when not null, the smallest eigenvalue of each window's structure tensor into
// `confidence` (the same shape). With `flow` (CV_32FC2, comp-sized), the flow goes there
// interleaved instead, u and v are left alone, and `confidence` is comp-sized too. Row bands
// run on the executor; the result is the same for any split.
void iterate_level(const LevelProblem& p, const LevelInput& input, cv::Mat& u, cv::Mat& v,
                   cv::Mat* confidence, int iterations, const Executor& executor,
                   LevelScratch& scratch, cv::Mat* flow = nullptr);

// One level of iterate_levels_chained: its problem, iterations and outputs (u, v, confidence,
// flow as iterate_level takes them).
struct ChainLevel {
  LevelProblem p;
  int iterations = 1;
  cv::Mat* u = nullptr;
  cv::Mat* v = nullptr;
  cv::Mat* confidence = nullptr;
  cv::Mat* flow = nullptr;
};

// iterate_level on each of `levels` in turn (coarse to fine: the first starts from `input`,
// every later one from the level before it, upsampled as LevelInput::coarser does), on two
// chains of row bands without a barrier between levels: the lower chain takes the lower rows of
// every level and reads only rows it wrote, the upper chain takes the upper rows and waits, row
// by row, for the lower chain's rows it reads on the coarser level (the first few of them, made
// early). Two chunks of one executor region, so a thread runs a whole chain and the chains'
// work, not each level's, is balanced; the result is iterate_level's to the last bit. Returns
// false, computing nothing, when no split fits (levels too small).
bool iterate_levels_chained(const std::vector<ChainLevel>& levels, const LevelInput& input,
                            const Executor& executor, LevelScratch& scratch);

// Flow component of the coarser level (origin `src_origin` in its level) resampled onto
// rectangle `dst` of the finer level and doubled; blocks of rows on `executor` when given (the
// rows are independent: the same result for any split).
void upsample_flow(const cv::Mat& src, cv::Point src_origin, const cv::Rect& dst, cv::Mat& out,
                   const Executor* executor = nullptr);

// upsample_flow of both components at once, written interleaved into `flow` (CV_32FC2,
// dst-sized, created here): the values of two upsample_flow calls and a cv::merge, without the
// two planes between them (the level-0 flow of a region LK ran on coarser levels).
void upsample_flow_pair(const cv::Mat& src_u, const cv::Mat& src_v, cv::Point src_origin,
                        const cv::Rect& dst, cv::Mat& flow, const Executor* executor = nullptr);

}  // namespace roiflow::flow::detail
