// Large displacements for dense LK: how many pyramid levels a frame gets (auto_levels), a coarse
// search that starts the coarsest level inside LK's basin when objects move further than a
// patch (search_flow: zero-mean SSD over a window, forward-backward consistent, better than the
// prior by a margin; unreliable pixels take the better of the prior and their nearest reliable
// neighbour's flow), and a candidate fusion that carries a motion found in one part of an object
// over to the rest (fuse_candidates). They work on CV_32FC1 level images in [0, 1] and planar
// flow (u, v) in level pixels.
//
//   using namespace roiflow::flow;
//   const int levels = auto_levels({1242, 375}, /*expected_motion=*/0.0);
//   const Pyramid p0 = build_pyramid(frame_t, levels, 0.5);
//   const Pyramid p1 = build_pyramid(frame_t1, levels, 0.5);
//   const cv::Mat &i0 = p0.levels.back(), &i1 = p1.levels.back();
//   cv::Mat u(i0.size(), CV_32F, 0.f), v(i0.size(), CV_32F, 0.f);
//   search_flow(i0, i1, {0.f, 0.f}, SearchParams{}, u, v);  // the coarsest level
//   fuse_candidates(i0, i1, /*step=*/6, /*window=*/7, u, v);  // any level
#pragma once

#include <opencv2/core.hpp>
#include <vector>

#include "core/executor.hpp"
#include "flow/dense_lk.hpp"

namespace roiflow::flow {

// The shorter side, in pixels, that auto_levels keeps for the coarsest level by default.
inline constexpr int kCoarsestSide = 40;
// The largest search radius LkParams accept, in pixels of the coarsest level.
inline constexpr int kMaxSearchRadius = 24;
// The window of the candidate fusion dense_flow runs (LkParams::fuse_step).
inline constexpr int kFuseWindow = 7;

// Levels for a frame of `size` (LkParams::levels = 0): the coarsest level is the deepest whose
// shorter side keeps `coarsest_side` pixels (at least kMinLevelSide), so that a search there
// still sees objects; when `expected_motion` (> 0, level-0 pixels) is small, fewer levels, as
// long as the coarsest still sees the motion as at most two of its pixels. 1..kMaxLevels.
int auto_levels(cv::Size size, double expected_motion, int coarsest_side = kCoarsestSide);

// The search radius, in pixels of coarsest level `level`, that covers `expected_motion`
// (level-0 pixels; <= 0: a quarter of the frame's larger side), at most `max_radius`.
int search_radius_for(cv::Size size, int level, double expected_motion, int max_radius);

struct SearchParams {
  int radius = 12;            // displacements -radius..radius on each axis around the prior
  int window = 7;             // odd side of the window the cost is summed over
  float fb_tolerance = 1.f;   // forward-backward mismatch still consistent, level pixels
  float prior_margin = 0.2f;  // share of the prior's cost a match must save (0 = any)
};

// Coarse search of `i0`'s pixels in `i1` (same size as i0, u and v) around `prior` (level
// pixels): u, v become each pixel's reliable integer displacement, or its fill (see above).
// Frame borders are replicated. With an executor of two threads or more, parts of the
// displacements are searched side by side, with the same result. Throws roiflow::Error on
// mismatched inputs or parameters out of range (radius 1..kMaxSearchRadius, window odd 3..15,
// tolerance >= 0, margin in [0, 1)).
void search_flow(const cv::Mat& i0, const cv::Mat& i1, cv::Point2f prior,
                 const SearchParams& params, cv::Mat& u, cv::Mat& v,
                 const Executor* executor = nullptr);

// Candidate fusion: each pixel keeps its own flow or takes that of the pixel `step` away in
// one of the 8 directions, whichever has the smallest zero-mean SSD over a `window` x `window`
// window (frame t+1 warped bilinearly, borders replicated); ties keep the pixel's own. One pass,
// all pixels at once. With an executor of two threads or more the nine candidates' costs are
// computed side by side (into `scratch` when given, kept for the next call; nine floats per
// pixel) and folded in rows, with the same result. Throws roiflow::Error on mismatched inputs,
// step < 1 or a window that is not odd in 3..15.
void fuse_candidates(const cv::Mat& i0, const cv::Mat& i1, int step, int window, cv::Mat& u,
                     cv::Mat& v, const Executor* executor = nullptr,
                     std::vector<float>* scratch = nullptr);

namespace detail {

// The levels `params` asks for at frame size `size`: params.levels, or auto_levels when it is 0.
int requested_levels(cv::Size size, const LkParams& params);

// Whether seed_level does anything at level `level` of `levels` for `params` and `options`.
bool seeds_level(const LkParams& params, int level, int levels, const FlowOptions& options);

// dense_flow's hook before the iterations of level `level` (of `levels`; i0, i1: its whole
// images), on the rectangle `c` that u and v cover: the coarse search at the coarsest level
// (around options.initial_motion; not when options.initial_flow gives the start), then the far
// and the near candidate fusion, as `params` ask. A region is searched within its own
// rectangle.
void seed_level(const LkParams& params, const cv::Mat& i0, const cv::Mat& i1, const cv::Rect& c,
                int level, int levels, const FlowOptions& options, cv::Mat& u, cv::Mat& v,
                const Executor* executor = nullptr, std::vector<float>* scratch = nullptr);

}  // namespace detail

}  // namespace roiflow::flow
