#include "tracking/shadow_parts.hpp"

#include <opencv2/imgproc.hpp>
#include <vector>

#include "core/error.hpp"

namespace roiflow::tracking {

int reclaim_enclosed_shadows(cv::Mat& labels, double share) {
  if (labels.type() != CV_8U) throw Error("shadow parts: the labels must be 8-bit");
  if (!(share > 0 && share <= 1)) throw Error("shadow parts: share must be in (0, 1]");
  const cv::Mat shadow = labels == kShadowLabel;
  cv::Mat parts;
  const int n = cv::connectedComponents(shadow, parts, 8, CV_32S);
  if (n <= 1) return 0;
  // The outline: shadow pixels with a 4-neighbour outside the shadow (the frame's edge counts as
  // outside); next to the foreground: within one pixel (8-neighbourhood) of a foreground pixel.
  cv::Mat inner, near_fg;
  cv::erode(shadow, inner, cv::getStructuringElement(cv::MORPH_CROSS, {3, 3}), {-1, -1}, 1,
            cv::BORDER_CONSTANT, cv::Scalar(0));
  cv::dilate(labels == kForegroundLabel, near_fg, cv::Mat());
  std::vector<int> outline(static_cast<std::size_t>(n), 0), touching(outline);
  for (int y = 0; y < labels.rows; ++y) {
    const int* p = parts.ptr<int>(y);
    const unsigned char* in = inner.ptr<unsigned char>(y);
    const unsigned char* nf = near_fg.ptr<unsigned char>(y);
    for (int x = 0; x < labels.cols; ++x) {
      if (p[x] == 0 || in[x] != 0) continue;
      const auto i = static_cast<std::size_t>(p[x]);
      ++outline[i];
      if (nf[x] != 0) ++touching[i];
    }
  }
  std::vector<unsigned char> reclaim(static_cast<std::size_t>(n), 0);
  int count = 0;
  for (std::size_t i = 1; i < reclaim.size(); ++i) {
    if (outline[i] > 0 && touching[i] >= share * outline[i]) {
      reclaim[i] = 1;
      ++count;
    }
  }
  if (count == 0) return 0;
  for (int y = 0; y < labels.rows; ++y) {
    const int* p = parts.ptr<int>(y);
    unsigned char* l = labels.ptr<unsigned char>(y);
    for (int x = 0; x < labels.cols; ++x)
      if (reclaim[static_cast<std::size_t>(p[x])] != 0) l[x] = kForegroundLabel;
  }
  return count;
}

}  // namespace roiflow::tracking
