// The Python module `roiflow` (pybind11): dense flow, .flo files, colour coding and the tracker
// on NumPy arrays.
//
//   import numpy as np, roiflow
//   a = roiflow.read_gray("frame10.png"); b = roiflow.read_gray("frame11.png")
//   flow = roiflow.dense_flow(a, b, preset="paper", patch=10)   # (H, W, 2) float32, (u, v)
//   roiflow.write_flo("out.flo", flow)
//   tracker = roiflow.Tracker(init=(70, 51, 107, 87))
//   for index, objects in roiflow.track("car.mp4", init=(70, 51, 107, 87)):
//       print(index, [(o.id, o.box) for o in objects])
//
// Frames are taken without a copy when NumPy's layout allows (each row contiguous, any row
// stride): dense_flow reads them in place and writes its result into a fresh (or the given
// `out`) array in place. The Tracker copies each frame, because it keeps the previous one for
// the next frame's flow and NumPy may reuse the buffer. The GIL is released while roiflow
// computes (flow, tracking, decoding, file I/O). roiflow's errors arrive as roiflow.Error (a
// ValueError) with the CLI's one-line message; wrong types raise TypeError.
#include <oneapi/tbb/task_arena.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <algorithm>
#include <memory>
#include <opencv2/imgproc.hpp>
#include <optional>
#include <string>
#include <vector>

#include "core/error.hpp"
#include "eval/flo_io.hpp"
#include "eval/flow_eval.hpp"
#include "eval/image_io.hpp"
#include "flow/color_code.hpp"
#include "flow/dense_lk.hpp"
#include "flow/metrics.hpp"
#include "pipeline/tbb_executor.hpp"
#include "tracking/object_tracker.hpp"
#include "video/video_source.hpp"

namespace py = pybind11;
using namespace roiflow;

namespace {

// ------------------------------------------------------------------------------ arrays <-> Mat

int depth_of(const py::dtype& dtype) {
  if (dtype.is(py::dtype::of<std::uint8_t>())) return CV_8U;
  if (dtype.is(py::dtype::of<std::uint16_t>())) return CV_16U;
  if (dtype.is(py::dtype::of<float>())) return CV_32F;
  return -1;
}

// A Mat over `array`'s memory when each row is contiguous (elements and channels packed), else
// over a C-contiguous copy held in `keep`. `channels`: the allowed channel counts (1 = 2-D).
cv::Mat as_mat(const py::array& array, const char* what, const std::vector<int>& allowed_depths,
               const std::vector<int>& allowed_channels, py::array& keep) {
  const int depth = depth_of(array.dtype());
  if (depth < 0 ||
      std::find(allowed_depths.begin(), allowed_depths.end(), depth) == allowed_depths.end()) {
    throw py::type_error(std::string(what) + ": unsupported dtype " +
                         std::string(py::str(array.dtype())));
  }
  const int channels = array.ndim() == 2   ? 1
                       : array.ndim() == 3 ? static_cast<int>(array.shape(2))
                                           : -1;
  if (channels < 0 || std::find(allowed_channels.begin(), allowed_channels.end(), channels) ==
                          allowed_channels.end()) {
    std::string shapes;
    for (int c : allowed_channels)
      shapes += std::string(shapes.empty() ? "" : " or ") +
                (c == 1 ? "(H, W)" : "(H, W, " + std::to_string(c) + ")");
    throw py::type_error(std::string(what) + ": expected an array of shape " + shapes + ", got " +
                         std::to_string(array.ndim()) + " dimensions" +
                         (array.ndim() == 3
                              ? " with " + std::to_string(array.shape(2)) + " channels"
                              : std::string()));
  }
  const auto item = static_cast<py::ssize_t>(array.itemsize());
  const bool packed = array.strides(1) == item * channels &&
                      (channels == 1 || array.strides(2) == item) && array.strides(0) > 0 &&
                      array.strides(0) % item == 0 &&
                      array.strides(0) >= array.shape(1) * item * channels;
  py::array source = array;
  if (!packed) {
    keep = py::array::ensure(array, py::array::c_style | py::array::forcecast);
    source = keep;
  }
  const int rows = static_cast<int>(source.shape(0));
  const int cols = static_cast<int>(source.shape(1));
  if (rows == 0 || cols == 0) throw Error(std::string(what) + ": empty image");
  return cv::Mat(rows, cols, CV_MAKETYPE(depth, channels), const_cast<void*>(source.data()),
                 static_cast<std::size_t>(source.strides(0)));
}

py::array_t<float> new_flow_array(cv::Size size) {
  return py::array_t<float>({static_cast<py::ssize_t>(size.height),
                             static_cast<py::ssize_t>(size.width), py::ssize_t{2}});
}

cv::Mat flow_view(py::array_t<float>& a) {
  return cv::Mat(static_cast<int>(a.shape(0)), static_cast<int>(a.shape(1)), CV_32FC2,
                 a.mutable_data(), static_cast<std::size_t>(a.strides(0)));
}

py::array mat_to_array(const cv::Mat& m) {
  std::vector<py::ssize_t> shape = {m.rows, m.cols};
  if (m.channels() > 1) shape.push_back(m.channels());
  py::dtype dtype = m.depth() == CV_8U    ? py::dtype::of<std::uint8_t>()
                    : m.depth() == CV_16U ? py::dtype::of<std::uint16_t>()
                                          : py::dtype::of<float>();
  py::array out(dtype, shape);
  cv::Mat view(m.rows, m.cols, m.type(), out.mutable_data());
  m.copyTo(view);
  return out;
}

// (H, W, 2) float32 flow (copied when not packed).
cv::Mat flow_mat(const py::array& flow, const char* what, py::array& keep) {
  cv::Mat m = as_mat(flow, what, {CV_32F}, {2}, keep);
  return m;
}

// --------------------------------------------------------------------------------- parameters

int as_int(const py::handle& value, const std::string& name) {
  if (py::isinstance<py::bool_>(value) || !py::isinstance<py::int_>(value)) {
    throw py::type_error(name + ": expected an int, got " +
                         std::string(py::str(py::type::of(value).attr("__name__"))));
  }
  return value.cast<int>();
}

double as_double(const py::handle& value, const std::string& name) {
  if (py::isinstance<py::bool_>(value) ||
      !(py::isinstance<py::int_>(value) || py::isinstance<py::float_>(value))) {
    throw py::type_error(name + ": expected a number, got " +
                         std::string(py::str(py::type::of(value).attr("__name__"))));
  }
  return value.cast<double>();
}

// The preset with the keyword overrides applied (the CLI's LK options, spelled with '_';
// `lambda_` for --lambda), validated as the CLI validates them.
flow::LkParams lk_params(const std::string& preset, const py::kwargs& kwargs,
                         const char* function) {
  flow::LkParams p = flow::LkParams::preset(preset);
  for (const auto& item : kwargs) {
    const std::string key = py::str(item.first);
    const py::handle v = item.second;
    if (key == "patch")
      p.patch = as_int(v, key);
    else if (key == "levels") {
      if (py::isinstance<py::str>(v) && v.cast<std::string>() == "auto")
        p.levels = 0;
      else
        p.levels = as_int(v, key);
    } else if (key == "iterations")
      p.iterations = as_int(v, key);
    else if (key == "sigma")
      p.sigma = as_double(v, key);
    else if (key == "lambda_" || key == "lambda")
      p.lambda = as_double(v, key);
    else if (key == "robust_scale")
      p.robust_scale = as_double(v, key);
    else if (key == "level_median")
      p.level_median = as_int(v, key);
    else if (key == "final_median")
      p.final_median = as_int(v, key);
    else if (key == "derivative")
      p.derivative = flow::derivative_from_string(v.cast<std::string>());
    else if (key == "expected_motion")
      p.expected_motion = as_double(v, key);
    else if (key == "coarsest_side")
      p.coarsest_side = as_int(v, key);
    else if (key == "search_radius")
      p.search_radius = as_int(v, key);
    else if (key == "fuse_far_step")
      p.fuse_far_step = as_int(v, key);
    else if (key == "fuse_far_finest_level")
      p.fuse_far_finest_level = as_int(v, key);
    else if (key == "fuse_step")
      p.fuse_step = as_int(v, key);
    else if (key == "fuse_finest_level")
      p.fuse_finest_level = as_int(v, key);
    else if (key == "mask_outside")
      p.mask_outside = as_int(v, key) != 0;
    else if (key == "finest_level")
      p.finest_level = as_int(v, key);
    else {
      throw py::type_error(std::string(function) + "() got an unexpected keyword argument '" + key +
                           "'");
    }
  }
  p.validate();
  return p;
}

int check_threads(int threads) {
  if (threads < 1 || threads > pipeline::kMaxThreads) {
    throw Error("threads must be in 1.." + std::to_string(pipeline::kMaxThreads) + ", got " +
                std::to_string(threads));
  }
  return threads;
}

// ---------------------------------------------------------------------------------- dense flow

py::array dense_flow(const py::array& a, const py::array& b, const std::string& preset, int threads,
                     std::optional<py::array_t<float>> out, const py::kwargs& kwargs) {
  const flow::LkParams params = lk_params(preset, kwargs, "dense_flow");
  check_threads(threads);
  py::array keep_a, keep_b;
  const std::vector<int> depths = {CV_8U, CV_16U, CV_32F};
  const cv::Mat frame_t = as_mat(a, "dense_flow: a", depths, {1, 3}, keep_a);
  const cv::Mat frame_t1 = as_mat(b, "dense_flow: b", depths, {1, 3}, keep_b);
  if (frame_t.size() != frame_t1.size() || frame_t.type() != frame_t1.type()) {
    throw Error("dense_flow: a and b differ in shape or dtype");
  }
  eval::check_frame_size(frame_t.size(), "dense_flow: a");
  if ((frame_t.channels() == 3) && frame_t.depth() != CV_8U) {
    throw py::type_error("dense_flow: 3-channel frames must be uint8 (BGR)");
  }
  py::array_t<float> result_array;
  if (out) {
    result_array = *out;
    if (result_array.ndim() != 3 || result_array.shape(0) != frame_t.rows ||
        result_array.shape(1) != frame_t.cols || result_array.shape(2) != 2 ||
        result_array.strides(2) != 4 || result_array.strides(1) != 8 || !result_array.writeable()) {
      throw Error("dense_flow: out must be a writeable (H, W, 2) float32 array with packed rows");
    }
  } else {
    result_array = new_flow_array(frame_t.size());
  }
  flow::FlowResult result;
  result.flow = flow_view(result_array);
  const uchar* target = result.flow.data;
  {
    py::gil_scoped_release release;
    pipeline::TbbExecutor executor;
    tbb::task_arena arena(threads);
    arena.execute([&] {
      flow::DenseLK lk(params, &executor);
      lk.calc(frame_t, frame_t1, result);
    });
  }
  if (result.flow.data != target) {  // the flow was written elsewhere: copy it in
    cv::Mat view = flow_view(result_array);
    result.flow.copyTo(view);
  }
  return result_array;
}

// ------------------------------------------------------------------------------------ tracker

tracking::TrackerParams tracker_params(const std::string& mode, int roi, const std::string& preset,
                                       const py::kwargs& kwargs, const char* function) {
  tracking::TrackerParams p;
  p.mode = tracking::track_mode_from_string(mode);
  p.roi = roi;
  p.lk = lk_params(preset, kwargs, function);
  return p;
}

cv::Rect2f box_from(const py::handle& h) {
  std::vector<double> v;
  try {
    v = h.cast<std::vector<double>>();
  } catch (const py::cast_error&) {
    throw Error("init: a box is 4 numbers (x, y, w, h), got " + std::string(py::repr(h)));
  }
  if (v.size() != 4) {
    throw Error("init: a box is 4 numbers (x, y, w, h), got " + std::string(py::repr(h)));
  }
  return {static_cast<float>(v[0]), static_cast<float>(v[1]), static_cast<float>(v[2]),
          static_cast<float>(v[3])};
}

// None, one box (x, y, w, h) or a sequence of boxes.
std::vector<cv::Rect2f> boxes_from(const py::object& init) {
  std::vector<cv::Rect2f> boxes;
  if (init.is_none()) return boxes;
  if (!py::isinstance<py::sequence>(init) || py::isinstance<py::str>(init)) {
    throw Error("init: expected a box (x, y, w, h) or a list of boxes, got " +
                std::string(py::repr(init)));
  }
  const py::sequence seq = init.cast<py::sequence>();
  if (seq.size() > 0 && !py::isinstance<py::sequence>(seq[0])) {
    boxes.push_back(box_from(seq));
    return boxes;
  }
  for (const py::handle item : seq)
    boxes.push_back(box_from(item));
  return boxes;
}

class PyTracker {
 public:
  PyTracker(const py::object& init, const std::string& mode, int roi, int max_lost,
            const std::string& preset, int threads, const py::kwargs& kwargs)
      : arena_(check_threads(threads)) {
    tracking::ObjectTrackerParams params;
    params.tracker = tracker_params(mode, roi, preset, kwargs, "Tracker");
    params.init = boxes_from(init);
    params.max_lost = max_lost;
    tracker_ = std::make_unique<tracking::ObjectTracker>(params, &executor_);
  }
  ~PyTracker() {
    arena_.execute([&] { tracker_->finish_background_work(); });
  }

  std::vector<tracking::TrackedObject> update(const py::array& frame) {
    py::array keep;
    const cv::Mat view = as_mat(frame, "Tracker.update: frame", {CV_8U}, {1, 3}, keep);
    eval::check_frame_size(view.size(), "Tracker.update: frame");
    std::vector<tracking::TrackedObject> objects;
    py::gil_scoped_release release;
    tracking::TrackerInput in;
    in.index = index_;
    if (view.channels() == 3) {
      in.image = view.clone();
      cv::cvtColor(in.image, in.gray, cv::COLOR_BGR2GRAY);
    } else {
      in.gray = view.clone();
      in.image = in.gray;
    }
    arena_.execute([&] { objects = tracker_->update(in); });
    ++index_;
    return objects;
  }

  long long frames() const { return index_; }

 private:
  pipeline::TbbExecutor executor_;
  tbb::task_arena arena_;
  std::unique_ptr<tracking::ObjectTracker> tracker_;
  long long index_ = 0;
};

// roiflow.track(path, ...): an iterator of (index, objects), one per frame of the input.
class TrackIterator {
 public:
  TrackIterator(const std::string& input, const py::object& init, const std::string& mode, int roi,
                int max_lost, long long start, long long max_frames, const std::string& preset,
                int threads, const py::kwargs& kwargs)
      : arena_(check_threads(threads)) {
    tracking::ObjectTrackerParams params;
    params.tracker = tracker_params(mode, roi, preset, kwargs, "track");
    params.init = boxes_from(init);
    params.max_lost = max_lost;
    params.validate();
    video::VideoSourceParams source_params;
    source_params.start = start;
    source_params.max_frames = max_frames;
    source_params.defer_colour = true;
    {
      py::gil_scoped_release release;
      source_ = std::make_unique<video::VideoSource>(input, source_params);
    }
    tracker_ = std::make_unique<tracking::ObjectTracker>(params, &executor_);
  }
  ~TrackIterator() {
    arena_.execute([&] { tracker_->finish_background_work(); });
  }

  py::tuple next() {
    std::optional<video::Frame> frame;
    std::vector<tracking::TrackedObject> objects;
    {
      py::gil_scoped_release release;
      frame = source_->next();
      if (frame) {
        arena_.execute([&] {
          objects = tracker_->update(
              {frame->index, frame->image, frame->gray, nullptr, frame->deferred_image});
        });
      }
    }
    if (!frame) {
      if (source_->status().state == video::SourceStatus::State::kStopped) {
        throw Error("input " + source_->status().message);
      }
      throw py::stop_iteration();
    }
    return py::make_tuple(frame->index, objects);
  }

  cv::Size size() const { return source_->size(); }
  double fps() const { return source_->fps(); }

 private:
  pipeline::TbbExecutor executor_;
  tbb::task_arena arena_;
  std::unique_ptr<video::VideoSource> source_;
  std::unique_ptr<tracking::ObjectTracker> tracker_;
};

const char* mode_name(eval::TrackRecord::Mode m) {
  return eval::to_string(m);
}

}  // namespace

PYBIND11_MODULE(roiflow, m) {
  m.doc() =
      "roiflow: dense pyramidal Lucas-Kanade optical flow and ROI tracking on NumPy arrays "
      "(docs/DROPIN.md)";
  static py::exception<Error> error(m, "Error", PyExc_ValueError);
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const Error& e) {
      PyErr_SetString(error.ptr(), e.what());
    } catch (const cv::Exception& e) {
      PyErr_SetString(error.ptr(), ("OpenCV: " + e.err).c_str());
    }
  });

  m.def("dense_flow", &dense_flow, py::arg("a"), py::arg("b"), py::arg("preset") = "paper",
        py::arg("threads") = 1, py::arg("out") = py::none(),
        "Dense flow from frame a to frame b: (H, W, 2) float32 (u right, v down, pixels).\n"
        "a, b: (H, W) uint8/uint16/float32 (float in [0, 1]) or (H, W, 3) uint8 BGR.\n"
        "preset: paper | accurate | fast; keyword overrides as the CLI's LK options\n"
        "(patch, levels, iterations, sigma, lambda_, derivative, ...). out: an array to write.");
  m.def(
      "read_flo",
      [](const std::string& path) {
        cv::Mat flow;
        {
          py::gil_scoped_release release;
          flow = eval::read_flo(path);
        }
        return mat_to_array(flow);
      },
      py::arg("path"), "A Middlebury .flo file as an (H, W, 2) float32 array.");
  m.def(
      "write_flo",
      [](const std::string& path, const py::array& flow) {
        py::array keep;
        const cv::Mat mat = flow_mat(flow, "write_flo: flow", keep);
        py::gil_scoped_release release;
        eval::write_flo(path, mat);
      },
      py::arg("path"), py::arg("flow"), "Writes an (H, W, 2) float32 flow as .flo (atomically).");
  m.def(
      "flow_to_color",
      [](const py::array& flow, float max_magnitude) {
        py::array keep;
        const cv::Mat mat = flow_mat(flow, "flow_to_color: flow", keep);
        cv::Mat bgr;
        {
          py::gil_scoped_release release;
          bgr = flow::flow_to_color(mat, max_magnitude);
        }
        return mat_to_array(bgr);
      },
      py::arg("flow"), py::arg("max_magnitude") = -1.f,
      "Middlebury colour coding: (H, W, 3) uint8 BGR; max_magnitude <= 0: the field's largest.");
  m.def(
      "read_gray",
      [](const std::string& path) {
        cv::Mat gray;
        {
          py::gil_scoped_release release;
          gray = eval::read_gray(path);
        }
        return mat_to_array(gray);
      },
      py::arg("path"), "An image file as (H, W) uint8 gray, decoded as roiflow flow does.");
  m.def(
      "flow_errors",
      [](const py::array& estimate, const py::array& truth) {
        py::array keep_e, keep_t;
        const cv::Mat e = flow_mat(estimate, "flow_errors: estimate", keep_e);
        const cv::Mat t = flow_mat(truth, "flow_errors: truth", keep_t);
        if (e.size() != t.size()) throw Error("flow_errors: estimate and truth differ in shape");
        const flow::FlowErrors r = flow::flow_errors(e, t);
        py::dict d;
        d["aae_deg"] = r.aae_deg;
        d["epe"] = r.epe;
        d["r1"] = r.r1;
        d["r3"] = r.r3;
        d["fl"] = r.fl;
        d["pixels"] = r.pixels;
        return d;
      },
      py::arg("estimate"), py::arg("truth"),
      "AAE (deg), EPE (px), R1, R3, Fl (%) and pixels counted, as roiflow eval computes them.");
  m.def("presets", &flow::LkParams::preset_names, "The LK presets' names.");

  py::class_<tracking::TrackedObject>(m, "TrackedObject")
      .def_readonly("id", &tracking::TrackedObject::id)
      .def_property_readonly("box",
                             [](const tracking::TrackedObject& o) {
                               return py::make_tuple(o.box.x, o.box.y, o.box.width, o.box.height);
                             })
      .def_property_readonly("velocity",
                             [](const tracking::TrackedObject& o) {
                               return py::make_tuple(o.velocity.x, o.velocity.y);
                             })
      .def_property_readonly("mode",
                             [](const tracking::TrackedObject& o) { return mode_name(o.mode); })
      .def_readonly("lost", &tracking::TrackedObject::lost)
      .def_readonly("lost_frames", &tracking::TrackedObject::lost_frames)
      .def("__repr__", [](const tracking::TrackedObject& o) {
        return "TrackedObject(id=" + std::to_string(o.id) + ", box=(" + std::to_string(o.box.x) +
               ", " + std::to_string(o.box.y) + ", " + std::to_string(o.box.width) + ", " +
               std::to_string(o.box.height) + "), mode=" + mode_name(o.mode) +
               (o.lost ? ", lost" : "") + ")";
      });

  py::class_<PyTracker>(m, "Tracker",
                        "Tracks objects over frames given one at a time. init: None (find the "
                        "moving object), a box (x, y, w, h) or a list of boxes.")
      .def(py::init<const py::object&, const std::string&, int, int, const std::string&, int,
                    const py::kwargs&>(),
           py::arg("init") = py::none(), py::arg("mode") = "local", py::arg("roi") = 50,
           py::arg("max_lost") = 0, py::arg("preset") = "paper", py::arg("threads") = 1)
      .def("update", &PyTracker::update, py::arg("frame"),
           "Tracks one frame ((H, W) uint8 gray or (H, W, 3) uint8 BGR); returns its objects.")
      .def_property_readonly("frames", &PyTracker::frames);

  py::class_<TrackIterator>(m, "TrackIterator")
      .def("__iter__", [](TrackIterator& self) -> TrackIterator& { return self; })
      .def("__next__", &TrackIterator::next)
      .def_property_readonly(
          "size",
          [](const TrackIterator& t) { return py::make_tuple(t.size().width, t.size().height); })
      .def_property_readonly("fps", &TrackIterator::fps);

  m.def(
      "track",
      [](const std::string& input, const py::object& init, const std::string& mode, int roi,
         int max_lost, long long start, long long max_frames, const std::string& preset,
         int threads, const py::kwargs& kwargs) {
        return std::make_unique<TrackIterator>(input, init, mode, roi, max_lost, start, max_frames,
                                               preset, threads, kwargs);
      },
      py::arg("input"), py::arg("init") = py::none(), py::arg("mode") = "local",
      py::arg("roi") = 50, py::arg("max_lost") = 0, py::arg("start") = 0, py::arg("max_frames") = 0,
      py::arg("preset") = "paper", py::arg("threads") = 1,
      "Iterates (index, objects) over the frames of a video, image folder or synthetic:N input.");
}
