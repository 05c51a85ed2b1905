// FlowFileSink: the raw flow of every frame pair of a video, one file per pair in a folder, as
// Middlebury .flo (float32, exact) or KITTI 16-bit PNG (u, v rounded to 1/64 px, a valid bit;
// about a tenth of the .flo's size). Files are named after frame t's 1-based number, like
// VideoSink's PNG frames: 000001.flo holds the flow from frame 1 to frame 2.
//
//   roiflow::video::FlowFileSink sink("run/flow", roiflow::video::FlowFileFormat::Kitti);
//   const cv::Mat flow(frame_t.size(), CV_32FC2, cv::Scalar(1.f, 2.f));
//   sink.write(flow);                          // run/flow/000001.png
//   cv::Mat bytes = sink.encode(flow);         // on any thread (e.g. a parallel graph node) ...
//   sink.write_encoded(bytes);                 // ... then written in order: 000002.png
//
// encode() is const and thread-safe; the costly part of a KITTI file (the 16-bit encoding and
// the PNG compression) happens there, so a graph can run it on several pairs at once and leave
// only the ordered write serial. A KITTI vector outside the format's [-512, 512) px range is
// written invalid (as unknown flow is) rather than failing the run. Each file is written
// atomically (atomic_write.hpp). Errors throw roiflow::Error naming the path: a folder that
// cannot be created, a flow that is not CV_32FC2, a file that cannot be written.
#pragma once

#include <opencv2/core.hpp>
#include <string>
#include <string_view>

namespace roiflow::video {

enum class FlowFileFormat { Flo, Kitti };

// "flo" or "kitti"; throws roiflow::Error naming anything else.
FlowFileFormat flow_file_format_from_string(std::string_view name);
const char* to_string(FlowFileFormat format);
// ".flo" or ".png"
const char* extension(FlowFileFormat format);

class FlowFileSink {
 public:
  // Creates `dir` (and its parents) when missing.
  FlowFileSink(const std::string& dir, FlowFileFormat format);

  void write(const cv::Mat& flow);
  // write() in two parts: encode() is thread-safe and returns the file's content (for .flo the
  // flow itself, for KITTI the PNG's bytes as a 1xN CV_8U row); write_encoded() writes the next
  // file from what encode() returned.
  cv::Mat encode(const cv::Mat& flow) const;
  void write_encoded(const cv::Mat& encoded);

  long long files() const { return files_; }
  FlowFileFormat format() const { return format_; }
  // e.g. "KITTI flow PNGs in 'run/flow/'"
  std::string description() const;

 private:
  std::string dir_;
  FlowFileFormat format_;
  long long files_ = 0;
};

}  // namespace roiflow::video
