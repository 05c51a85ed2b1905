#include "tracking/object_tracker.hpp"

#include <cmath>
#include <string>
#include <utility>

#include "core/error.hpp"
#include "core/text.hpp"

namespace roiflow::tracking {

void ObjectTrackerParams::validate() const {
  TrackerParams base = tracker;
  base.init.reset();
  base.validate();
  if (max_lost < 0) throw Error("tracker: max_lost must be >= 0, got " + std::to_string(max_lost));
  if (init.size() > 256) {
    throw Error("tracker: at most 256 init boxes, got " + std::to_string(init.size()));
  }
  for (const cv::Rect2f& box : init) {
    TrackerParams one = base;
    one.init = box;
    one.validate();
  }
}

struct ObjectTracker::Impl {
  struct Slot {
    Tracker tracker;
    int id = 0;  // 0 until its object is known
    int lost_frames = 0;
    bool dropped = false;
  };

  ObjectTrackerParams params;
  const Executor* executor = nullptr;
  std::vector<Slot> slots;
  int next_id = 1;
  long long frames = 0;
  TrackerOutput primary;

  Tracker make(const std::optional<cv::Rect2f>& init) const {
    TrackerParams p = params.tracker;
    p.init = init;
    return Tracker(p, executor);
  }
};

ObjectTracker::ObjectTracker(const ObjectTrackerParams& params, const Executor* executor)
    : impl_(std::make_unique<Impl>()) {
  params.validate();
  impl_->params = params;
  impl_->executor = executor;
  if (params.init.empty()) {
    impl_->slots.push_back({impl_->make(std::nullopt)});
  } else {
    for (const cv::Rect2f& box : params.init) {
      impl_->slots.push_back({impl_->make(box)});
      impl_->slots.back().id = impl_->next_id++;
    }
  }
}

ObjectTracker::~ObjectTracker() = default;
ObjectTracker::ObjectTracker(ObjectTracker&&) noexcept = default;
ObjectTracker& ObjectTracker::operator=(ObjectTracker&&) noexcept = default;

std::vector<TrackedObject> ObjectTracker::update(const TrackerInput& frame) {
  Impl& m = *impl_;
  std::vector<TrackedObject> objects;
  for (std::size_t i = 0; i < m.slots.size(); ++i) {
    Impl::Slot& slot = m.slots[i];
    if (slot.dropped) {
      if (i == 0) {
        m.primary = TrackerOutput{};
        m.primary.index = frame.index;
      }
      continue;
    }
    TrackerOutput out = slot.tracker.process(frame);
    if (out.has_target && slot.id == 0) slot.id = m.next_id++;
    if (out.has_target) {
      slot.lost_frames = out.lost ? slot.lost_frames + 1 : 0;
      objects.push_back({slot.id, out.box, out.velocity, out.mode, out.lost, slot.lost_frames});
    }
    if (i == 0) m.primary = std::move(out);
    if (m.params.max_lost > 0 && slot.lost_frames > m.params.max_lost) {
      objects.pop_back();  // dropped on this frame: no longer an object
      slot.tracker.finish_background_work();
      if (m.params.init.empty()) {
        slot.tracker = m.make(std::nullopt);  // look for the next moving object
        slot.id = 0;
        slot.lost_frames = 0;
      } else {
        slot.dropped = true;
      }
    }
  }
  ++m.frames;
  return objects;
}

const TrackerOutput& ObjectTracker::primary() const {
  return impl_->primary;
}

bool ObjectTracker::wants_pyramid() const {
  for (const Impl::Slot& slot : impl_->slots) {
    if (!slot.dropped && slot.tracker.wants_pyramid()) return true;
  }
  return false;
}

int ObjectTracker::pyramid_levels() const {
  return impl_->slots.front().tracker.pyramid_levels();
}
double ObjectTracker::pyramid_sigma() const {
  return impl_->slots.front().tracker.pyramid_sigma();
}
long long ObjectTracker::frames() const {
  return impl_->frames;
}

void ObjectTracker::finish_background_work() {
  for (Impl::Slot& slot : impl_->slots)
    slot.tracker.finish_background_work();
}

}  // namespace roiflow::tracking
