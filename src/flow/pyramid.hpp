// Gaussian image pyramids, the one builder for every caller (whole frames, parts of frames,
// level by level). Level 0 is the input as float in [0, 1], smoothed by a Gaussian of `sigma`
// pixels (0 = none; the paper's pretreatment otherwise); level k+1 is level k smoothed by
// [1 4 6 4 1]/16 and halved (cv::pyrDown's values). An image too small for the levels asked
// gets fewer: the coarsest level keeps at least kMinLevelSide pixels on its shorter side.
//
//   const roiflow::flow::Pyramid pyr = roiflow::flow::build_pyramid(frame_t, 3, 1.0);
//   std::cout << pyr.levels.back().size() << "\n";  // the coarsest: CV_32FC1, values in [0, 1]
//   roiflow::flow::Pyramid part;                   // the levels of a region only
//   roiflow::flow::build_pyramid_part(frame_t, {8, 8, 64, 64}, 3, 1.0, part);
#pragma once

#include <opencv2/core.hpp>
#include <vector>

namespace roiflow::flow {

inline constexpr int kMinLevelSide = 12;
inline constexpr int kMaxLevels = 6;

struct Pyramid {
  std::vector<cv::Mat> levels;  // CV_32FC1, level 0 full resolution
  int num_levels() const { return static_cast<int>(levels.size()); }
  cv::Size size() const { return levels.empty() ? cv::Size() : levels[0].size(); }
};

// Number of levels build_pyramid really builds for an image of `size` when `requested` are
// asked (1..kMaxLevels; throws roiflow::Error outside that range).
int effective_levels(cv::Size size, int requested);

// Size of level `level` (>= 0) of a pyramid whose level 0 is `size`: pyrDown's (w+1)/2 x (h+1)/2
// applied `level` times.
cv::Size level_size(cv::Size size, int level);

// Accepts CV_8UC1, CV_8UC3 (BGR, converted to gray), CV_16UC1 and CV_32FC1 (taken as [0, 1]).
// Throws roiflow::Error on an empty image, another type, or sigma < 0 or > 20.
Pyramid build_pyramid(const cv::Mat& image, int levels, double sigma);
// The same into `out`, reusing its buffers when the sizes match (one pyramid per video frame
// without an allocation per frame). `out` must not share buffers with `image`.
void build_pyramid(const cv::Mat& image, int levels, double sigma, Pyramid& out);

// Level by level (a graph with one node per level): build_base_level writes level 0 and sizes
// out.levels for effective_levels(image.size(), levels), keeping the coarser levels' buffers;
// build_level(out, l) then makes level l from level l - 1. Together they equal build_pyramid.
void build_base_level(const cv::Mat& image, int levels, double sigma, Pyramid& out);
void build_level(Pyramid& pyr, int level);

// The pyramid of part `rect` of `image` (build_pyramid of image(rect)). rect.tl() must lie on
// the grid of the coarsest level (multiples of 2^(levels - 1)), so that level l is the frame's
// level l over part_level_rect(rect, l), except near the part's edges where the smoothing sees
// a replicated border instead of the frame. Throws roiflow::Error otherwise.
void build_pyramid_part(const cv::Mat& image, const cv::Rect& rect, int levels, double sigma,
                        Pyramid& out);
// Level l of a part whose level 0 is `rect` (origin on the grid of level l): rect / 2^l, with
// the sizes the pyramid gives it.
cv::Rect part_level_rect(const cv::Rect& rect, int level);

}  // namespace roiflow::flow
