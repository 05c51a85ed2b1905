#include "tracking/motion_split.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <opencv2/imgproc.hpp>
#include <vector>

#include "tracking/start_motion_impl.hpp"

namespace roiflow::tracking {
namespace {

float split_median(std::vector<float>& v) {
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2), v.end());
  return v[v.size() / 2];
}

}  // namespace

std::vector<std::size_t> split_candidates(const TrackSet& state,
                                          const std::vector<Detection>& detections,
                                          const Foreground& fg_t1,
                                          const MultiTrackerParams& params) {
  std::vector<std::size_t> out;
  if (params.split_grow <= 0 || !fg_t1.motion.empty() || state.tracks.empty()) return out;
  std::vector<cv::Rect2f> guess;
  for (const Track& t : state.tracks) {
    if (t.id == 0) {
      guess.emplace_back();
      continue;
    }
    BoxFilter f = t.filter;
    f.predict();
    guess.push_back(f.box());
  }
  for (std::size_t j = 0; j < detections.size(); ++j) {
    const cv::Rect2f& d = detections[j].box;
    int inside = 0;
    bool grown = false;
    for (const cv::Rect2f& g : guess) {
      if (!(g.area() > 0) || (g & d).area() < 0.5 * g.area()) continue;
      ++inside;
      if (d.area() >= params.split_grow * g.area()) grown = true;
    }
    // Over two objects it is a merge, which the objects' own LK follows (decide).
    if (inside == 1 && grown) out.push_back(j);
  }
  return out;
}

std::vector<cv::Rect2f> split_by_flow(const cv::Rect2f& box, const flow::Pyramid& pyr_t,
                                      const flow::Pyramid& pyr_t1, const Foreground& fg_t1,
                                      flow::DenseLK& lk, const MultiTrackerParams& params) {
  const MotionDetectorParams& dp = params.detector;
  if (fg_t1.empty() || !(dp.start_motion > 0)) return {};
  const cv::Size size = pyr_t1.size();
  const cv::Rect frame(0, 0, size.width, size.height);
  const cv::Rect inner =
      cv::Rect(static_cast<int>(std::floor(box.x)), static_cast<int>(std::floor(box.y)),
               static_cast<int>(std::ceil(box.width)), static_cast<int>(std::ceil(box.height))) &
      frame;
  if (inner.empty()) return {};
  const int m = params.margin;
  const cv::Rect region =
      cv::Rect(inner.x - m, inner.y - m, inner.width + 2 * m, inner.height + 2 * m) & frame;
  flow::FlowOptions fo;
  fo.region = region;
  fo.context = params.lk_context;
  flow::FlowResult back;
  lk.calc(pyr_t1, pyr_t, back, fo);
  const cv::Rect r = back.region;
  const int scale = std::max(1, fg_t1.scale);
  // Per pixel of the region: foreground (the model's mask, nearest), the background's motion and
  // texture (the median of the pixels outside the foreground).
  cv::Mat fg(r.size(), CV_8U);
  std::vector<float> us, vs, textures;
  for (int y = 0; y < r.height; ++y) {
    const std::uint8_t* mrow =
        fg_t1.mask.ptr<std::uint8_t>(std::min(fg_t1.mask.rows - 1, (y + r.y) / scale));
    std::uint8_t* out = fg.ptr<std::uint8_t>(y);
    const cv::Vec2f* f = back.flow.ptr<cv::Vec2f>(y);
    const float* c = back.confidence.ptr<float>(y);
    for (int x = 0; x < r.width; ++x) {
      out[x] = mrow[std::min(fg_t1.mask.cols - 1, (x + r.x) / scale)];
      if (out[x] == 0) {
        us.push_back(-f[x][0]);
        vs.push_back(-f[x][1]);
        textures.push_back(c[x]);
      }
    }
  }
  const bool seen = us.size() >= 16;
  const cv::Vec2f background = seen ? cv::Vec2f(split_median(us), split_median(vs)) : cv::Vec2f();
  const double texture = seen ? dp.start_texture * split_median(textures) : 0.0;
  cv::Mat motion(r.size(), CV_32FC2), moving(r.size(), CV_8U), still(r.size(), CV_8U);
  const float m2 = static_cast<float>(dp.start_motion * dp.start_motion);
  for (int y = 0; y < r.height; ++y) {
    const cv::Vec2f* f = back.flow.ptr<cv::Vec2f>(y);
    const float* c = back.confidence.ptr<float>(y);
    cv::Vec2f* v = motion.ptr<cv::Vec2f>(y);
    std::uint8_t* mv = moving.ptr<std::uint8_t>(y);
    std::uint8_t* st = still.ptr<std::uint8_t>(y);
    for (int x = 0; x < r.width; ++x) {
      v[x] = -f[x] - background;
      const float d2 = v[x][0] * v[x][0] + v[x][1] * v[x][1];
      mv[x] = d2 >= m2 && c[x] >= texture ? 255 : 0;
      st[x] = d2 < m2 ? 255 : 0;
    }
  }
  // The window's reach: LK carries an object's motion half a window beyond its edge.
  const int reach = static_cast<int>(std::lround(dp.start_reach));
  if (reach > 0)
    cv::erode(moving, moving,
              cv::getStructuringElement(cv::MORPH_RECT, {2 * reach + 1, 2 * reach + 1}));
  const cv::Rect in = inner - r.tl();
  cv::Mat mask(r.size(), CV_8U, cv::Scalar(0));
  fg(in).copyTo(mask(in));
  mask &= moving;
  const cv::Mat labels(r.size(), CV_32S, cv::Scalar(1));
  const double min_area = smallest_object(dp, scale);
  const int min_pixels = std::max(8 * scale * scale, static_cast<int>(0.25 * min_area));
  std::vector<cv::Rect> modes =
      detail::motion_modes(labels, mask, motion, 1, in, dp.start_motion, min_pixels);
  std::vector<cv::Rect2f> boxes(modes.begin(), modes.end());
  boxes = merge_nested(std::move(boxes), dp.merge_overlap);
  for (cv::Rect2f& b : boxes)
    b += cv::Point2f(static_cast<float>(r.x), static_cast<float>(r.y));
  std::erase_if(boxes, [&](const cv::Rect2f& b) { return b.area() < min_area; });
  if (boxes.size() >= 2) return boxes;
  if (boxes.size() != 1 || boxes[0].area() > params.split_keep * box.area()) return {};
  // One motion over a small part of the box: cut the rest when much of it stands still.
  const cv::Rect kept = cv::Rect(boxes[0]) - r.tl();
  long long outside = 0, standing = 0;
  for (int y = in.y; y < in.br().y; ++y) {
    const std::uint8_t* f = fg.ptr<std::uint8_t>(y);
    const std::uint8_t* st = still.ptr<std::uint8_t>(y);
    for (int x = in.x; x < in.br().x; ++x) {
      if (f[x] == 0 || kept.contains({x, y})) continue;
      ++outside;
      if (st[x] != 0) ++standing;
    }
  }
  if (standing < min_pixels || 4 * standing < outside) return {};
  return boxes;
}

std::vector<Detection> apply_splits(const std::vector<Detection>& detections,
                                    const std::vector<std::size_t>& which,
                                    const std::vector<std::vector<cv::Rect2f>>& parts) {
  std::vector<char> replaced(detections.size(), 0);
  std::vector<Detection> out;
  for (std::size_t k = 0; k < which.size() && k < parts.size(); ++k) {
    if (parts[k].empty() || which[k] >= detections.size()) continue;
    replaced[which[k]] = 1;
    for (const cv::Rect2f& b : parts[k])
      out.push_back({b, (b.tl() + b.br()) * 0.5f, b.area()});
  }
  for (std::size_t j = 0; j < detections.size(); ++j)
    if (!replaced[j]) out.push_back(detections[j]);
  std::sort(out.begin(), out.end(),
            [](const Detection& a, const Detection& b) { return a.score > b.score; });
  return out;
}

}  // namespace roiflow::tracking
