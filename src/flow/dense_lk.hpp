// Dense iterative pyramidal Lucas-Kanade optical flow (the paper's Algorithm 1). For each
// pyramid level from coarse to fine, the coarser flow is upsampled, frame t+1 is warped towards
// frame t, and `iterations` times every pixel solves the Tikhonov-regularised 2x2 least-squares
// system of its patch, (G + lambda I) w = b + lambda w_prev, from running window sums (O(1) per
// pixel whatever the patch). DenseLK owns its workspace (freed with it, or by collectGarbage);
// createDenseLK is the same as a cv::DenseOpticalFlow, a drop-in for cv::DISOpticalFlow; the
// execution policy (an Executor) is separate from the options (LkParams). docs/ARCHITECTURE.md
// describes the patch geometry and the large-displacement steps.
//
//   roiflow::flow::DenseLK lk(roiflow::flow::LkParams::paper());  // reuse it for every pair
//   const roiflow::flow::FlowResult r = lk.calc(frame_t, frame_t1);
//   const cv::Mat flow = r.flow;  // CV_32FC2: (u, v) in pixels, u right, v down
//   cv::Ptr<cv::DenseOpticalFlow> of = roiflow::flow::createDenseLK();
//   cv::Mat same;
//   of->calc(frame_t, frame_t1, same);
#pragma once

#include <cstddef>
#include <memory>
#include <opencv2/core.hpp>
#include <opencv2/video/tracking.hpp>
#include <string>
#include <string_view>
#include <vector>

#include "core/executor.hpp"
#include "flow/pyramid.hpp"

namespace roiflow::flow {

enum class Derivative {
  HornSchunck,  // 2x2x2 cube of Horn & Schunck: both frames, half-pixel grid (the paper's)
  Scharr,       // 3x3 Scharr on the mean of frame t and warped t+1
  Central,      // [-1 0 1]/2 on the mean of frame t and warped t+1
};

struct LkParams {
  int patch = 10;      // window side in pixels, 3..31, even sizes allowed (see above)
  int levels = 3;      // pyramid levels, 1..6 (fewer when the image is small); 0 = auto
  int iterations = 3;  // refinement iterations per level, 1..50
  // Iterations at the finest level LK runs on (0 = `iterations`), 0..50: the finest level holds
  // most of the pixels, so fewer iterations there cut most of the time (docs/PERFORMANCE.md).
  int finest_iterations = 0;
  double sigma = 0.5;  // pretreatment Gaussian sigma in pixels, 0 = off
  Derivative derivative = Derivative::HornSchunck;
  // Tikhonov weight, in (intensity/pixel)^2 with intensities in [0, 1]: it keeps textureless
  // windows at their previous (coarser-level) flow instead of solving a singular system.
  double lambda = 1e-6;
  // Robust reweighting (IRLS): residuals r get weight 1 / (1 + (r / robust_scale)^2)
  // (Cauchy). 0 = plain least squares.
  double robust_scale = 0.0;
  int level_median = 0;  // median filter (0 off, 3, 5) of the flow after each coarse level
  int final_median = 0;  // median filter (0 off, 3, 5) of the final flow
  // Large displacements (large_motion.hpp). levels = 0 (auto) picks the levels from the frame
  // size and the expected motion: the coarsest level keeps a shorter side of coarsest_side
  // pixels (12..480).
  double expected_motion = 0.0;  // level-0 pixels, >= 0; 0 = a quarter of the larger side
  int coarsest_side = 40;
  // Coarse search at the coarsest level: the largest radius, in that level's pixels
  // (0 = off, at most kMaxSearchRadius); the radius used covers the expected motion.
  int search_radius = 0;
  // Candidate fusion before the iterations of a level: each pixel may take the flow of the
  // pixels fuse_far_step, then fuse_step, away (that level's pixels; 0 = off, at most 32), on
  // the levels from fuse_far_finest_level and fuse_finest_level up to the coarsest.
  int fuse_far_step = 0;
  int fuse_far_finest_level = 0;
  int fuse_step = 0;
  int fuse_finest_level = 0;
  // Samples of frame t+1 that fall outside the frame carry no brightness term (It = 0): the
  // pixels moving out of view keep the flow their neighbours give them.
  bool mask_outside = false;
  // Level LK stops at (as FlowOptions::finest_level, which can only raise it): the finer
  // levels get the upsampled flow. 0..kMaxLevels - 1.
  int finest_level = 0;

  static LkParams paper();  // patch 10, levels 3, iterations 3, Horn–Schunck
  // Iterations at `level` when LK's finest level is `finest`.
  int iterations_at(int level, int finest) const {
    return level == finest && finest_iterations > 0 ? finest_iterations : iterations;
  }
  static LkParams accurate();  // tuned for the lowest error on real data
  static LkParams fast();      // realtime with large motions: search, fusion, LK to level 1
  // "paper", "accurate" or "fast"; throws roiflow::Error naming the unknown preset.
  static LkParams preset(std::string_view name);
  static std::vector<std::string> preset_names();

  // Throws roiflow::Error naming the first parameter out of range.
  void validate() const;
};

struct FlowOptions {
  // Region of frame t (level-0 pixels) where flow is wanted; empty = whole frame. The region
  // is clipped to the frame; flow and confidence have the region's size. Each level works on
  // the region plus the margin its iterations read, so the result is the whole frame's flow
  // inside the region, up to the rounding of window sums that start elsewhere (~1e-4 px on
  // average, at most ~0.01 px in ill-conditioned windows). Cost scales with the region.
  cv::Rect region;
  // Motion assumed before the coarsest level (e.g. a tracker's prediction), in pixels.
  cv::Point2f initial_motion{0.f, 0.f};
  // A flow field to start the coarsest level from, instead of `initial_motion` (e.g. a coarse
  // search for motions larger than the patch): CV_32FC2, (u, v) in pixels of that level, the
  // size of the whole level, level_size(frame size, flow_pyramid_levels(...) - 1). Empty = off.
  cv::Mat initial_flow;
  // Pixels of context computed around the region at every level. -1: as many as the
  // iterations read (iterations x window reach), which is what makes the region's flow equal the
  // whole frame's; that context dominates the cost of a small region (a 50x37 region costs as
  // much as ~20000 pixels at the paper's settings). A smaller context is cheaper and changes the
  // flow only near the region's border, which is what a tracker whose region already holds a
  // margin around the object wants. -1..1000.
  int context = -1;
  // Pyramid level LK stops at (0 = full resolution), 0..5: the finer levels are skipped. LK
  // runs on levels finest_level .. levels - 1, keeping at least min(levels, 2) levels (so up to
  // finest_level + 1 when it is at or above levels - 1; fewer when the image is too small; the
  // pyramids must have flow_pyramid_levels() levels), and the flow of the finest one is
  // upsampled (bilinear, x2 per level) onto the region; the confidence is the finest level's,
  // at the nearest pixel. A tracker runs LK where its object is a few dozen pixels across: the
  // cost stays that of a small object however large it is, at a precision of a fraction of
  // that level's pixel, and the coarsest level (the reach for unpredicted motion, in full-
  // resolution pixels) stays where `levels` put it. A coarser top level instead would grow the
  // context every level reads, in full-resolution pixels, by 2x.
  int finest_level = 0;
  // Whether result.confidence is computed. false: it is left empty, and the last iteration
  // skips the eigenvalue (a square root per pixel) and its plane; the flow is the same. The
  // OpenCV adapter (createDenseLK), whose caller sees only the flow, sets it false.
  bool confidence = true;
};

struct FlowResult {
  cv::Mat flow;        // CV_32FC2, (u, v) in pixels, region-sized
  cv::Mat confidence;  // CV_32FC1, smallest eigenvalue of the window's structure tensor
  cv::Rect region;     // where in frame t the result lies
};

// Dense flow with its own workspace (pyramids, flow planes, row buffers: ~10 MB at 640x480),
// kept across calls so that a video loop allocates nothing per pair, and freed with the object
// or by collectGarbage(). One object computes one pair at a time; give each thread its own.
// The executor runs the row stripes (nullptr = serial); the result is bit-identical for any
// executor and thread count.
class DenseLK {
 public:
  // Throws roiflow::Error naming the first parameter out of range.
  explicit DenseLK(const LkParams& params = LkParams::paper(), const Executor* executor = nullptr);
  ~DenseLK();
  DenseLK(DenseLK&&) noexcept;
  DenseLK& operator=(DenseLK&&) noexcept;
  DenseLK(const DenseLK&) = delete;
  DenseLK& operator=(const DenseLK&) = delete;

  // Flow from frame t to frame t+1. Both images: same size, types accepted by build_pyramid.
  // Writes into `result`, reusing its buffers when sizes match (as OpenCV's output arrays do):
  // clone() what must outlive the next call.
  void calc(const cv::Mat& frame_t, const cv::Mat& frame_t1, FlowResult& result,
            const FlowOptions& options = {});
  // The same on pyramids built once per frame (a video frame serves two pairs). The pyramids
  // must have the same size and at least flow_pyramid_levels(size, params, options) levels.
  void calc(const Pyramid& pyr_t, const Pyramid& pyr_t1, FlowResult& result,
            const FlowOptions& options = {});
  FlowResult calc(const cv::Mat& frame_t, const cv::Mat& frame_t1, const FlowOptions& options = {});
  FlowResult calc(const Pyramid& pyr_t, const Pyramid& pyr_t1, const FlowOptions& options = {});

  const LkParams& params() const { return params_; }
  void set_params(const LkParams& params);  // validates, as the constructor
  const Executor* executor() const { return executor_; }
  void set_executor(const Executor* executor) { executor_ = executor; }

  // Allocates (and touches) the workspace for frames of `size` now, so that the next calc of that
  // size allocates nothing: timing a single pair then measures the flow, not the page faults.
  void reserve(cv::Size size, const FlowOptions& options = {});
  // Frees the workspace now (the next calc allocates it again), as
  // cv::DenseOpticalFlow::collectGarbage does.
  void collectGarbage();
  // Bytes the workspace holds now.
  std::size_t workspace_bytes() const;

  struct Workspace;

 private:
  LkParams params_;
  const Executor* executor_ = nullptr;
  std::unique_ptr<Workspace> ws_;
};

// An OpenCV dense optical flow object computing DenseLK with `params`: swap
// cv::DISOpticalFlow::create(...) for createDenseLK(...) and keep calling calc(I0, I1, flow).
// calc takes 8-bit gray or BGR (and the other types build_pyramid accepts), writes CV_32FC2 into
// `flow` (its input value is not used) and gives dense_flow's result bit for bit.
cv::Ptr<cv::DenseOpticalFlow> createDenseLK(const LkParams& params = LkParams::paper(),
                                            const Executor* executor = nullptr);

// Conveniences: a DenseLK for one call (its workspace is allocated and freed every time; a loop
// over a video should keep a DenseLK instead).
FlowResult dense_flow(const cv::Mat& frame_t, const cv::Mat& frame_t1, const LkParams& params,
                      const FlowOptions& options = {}, const Executor* executor = nullptr);
FlowResult dense_flow(const Pyramid& pyr_t, const Pyramid& pyr_t1, const LkParams& params,
                      const FlowOptions& options = {}, const Executor* executor = nullptr);
void dense_flow(const cv::Mat& frame_t, const cv::Mat& frame_t1, const LkParams& params,
                FlowResult& result, const FlowOptions& options = {},
                const Executor* executor = nullptr);
void dense_flow(const Pyramid& pyr_t, const Pyramid& pyr_t1, const LkParams& params,
                FlowResult& result, const FlowOptions& options = {},
                const Executor* executor = nullptr);

// How many levels the pyramids given to dense_flow need for `options` at frame size `size`:
// effective_levels(size, max(levels, finest_level + min(levels, 2))), at most kMaxLevels.
int flow_pyramid_levels(cv::Size size, const LkParams& params, const FlowOptions& options);

// The level-0 pixels of frame t whose values dense_flow reads for `options` (the rectangles it
// computes at every level, scaled to level 0; the warps of frame t+1 reach further by the
// flow itself). A caller that builds pyramids of only part of a frame builds them over this
// (see tracking::LocalTracker). `size`: the frame's.
cv::Rect flow_footprint(cv::Size size, const LkParams& params, const FlowOptions& options);

const char* to_string(Derivative d);
Derivative derivative_from_string(std::string_view name);  // "hs", "scharr", "central"

}  // namespace roiflow::flow
