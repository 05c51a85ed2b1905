#include "pipeline/dense_outputs.hpp"

#include <cmath>
#include <string>

#include "core/error.hpp"
#include "flow/color_code.hpp"

namespace roiflow::pipeline {

DenseOutputs::DenseOutputs(const DenseOutputOptions& options, double fps, cv::Size size) {
  if (options.video.empty() && options.flow_dir.empty()) {
    throw Error("dense outputs: neither a colour output nor a flow folder is given");
  }
  if (!(options.max_motion >= 0) || !std::isfinite(options.max_motion)) {
    throw Error("dense outputs: max motion must be >= 0 pixels, got " +
                std::to_string(options.max_motion));
  }
  max_motion_ = options.max_motion > 0 ? static_cast<float>(options.max_motion) : -1.f;
  if (!options.video.empty()) video_ = std::make_unique<video::VideoSink>(options.video, fps, size);
  if (!options.flow_dir.empty()) {
    flow_ = std::make_unique<video::FlowFileSink>(options.flow_dir, options.flow_format);
  }
}

std::vector<FlowSink> DenseOutputs::sinks() {
  std::vector<FlowSink> out;
  if (video_) {
    video::VideoSink* video = video_.get();
    const float max_motion = max_motion_;
    out.push_back({"video", [video](const FlowPair& p) { video->write_encoded(p.prepared); },
                   [video, max_motion](const FlowPair& p) {
                     return video->encode(flow::flow_to_color(p.flow->flow, max_motion));
                   }});
  }
  if (flow_) {
    video::FlowFileSink* files = flow_.get();
    out.push_back({"flow_files", [files](const FlowPair& p) { files->write_encoded(p.prepared); },
                   [files](const FlowPair& p) { return files->encode(p.flow->flow); }});
  }
  return out;
}

void DenseOutputs::close() {
  if (video_) video_->close();
}

std::string DenseOutputs::description() const {
  std::string text;
  if (video_) text = video_->description();
  if (flow_) text += (text.empty() ? "" : ", ") + flow_->description();
  return text;
}

}  // namespace roiflow::pipeline
