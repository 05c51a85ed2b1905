// What dense mode writes for each frame pair: the colour-coded flow (a video or a folder of
// PNGs) and the raw flow (a folder of .flo or KITTI 16-bit PNG files), as run_dense sinks whose
// costly part (colour coding, PNG and KITTI encoding) runs on several pairs at once
// (FlowSink::prepare) and whose write alone is serial and in pair order.
//
//   using namespace roiflow;
//   pipeline::DenseOutputOptions out;
//   out.video = "run/colour/";                        // PNG folder (or "run/flow.mp4")
//   out.flow_dir = "run/flow";                        // run/flow/000001.png, ...
//   out.flow_format = video::FlowFileFormat::Kitti;
//   video::VideoSource source("synthetic:10");
//   pipeline::DenseOutputs outputs(out, source.fps(), source.size());
//   pipeline::run_dense([&] { return source.next(); }, flow::LkParams::paper(), outputs.sinks());
//   outputs.close();
//
// Colour scale: `max_motion` pixels saturate when it is > 0; otherwise each pair's robust
// maximum (flow::robust_max_magnitude: a high percentile of its magnitudes, so a few outliers
// do not wash the picture out).
#pragma once

#include <memory>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "pipeline/frame_graph.hpp"
#include "video/flow_file_sink.hpp"
#include "video/video_sink.hpp"

namespace roiflow::pipeline {

struct DenseOutputOptions {
  std::string video;     // colour-coded flow: video file or PNG folder (VideoSink); empty = none
  std::string flow_dir;  // raw flow, one file per pair (FlowFileSink); empty = none
  video::FlowFileFormat flow_format = video::FlowFileFormat::Flo;
  double max_motion = 0;  // pixels at full colour saturation; 0 = each pair's robust maximum
};

class DenseOutputs {
 public:
  // Opens the outputs asked for (throws roiflow::Error as VideoSink and FlowFileSink do, or
  // when none is asked for, or max_motion is negative or not finite).
  DenseOutputs(const DenseOutputOptions& options, double fps, cv::Size size);

  // "video" and/or "flow", each with its parallel prepare; valid while this object lives.
  std::vector<FlowSink> sinks();
  void close();
  // e.g. "PNG frames in 'run/colour/' (640x480), KITTI flow PNGs in 'run/flow'"
  std::string description() const;

 private:
  float max_motion_ = -1.f;
  std::unique_ptr<video::VideoSink> video_;
  std::unique_ptr<video::FlowFileSink> flow_;
};

}  // namespace roiflow::pipeline
