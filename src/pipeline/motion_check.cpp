#include "pipeline/motion_check.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <map>
#include <set>

namespace roiflow::pipeline {

MotionCheck check_motion(const FrameSource& video, const std::vector<eval::TrackRecord>& log,
                         const MotionCheckParams& params) {
  std::map<long long, std::vector<const eval::TrackRecord*>> by_frame;
  std::set<long long> ids;
  for (const eval::TrackRecord& r : log) {
    ids.insert(r.id);
    if (r.mode == eval::TrackRecord::Mode::Local && !r.lost) by_frame[r.frame].push_back(&r);
  }
  MotionCheck c;
  c.objects = static_cast<long long>(ids.size());
  struct Run {
    long long first = 0, last = 0;
    std::string what;
  };
  std::map<long long, Run> open;  // per id, the current run of bad frames
  auto close = [&](long long id) {
    auto it = open.find(id);
    if (it == open.end()) return;
    const long long length = it->second.last - it->second.first + 1;
    c.longest = std::max(c.longest, length);
    if (length > params.max_run)
      c.violations.push_back({id, it->second.first, it->second.last, it->second.what});
    open.erase(it);
  };
  tracking::MotionDetector detector(params.detector);
  while (std::optional<video::Frame> f = video()) {
    ++c.frames;
    const cv::Mat picture = f->picture();
    const cv::Rect2f view(0.f, 0.f, static_cast<float>(picture.cols),
                          static_cast<float>(picture.rows));
    const tracking::Foreground fg = detector.observe(picture);
    const long long frame = c.frames;  // 1-based, as the log counts
    std::set<long long> bad_now;
    const auto it = by_frame.find(frame);
    if (it != by_frame.end()) {
      for (const eval::TrackRecord* r : it->second) {
        ++c.records;
        // Collapsed, or hugging the border with the object outside the view: too little of the
        // box lies in the frame.
        const cv::Rect2f inside = r->box & view;
        const bool small = inside.width < params.min_side || inside.height < params.min_side;
        // The model's first frames see everything as moving or nothing: not judged.
        const bool still =
            fg.observed > params.detector.warmup && fg.moving_share(r->box) <= params.still_share;
        if (small) ++c.small;
        if (still) ++c.still;
        if (!small && !still) continue;
        bad_now.insert(r->id);
        Run& run = open[r->id];
        if (run.first == 0) run = {frame, frame, small ? "collapsed" : "no moving pixels"};
        run.last = frame;
      }
    }
    std::vector<long long> ended;
    for (const auto& [id, run] : open)
      if (bad_now.count(id) == 0) ended.push_back(id);
    for (long long id : ended)
      close(id);
  }
  std::vector<long long> rest;
  for (const auto& [id, run] : open)
    rest.push_back(id);
  for (long long id : rest)
    close(id);
  return c;
}

nlohmann::ordered_json to_json(const MotionCheck& c) {
  nlohmann::ordered_json violations = nlohmann::json::array();
  for (const MotionViolation& v : c.violations)
    violations.push_back({{"id", v.id}, {"first", v.first}, {"last", v.last}, {"what", v.what}});
  return {{"frames", c.frames},      {"objects", c.objects}, {"records", c.records},
          {"still", c.still},        {"small", c.small},     {"longest_run", c.longest},
          {"violations", violations}};
}

std::string motion_check_text(const MotionCheck& c, long long max_run) {
  std::string text = fmt::format(
      "frames {}, objects {}, found records {}: without moving pixels {}, collapsed {}, longest "
      "run {} frames (allowed {})\n",
      c.frames, c.objects, c.records, c.still, c.small, c.longest, max_run);
  for (const MotionViolation& v : c.violations)
    text += fmt::format("  id {} frames {}-{}: {}\n", v.id, v.first, v.last, v.what);
  return text;
}

}  // namespace roiflow::pipeline
