// roiflowflow: dense flow between consecutive frames as colour-coded video (gst_roiflow.hpp).
//
// Sink GRAY8, I420 or NV12 (the luma plane is the gray frame); source BGR of the same size and
// rate: each output frame is the Middlebury colour coding (flow::flow_to_color) of the flow
// from the previous input frame to this one; the first frame, and the first after a flush or a
// discontinuity, is white (no motion known). Why video and not the raw flow as meta: every
// downstream element understands video (encoders, displays, compositors), while a (u, v) float
// field has no standard GStreamer meta and would reach nothing but custom code; code that wants
// the numbers calls roiflow.dense_flow (Python) or `roiflow dense` / flow::DenseLK (C++) on the
// same frames. Each frame's pyramid is built once and serves two pairs.
#include <gst/video/gstvideofilter.h>
#include <gst/video/video.h>
#include <oneapi/tbb/task_arena.h>

#include <algorithm>
#include <cstring>
#include <exception>
#include <memory>
#include <string>
#include <thread>

#include "core/error.hpp"
#include "flow/color_code.hpp"
#include "flow/dense_lk.hpp"
#include "flow/pyramid.hpp"
#include "frame_copy.hpp"
#include "gst_roiflow.hpp"
#include "pipeline/tbb_executor.hpp"

GST_DEBUG_CATEGORY_STATIC(roiflow_flow_debug);
#define GST_CAT_DEFAULT roiflow_flow_debug

namespace {

using namespace roiflow;

enum { PROP_0, PROP_PRESET, PROP_THREADS, PROP_MAX_MOTION };

struct Settings {
  std::string preset = "paper";
  int threads = 0;
  double max_motion = 0;
};

struct Run {
  Run(const flow::LkParams& params, int threads) : arena(threads), lk(params, &executor) {}
  pipeline::TbbExecutor executor;
  tbb::task_arena arena;
  flow::DenseLK lk;
  std::shared_ptr<flow::Pyramid> previous;  // of the previous frame; null: none yet
  std::shared_ptr<flow::Pyramid> spare;     // recycled buffers
  flow::FlowResult result;
  float max_motion = -1.f;
};

int hardware_threads() {
  return std::clamp(static_cast<int>(std::thread::hardware_concurrency()), 1,
                    pipeline::kMaxThreads);
}

}  // namespace

struct GstRoiflowFlow {
  GstVideoFilter parent;
  Settings* settings;  // guarded by the object lock
  Run* run;
};
struct GstRoiflowFlowClass {
  GstVideoFilterClass parent_class;
};

G_DEFINE_TYPE(GstRoiflowFlow, gst_roiflow_flow, GST_TYPE_VIDEO_FILTER)

namespace {

GstRoiflowFlow* self_of(gpointer p) {
  return reinterpret_cast<GstRoiflowFlow*>(p);
}

void set_property(GObject* object, guint id, const GValue* value, GParamSpec* pspec) {
  GstRoiflowFlow* self = self_of(object);
  GST_OBJECT_LOCK(self);
  Settings& s = *self->settings;
  switch (id) {
    case PROP_PRESET:
      s.preset = g_value_get_string(value) ? g_value_get_string(value) : "paper";
      break;
    case PROP_THREADS:
      s.threads = g_value_get_int(value);
      break;
    case PROP_MAX_MOTION:
      s.max_motion = g_value_get_double(value);
      break;
    default:
      G_OBJECT_WARN_INVALID_PROPERTY_ID(object, id, pspec);
      break;
  }
  GST_OBJECT_UNLOCK(self);
}

void get_property(GObject* object, guint id, GValue* value, GParamSpec* pspec) {
  GstRoiflowFlow* self = self_of(object);
  GST_OBJECT_LOCK(self);
  const Settings& s = *self->settings;
  switch (id) {
    case PROP_PRESET:
      g_value_set_string(value, s.preset.c_str());
      break;
    case PROP_THREADS:
      g_value_set_int(value, s.threads);
      break;
    case PROP_MAX_MOTION:
      g_value_set_double(value, s.max_motion);
      break;
    default:
      G_OBJECT_WARN_INVALID_PROPERTY_ID(object, id, pspec);
      break;
  }
  GST_OBJECT_UNLOCK(self);
}

gboolean start(GstBaseTransform* trans) {
  GstRoiflowFlow* self = self_of(trans);
  GST_OBJECT_LOCK(self);
  const Settings s = *self->settings;
  GST_OBJECT_UNLOCK(self);
  delete self->run;
  self->run = nullptr;
  try {
    self->run =
        new Run(flow::LkParams::preset(s.preset), s.threads == 0 ? hardware_threads() : s.threads);
    self->run->max_motion = s.max_motion > 0 ? static_cast<float>(s.max_motion) : -1.f;
  } catch (const Error& e) {
    GST_ELEMENT_ERROR(self, LIBRARY, SETTINGS, ("%s", e.what()), (nullptr));
    return FALSE;
  }
  return TRUE;
}

gboolean stop(GstBaseTransform* trans) {
  GstRoiflowFlow* self = self_of(trans);
  delete self->run;
  self->run = nullptr;
  return TRUE;
}

gboolean sink_event(GstBaseTransform* trans, GstEvent* event) {
  GstRoiflowFlow* self = self_of(trans);
  if (GST_EVENT_TYPE(event) == GST_EVENT_FLUSH_STOP && self->run != nullptr) {
    self->run->previous.reset();  // no flow across a seek
  }
  return GST_BASE_TRANSFORM_CLASS(gst_roiflow_flow_parent_class)->sink_event(trans, event);
}

// Sink GRAY8/I420/NV12 <-> source BGR, the other fields kept.
GstCaps* transform_caps(GstBaseTransform*, GstPadDirection direction, GstCaps* caps,
                        GstCaps* filter) {
  GstCaps* out = gst_caps_new_empty();
  for (guint i = 0; i < gst_caps_get_size(caps); ++i) {
    GstStructure* s = gst_structure_copy(gst_caps_get_structure(caps, i));
    gst_structure_remove_fields(s, "format", "colorimetry", "chroma-site", nullptr);
    if (direction == GST_PAD_SINK) {
      gst_structure_set(s, "format", G_TYPE_STRING, "BGR", nullptr);
    } else {
      GValue list = G_VALUE_INIT;
      GValue v = G_VALUE_INIT;
      gst_value_list_init(&list, 3);
      g_value_init(&v, G_TYPE_STRING);
      for (const char* format : {"GRAY8", "I420", "NV12"}) {
        g_value_set_string(&v, format);
        gst_value_list_append_value(&list, &v);
      }
      g_value_unset(&v);
      gst_structure_take_value(s, "format", &list);
    }
    out = gst_caps_merge_structure(out, s);
  }
  if (filter != nullptr) {
    GstCaps* both = gst_caps_intersect_full(filter, out, GST_CAPS_INTERSECT_FIRST);
    gst_caps_unref(out);
    out = both;
  }
  return out;
}

GstFlowReturn transform_frame(GstVideoFilter* filter, GstVideoFrame* in, GstVideoFrame* out) {
  GstRoiflowFlow* self = self_of(filter);
  Run* run = self->run;
  if (run == nullptr) return GST_FLOW_FLUSHING;
  try {
    const gst::OwnedFrame frame = gst::copy_frame(in);
    const cv::Size size = frame.gray.size();
    if (GST_BUFFER_FLAG_IS_SET(in->buffer, GST_BUFFER_FLAG_DISCONT)) run->previous.reset();
    if (run->previous && run->previous->size() != size) run->previous.reset();
    const int levels = flow::flow_pyramid_levels(size, run->lk.params(), {});
    std::shared_ptr<flow::Pyramid> current =
        run->spare ? run->spare : std::make_shared<flow::Pyramid>();
    run->spare.reset();
    cv::Mat color;
    run->arena.execute([&] {
      flow::build_pyramid(frame.gray, levels, run->lk.params().sigma, *current);
      if (run->previous) {
        run->lk.calc(*run->previous, *current, run->result);
        color = flow::flow_to_color(run->result.flow, run->max_motion);
      }
    });
    run->spare = run->previous;
    run->previous = current;
    cv::Mat target(GST_VIDEO_FRAME_HEIGHT(out), GST_VIDEO_FRAME_WIDTH(out), CV_8UC3,
                   GST_VIDEO_FRAME_PLANE_DATA(out, 0),
                   static_cast<std::size_t>(GST_VIDEO_FRAME_PLANE_STRIDE(out, 0)));
    if (color.empty()) {
      target.setTo(cv::Scalar::all(255));
    } else {
      color.copyTo(target);
    }
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
  GstRoiflowFlow* self = self_of(object);
  delete self->run;
  self->run = nullptr;
  delete self->settings;
  self->settings = nullptr;
  G_OBJECT_CLASS(gst_roiflow_flow_parent_class)->finalize(object);
}

constexpr GParamFlags kReadyProp =
    static_cast<GParamFlags>(G_PARAM_READWRITE | G_PARAM_STATIC_STRINGS | GST_PARAM_MUTABLE_READY);

}  // namespace

static void gst_roiflow_flow_class_init(GstRoiflowFlowClass* klass) {
  GST_DEBUG_CATEGORY_INIT(roiflow_flow_debug, "roiflowflow", 0, "roiflow dense flow");
  GObjectClass* gobject_class = G_OBJECT_CLASS(klass);
  GstElementClass* element_class = GST_ELEMENT_CLASS(klass);
  GstBaseTransformClass* trans_class = GST_BASE_TRANSFORM_CLASS(klass);
  GstVideoFilterClass* filter_class = GST_VIDEO_FILTER_CLASS(klass);
  gobject_class->set_property = set_property;
  gobject_class->get_property = get_property;
  gobject_class->finalize = finalize;
  g_object_class_install_property(
      gobject_class, PROP_PRESET,
      g_param_spec_string("preset", "Preset", "LK parameter set: paper, accurate or fast", "paper",
                          kReadyProp));
  g_object_class_install_property(
      gobject_class, PROP_THREADS,
      g_param_spec_int("threads", "Threads", "Worker threads of the flow (0 = all cores)", 0,
                       pipeline::kMaxThreads, 0, kReadyProp));
  g_object_class_install_property(
      gobject_class, PROP_MAX_MOTION,
      g_param_spec_double("max-motion", "Max motion",
                          "Flow magnitude (pixels) at full colour saturation (0 = each frame's "
                          "largest)",
                          0.0, 1e6, 0.0, kReadyProp));

  GstCaps* sink = gst_caps_from_string(GST_VIDEO_CAPS_MAKE("{ GRAY8, I420, NV12 }"));
  GstCaps* src = gst_caps_from_string(GST_VIDEO_CAPS_MAKE("BGR"));
  gst_element_class_add_pad_template(
      element_class, gst_pad_template_new("sink", GST_PAD_SINK, GST_PAD_ALWAYS, sink));
  gst_element_class_add_pad_template(element_class,
                                     gst_pad_template_new("src", GST_PAD_SRC, GST_PAD_ALWAYS, src));
  gst_caps_unref(sink);
  gst_caps_unref(src);
  gst_element_class_set_static_metadata(
      element_class, "roiflow dense flow", "Filter/Analyzer/Video",
      "Dense Lucas-Kanade flow between consecutive frames, as Middlebury colour-coded video",
      "roiflow");
  trans_class->start = start;
  trans_class->stop = stop;
  trans_class->sink_event = sink_event;
  trans_class->transform_caps = transform_caps;
  trans_class->passthrough_on_same_caps = FALSE;
  filter_class->transform_frame = transform_frame;
}

static void gst_roiflow_flow_init(GstRoiflowFlow* self) {
  self->settings = new Settings();
  self->run = nullptr;
  gst_base_transform_set_qos_enabled(GST_BASE_TRANSFORM(self), TRUE);
}
