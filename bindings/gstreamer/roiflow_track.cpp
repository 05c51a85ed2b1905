// roiflowtrack: tracking::ObjectTracker as a GstVideoFilter (gst_roiflow.hpp, docs/DROPIN.md).
//
// Conventions: the caps are the same on both pads (GRAY8, I420 or NV12, any size and rate); the
// buffer passes through in place with one GstVideoRegionOfInterestMeta per object (draw=true
// also paints the boxes into the luma plane). Properties are read when the element goes
// READY -> PAUSED (start): bad values post an error there and the state change fails. QoS is on
// (GstBaseTransform drops frames that arrive too late; the tracker then sees a longer motion).
// Flushing keeps the tracker: after a seek the local treatment loses the object and the global
// one finds it again. EOS waits for the tracker's background work; the log, flushed per frame,
// is closed when the element stops. A size change in mid-stream restarts the tracker.
#include <gst/video/gstvideofilter.h>
#include <gst/video/video.h>
#include <oneapi/tbb/task_arena.h>

#include <algorithm>
#include <cmath>
#include <exception>
#include <memory>
#include <opencv2/imgproc.hpp>
#include <optional>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "core/error.hpp"
#include "flow/dense_lk.hpp"
#include "frame_copy.hpp"
#include "gst_roiflow.hpp"
#include "pipeline/tbb_executor.hpp"
#include "tracking/object_tracker.hpp"
#include "video/track_log_sink.hpp"

GST_DEBUG_CATEGORY_STATIC(roiflow_track_debug);
#define GST_CAT_DEFAULT roiflow_track_debug

namespace {

using namespace roiflow;

enum RoiflowTrackMode { kModeLocal = 0, kModeGlobal = 1 };

GType roiflow_track_mode_get_type() {
  static GType type = 0;
  if (g_once_init_enter(&type)) {
    static const GEnumValue values[] = {
        {kModeLocal, "LK in the local region, global fallback (the paper's system)", "local"},
        {kModeGlobal, "LK over the whole frame every frame (the paper's baseline)", "global"},
        {0, nullptr, nullptr}};
    const GType t = g_enum_register_static("GstRoiflowTrackMode", values);
    g_once_init_leave(&type, t);
  }
  return type;
}

enum {
  PROP_0,
  PROP_ROI,
  PROP_MODE,
  PROP_THREADS,
  PROP_INIT,
  PROP_MAX_LOST,
  PROP_LOG,
  PROP_DRAW,
  PROP_PRESET,
};

struct Settings {
  int roi = 50;
  RoiflowTrackMode mode = kModeLocal;
  int threads = 0;
  std::string init;
  int max_lost = 0;
  std::string log;
  bool draw = false;
  std::string preset = "paper";
};

// What exists between start() and stop().
struct Run {
  explicit Run(int threads) : arena(threads) {}
  pipeline::TbbExecutor executor;
  tbb::task_arena arena;
  tracking::ObjectTrackerParams params;
  std::unique_ptr<tracking::ObjectTracker> tracker;
  std::optional<video::TrackLogWriter> log;
  cv::Size size;
  long long index = 0;
  bool draw = false;
};

int hardware_threads() {
  return std::clamp(static_cast<int>(std::thread::hardware_concurrency()), 1,
                    pipeline::kMaxThreads);
}

// "x,y,w,h" boxes separated by ';' (commas and/or spaces between the numbers).
std::vector<cv::Rect2f> parse_boxes(const std::string& text) {
  std::vector<cv::Rect2f> boxes;
  std::stringstream all(text);
  std::string one;
  while (std::getline(all, one, ';')) {
    if (one.find_first_not_of(" \t") == std::string::npos) continue;
    std::string spaced = one;
    std::replace(spaced.begin(), spaced.end(), ',', ' ');
    std::istringstream in(spaced);
    double v[4];
    for (double& x : v) {
      if (!(in >> x) || !std::isfinite(x)) {
        throw Error("init: expected boxes x,y,w,h separated by ';', got '" + text + "'");
      }
    }
    std::string rest;
    if (in >> rest) throw Error("init: expected 4 numbers x,y,w,h per box, got '" + one + "'");
    boxes.emplace_back(static_cast<float>(v[0]), static_cast<float>(v[1]), static_cast<float>(v[2]),
                       static_cast<float>(v[3]));
  }
  return boxes;
}

}  // namespace

struct GstRoiflowTrack {
  GstVideoFilter parent;
  Settings* settings;  // guarded by the object lock
  Run* run;            // streaming thread (and start/stop)
};
struct GstRoiflowTrackClass {
  GstVideoFilterClass parent_class;
};

G_DEFINE_TYPE(GstRoiflowTrack, gst_roiflow_track, GST_TYPE_VIDEO_FILTER)

namespace {

GstRoiflowTrack* self_of(gpointer p) {
  return reinterpret_cast<GstRoiflowTrack*>(p);
}

void set_property(GObject* object, guint id, const GValue* value, GParamSpec* pspec) {
  GstRoiflowTrack* self = self_of(object);
  GST_OBJECT_LOCK(self);
  Settings& s = *self->settings;
  switch (id) {
    case PROP_ROI:
      s.roi = g_value_get_int(value);
      break;
    case PROP_MODE:
      s.mode = static_cast<RoiflowTrackMode>(g_value_get_enum(value));
      break;
    case PROP_THREADS:
      s.threads = g_value_get_int(value);
      break;
    case PROP_INIT:
      s.init = g_value_get_string(value) ? g_value_get_string(value) : "";
      break;
    case PROP_MAX_LOST:
      s.max_lost = g_value_get_int(value);
      break;
    case PROP_LOG:
      s.log = g_value_get_string(value) ? g_value_get_string(value) : "";
      break;
    case PROP_DRAW:
      s.draw = g_value_get_boolean(value);
      break;
    case PROP_PRESET:
      s.preset = g_value_get_string(value) ? g_value_get_string(value) : "paper";
      break;
    default:
      G_OBJECT_WARN_INVALID_PROPERTY_ID(object, id, pspec);
      break;
  }
  GST_OBJECT_UNLOCK(self);
}

void get_property(GObject* object, guint id, GValue* value, GParamSpec* pspec) {
  GstRoiflowTrack* self = self_of(object);
  GST_OBJECT_LOCK(self);
  const Settings& s = *self->settings;
  switch (id) {
    case PROP_ROI:
      g_value_set_int(value, s.roi);
      break;
    case PROP_MODE:
      g_value_set_enum(value, s.mode);
      break;
    case PROP_THREADS:
      g_value_set_int(value, s.threads);
      break;
    case PROP_INIT:
      g_value_set_string(value, s.init.c_str());
      break;
    case PROP_MAX_LOST:
      g_value_set_int(value, s.max_lost);
      break;
    case PROP_LOG:
      g_value_set_string(value, s.log.c_str());
      break;
    case PROP_DRAW:
      g_value_set_boolean(value, s.draw);
      break;
    case PROP_PRESET:
      g_value_set_string(value, s.preset.c_str());
      break;
    default:
      G_OBJECT_WARN_INVALID_PROPERTY_ID(object, id, pspec);
      break;
  }
  GST_OBJECT_UNLOCK(self);
}

void finish(Run* run) {
  if (run != nullptr && run->tracker) {
    run->arena.execute([&] { run->tracker->finish_background_work(); });
  }
}

void destroy_run(GstRoiflowTrack* self) {
  if (self->run == nullptr) return;
  try {
    finish(self->run);
  } catch (const std::exception& e) {
    GST_WARNING_OBJECT(self, "background work failed: %s", e.what());
  }
  delete self->run;
  self->run = nullptr;
}

gboolean start(GstBaseTransform* trans) {
  GstRoiflowTrack* self = self_of(trans);
  GST_OBJECT_LOCK(self);
  const Settings s = *self->settings;
  GST_OBJECT_UNLOCK(self);
  destroy_run(self);
  try {
    auto run = std::make_unique<Run>(s.threads == 0 ? hardware_threads() : s.threads);
    run->params.tracker.mode =
        s.mode == kModeGlobal ? tracking::TrackMode::Global : tracking::TrackMode::Local;
    run->params.tracker.roi = s.roi;
    run->params.tracker.lk = flow::LkParams::preset(s.preset);
    run->params.init = parse_boxes(s.init);
    run->params.max_lost = s.max_lost;
    run->params.validate();
    run->draw = s.draw;
    if (!s.log.empty()) {
      try {
        run->log.emplace(s.log);
      } catch (const Error& e) {
        GST_ELEMENT_ERROR(self, RESOURCE, OPEN_WRITE, ("%s", e.what()), (nullptr));
        return FALSE;
      }
    }
    self->run = run.release();
  } catch (const Error& e) {
    GST_ELEMENT_ERROR(self, LIBRARY, SETTINGS, ("%s", e.what()), (nullptr));
    return FALSE;
  }
  return TRUE;
}

gboolean stop(GstBaseTransform* trans) {
  GstRoiflowTrack* self = self_of(trans);
  if (self->run != nullptr && self->run->log) {
    try {
      self->run->log->close();
    } catch (const Error& e) {
      GST_ELEMENT_WARNING(self, RESOURCE, WRITE, ("%s", e.what()), (nullptr));
    }
  }
  destroy_run(self);
  return TRUE;
}

gboolean sink_event(GstBaseTransform* trans, GstEvent* event) {
  GstRoiflowTrack* self = self_of(trans);
  if (GST_EVENT_TYPE(event) == GST_EVENT_EOS && self->run != nullptr) {
    try {
      finish(self->run);
    } catch (const std::exception& e) {
      GST_ELEMENT_WARNING(self, STREAM, FAILED, ("%s", e.what()), (nullptr));
    }
  }
  return GST_BASE_TRANSFORM_CLASS(gst_roiflow_track_parent_class)->sink_event(trans, event);
}

gboolean set_info(GstVideoFilter* filter, GstCaps*, GstVideoInfo* in_info, GstCaps*,
                  GstVideoInfo*) {
  GstRoiflowTrack* self = self_of(filter);
  if (self->run == nullptr) return TRUE;
  const cv::Size size(GST_VIDEO_INFO_WIDTH(in_info), GST_VIDEO_INFO_HEIGHT(in_info));
  if (self->run->tracker && size != self->run->size) {
    GST_INFO_OBJECT(self, "frame size changed to %dx%d: the tracker restarts", size.width,
                    size.height);
    finish(self->run);
    self->run->tracker.reset();
  }
  self->run->size = size;
  return TRUE;
}

void draw_objects(GstVideoFrame* frame, const std::vector<tracking::TrackedObject>& objects) {
  cv::Mat luma(GST_VIDEO_FRAME_HEIGHT(frame), GST_VIDEO_FRAME_WIDTH(frame), CV_8UC1,
               GST_VIDEO_FRAME_PLANE_DATA(frame, 0),
               static_cast<std::size_t>(GST_VIDEO_FRAME_PLANE_STRIDE(frame, 0)));
  for (const tracking::TrackedObject& o : objects) {
    const cv::Rect box(cvRound(o.box.x), cvRound(o.box.y), cvRound(o.box.width),
                       cvRound(o.box.height));
    // found: white, lost (the prediction): black; global treatment: thinner
    const int thickness = o.mode == eval::TrackRecord::Mode::Local ? 2 : 1;
    cv::rectangle(luma, box, cv::Scalar(o.lost ? 0 : 255), thickness);
    cv::putText(luma, std::to_string(o.id), box.tl() + cv::Point(2, 14), cv::FONT_HERSHEY_SIMPLEX,
                0.5, cv::Scalar(o.lost ? 0 : 255), 1);
  }
}

void attach_meta(GstBuffer* buffer, const tracking::TrackedObject& o, long long index,
                 cv::Size size) {
  const auto clip = [](double v, int limit) {
    return static_cast<guint>(std::clamp(v, 0.0, static_cast<double>(limit)));
  };
  const guint x0 = clip(std::floor(o.box.x), size.width);
  const guint y0 = clip(std::floor(o.box.y), size.height);
  const guint x1 = clip(std::ceil(o.box.x + o.box.width), size.width);
  const guint y1 = clip(std::ceil(o.box.y + o.box.height), size.height);
  GstVideoRegionOfInterestMeta* meta = gst_buffer_add_video_region_of_interest_meta(
      buffer, "roiflow", x0, y0, x1 > x0 ? x1 - x0 : 0, y1 > y0 ? y1 - y0 : 0);
  meta->id = o.id;
  gst_video_region_of_interest_meta_add_param(
      meta,
      gst_structure_new(
          "roiflow/track", "id", G_TYPE_INT, o.id, "x", G_TYPE_DOUBLE, static_cast<double>(o.box.x),
          "y", G_TYPE_DOUBLE, static_cast<double>(o.box.y), "w", G_TYPE_DOUBLE,
          static_cast<double>(o.box.width), "h", G_TYPE_DOUBLE, static_cast<double>(o.box.height),
          "vx", G_TYPE_DOUBLE, static_cast<double>(o.velocity.x), "vy", G_TYPE_DOUBLE,
          static_cast<double>(o.velocity.y), "mode", G_TYPE_STRING, eval::to_string(o.mode), "lost",
          G_TYPE_BOOLEAN, static_cast<gboolean>(o.lost), "frame", G_TYPE_INT64,
          static_cast<gint64>(index), nullptr));
}

GstFlowReturn transform_frame_ip(GstVideoFilter* filter, GstVideoFrame* frame) {
  GstRoiflowTrack* self = self_of(filter);
  Run* run = self->run;
  if (run == nullptr) return GST_FLOW_FLUSHING;
  try {
    if (!run->tracker)
      run->tracker = std::make_unique<tracking::ObjectTracker>(run->params, &run->executor);
    const gst::OwnedFrame owned = gst::copy_frame(frame);
    tracking::TrackerInput in;
    in.index = run->index;
    in.gray = owned.gray;
    in.deferred_image = owned.picture;
    std::vector<tracking::TrackedObject> objects;
    run->arena.execute([&] { objects = run->tracker->update(in); });
    if (run->log) run->log->write(run->tracker->primary().record());
    for (const tracking::TrackedObject& o : objects)
      attach_meta(frame->buffer, o, run->index, owned.gray.size());
    if (run->draw) draw_objects(frame, objects);
    ++run->index;
  } catch (const Error& e) {
    GST_ELEMENT_ERROR(self, STREAM, FAILED, ("%s", e.what()), (nullptr));
    return GST_FLOW_ERROR;
  } catch (const cv::Exception& e) {
    GST_ELEMENT_ERROR(self, STREAM, FAILED, ("OpenCV: %s", e.err.c_str()), (nullptr));
    return GST_FLOW_ERROR;
  } catch (const std::exception& e) {
    GST_ELEMENT_ERROR(self, STREAM, FAILED, ("%s", e.what()), (nullptr));
    return GST_FLOW_ERROR;
  }
  return GST_FLOW_OK;
}

void finalize(GObject* object) {
  GstRoiflowTrack* self = self_of(object);
  destroy_run(self);
  delete self->settings;
  self->settings = nullptr;
  G_OBJECT_CLASS(gst_roiflow_track_parent_class)->finalize(object);
}

constexpr GParamFlags kReadyProp =
    static_cast<GParamFlags>(G_PARAM_READWRITE | G_PARAM_STATIC_STRINGS | GST_PARAM_MUTABLE_READY);

}  // namespace

static void gst_roiflow_track_class_init(GstRoiflowTrackClass* klass) {
  GST_DEBUG_CATEGORY_INIT(roiflow_track_debug, "roiflowtrack", 0, "roiflow tracker");
  GObjectClass* gobject_class = G_OBJECT_CLASS(klass);
  GstElementClass* element_class = GST_ELEMENT_CLASS(klass);
  GstBaseTransformClass* trans_class = GST_BASE_TRANSFORM_CLASS(klass);
  GstVideoFilterClass* filter_class = GST_VIDEO_FILTER_CLASS(klass);
  gobject_class->set_property = set_property;
  gobject_class->get_property = get_property;
  gobject_class->finalize = finalize;

  g_object_class_install_property(
      gobject_class, PROP_ROI,
      g_param_spec_int("roi", "ROI", "Side of the local region in pixels", 8, 4096, 50,
                       kReadyProp));
  g_object_class_install_property(
      gobject_class, PROP_MODE,
      g_param_spec_enum("mode", "Mode", "Tracking treatment", roiflow_track_mode_get_type(),
                        kModeLocal, kReadyProp));
  g_object_class_install_property(
      gobject_class, PROP_THREADS,
      g_param_spec_int("threads", "Threads", "Worker threads of the tracker (0 = all cores)", 0,
                       pipeline::kMaxThreads, 0, kReadyProp));
  g_object_class_install_property(
      gobject_class, PROP_INIT,
      g_param_spec_string("init", "Init boxes",
                          "Boxes to track from the first frame, \"x,y,w,h;x,y,w,h\" (empty: "
                          "find the moving object)",
                          "", kReadyProp));
  g_object_class_install_property(
      gobject_class, PROP_MAX_LOST,
      g_param_spec_int("max-lost", "Max lost",
                       "Frames an object may stay lost in a row before it is dropped (0 = never)",
                       0, G_MAXINT, 0, kReadyProp));
  g_object_class_install_property(
      gobject_class, PROP_LOG,
      g_param_spec_string("log", "Track log",
                          "Track log of object 1 (.csv or .json, as roiflow track --log)", "",
                          kReadyProp));
  g_object_class_install_property(
      gobject_class, PROP_DRAW,
      g_param_spec_boolean("draw", "Draw", "Paint the boxes into the frame's luma plane", FALSE,
                           kReadyProp));
  g_object_class_install_property(
      gobject_class, PROP_PRESET,
      g_param_spec_string("preset", "Preset", "LK parameter set: paper, accurate or fast", "paper",
                          kReadyProp));

  GstCaps* caps = gst_caps_from_string(GST_VIDEO_CAPS_MAKE("{ GRAY8, I420, NV12 }"));
  gst_element_class_add_pad_template(
      element_class, gst_pad_template_new("sink", GST_PAD_SINK, GST_PAD_ALWAYS, caps));
  gst_element_class_add_pad_template(
      element_class, gst_pad_template_new("src", GST_PAD_SRC, GST_PAD_ALWAYS, caps));
  gst_caps_unref(caps);
  gst_element_class_set_static_metadata(
      element_class, "roiflow tracker", "Filter/Analyzer/Video",
      "Tracks objects with dense Lucas-Kanade flow in a local region (global fallback) and "
      "attaches a GstVideoRegionOfInterestMeta per object",
      "roiflow");
  trans_class->start = start;
  trans_class->stop = stop;
  trans_class->sink_event = sink_event;
  filter_class->set_info = set_info;
  filter_class->transform_frame_ip = transform_frame_ip;
  gst_type_mark_as_plugin_api(roiflow_track_mode_get_type(), static_cast<GstPluginAPIFlags>(0));
}

static void gst_roiflow_track_init(GstRoiflowTrack* self) {
  self->settings = new Settings();
  self->run = nullptr;
  gst_base_transform_set_qos_enabled(GST_BASE_TRANSFORM(self), TRUE);
}
