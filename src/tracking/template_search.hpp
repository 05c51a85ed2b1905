// Where a known appearance is in an image: normalised cross-correlation (OpenCV's
// TM_CCOEFF_NORMED) of the template at several scales over a search region, the best position
// refined to sub-pixel; large templates are searched coarse to fine (docs/STAGES.md).
//
//   const cv::Mat templ = frame_t(cv::Rect(100, 100, 40, 30)).clone();
//   const roiflow::tracking::TemplateMatch m = roiflow::tracking::match_template(
//       frame_t1, templ, cv::Rect(60, 60, 120, 110), {{0.95, 1.0, 1.05}});
//   if (m.score > 0.6) std::cout << m.box << "\n";  // sub-pixel top-left, scaled size
#pragma once

#include <opencv2/core.hpp>
#include <vector>

namespace roiflow::tracking {

struct TemplateMatch {
  cv::Rect2f box;      // in image coordinates
  double score = -1;   // NCC of the best match, -1 when nothing was searched
  double scale = 1;    // the scale (of those given) that won
  double ranked = -1;  // what chose it: `score` less the prior's penalty (= score without one)
};

struct TemplateSearchParams {
  std::vector<double> scales{1.0};  // template scale factors to try, each > 0
  int coarse_side = 24;             // coarse-to-fine above this template side; 0 = never
};

// A prior on where the match's centre is (image coordinates; none while radius or penalty is 0):
// a position d pixels from `centre` ranks as its NCC less penalty x (d / radius)^2, so of two
// nearly equal matches the nearer wins (an object does not jump to a lookalike).
struct MatchPrior {
  cv::Point2f centre;
  double radius = 0;   // >= 0
  double penalty = 0;  // >= 0
};

// `image` and `templ`: 8-bit or float single channel (the same depth). Throws roiflow::Error on
// empty or multi-channel inputs, mixed depths or a non-positive scale.
TemplateMatch match_template(const cv::Mat& image, const cv::Mat& templ, const cv::Rect& search,
                             const TemplateSearchParams& params = {}, const MatchPrior& prior = {});

// The size match_template gives `templ` at `scale`, and `templ` resized to `size` as it does
// (area interpolation when shrinking, linear when growing): a caller that matches the same
// sizes frame after frame keeps them and matches them at scale 1.
cv::Size scaled_size(const cv::Mat& templ, double scale);
cv::Mat resize_template(const cv::Mat& templ, cv::Size size);

// OpenCV's TM_CCOEFF_NORMED response (same formula and flat-window rule) by direct summation,
// which match_template uses for float images when positions x template pixels is small: there
// it is several times faster than matchTemplate's DFT. Float single-channel inputs, the
// template no larger than the image; response is (rows, cols) = image - template + 1.
void ccoeff_normed_direct(const cv::Mat& image, const cv::Mat& templ, cv::Mat& response);

// A float template made ready for ccoeff_normed_direct once (centred on its mean, rows padded,
// its sum of squares): a caller that matches the same template many times prepares it once.
// Throws roiflow::Error on an empty or non-float template.
struct DirectTemplate {
  explicit DirectTemplate(const cv::Mat& templ);
  cv::Mat templ;            // CV_32FC1, as given
  std::vector<float> rows;  // centred, each row padded with zeros to `stride` floats
  int stride = 0;
  double norm2 = 0;  // sum of squares of the centred template
};
void ccoeff_normed_direct(const cv::Mat& image, const DirectTemplate& templ, cv::Mat& response);
// match_template at scale 1 (no coarse pass) of a prepared template: the same result.
TemplateMatch match_template(const cv::Mat& image, const DirectTemplate& templ,
                             const cv::Rect& search, const MatchPrior& prior = {});

}  // namespace roiflow::tracking
