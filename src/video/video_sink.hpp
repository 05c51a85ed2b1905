// Frames out, as a video file (.mp4, .mov, .mkv: mp4v; .avi: Motion JPEG; OpenCV's FFmpeg
// backend) or as a folder of numbered PNG images each written atomically (no extension, a
// trailing '/', or an existing directory); docs/STAGES.md has the details.
//
//   roiflow::video::VideoSink sink("run/annotated.mp4", 25.0, bgr.size());
//   sink.write(bgr);  // 8-bit BGR or gray, of that size
//   const cv::Mat png = sink.encode(bgr);  // on any thread (a parallel graph node) ...
//   sink.write_encoded(png);               // ... then written in order
//   std::cerr << sink.description() << ": " << sink.frames() << " frames\n";
//   sink.close();  // or let the destructor do it
#pragma once

#include <memory>
#include <opencv2/core.hpp>
#include <string>

namespace cv {
class VideoWriter;
}

namespace roiflow::video {

class VideoSink {
 public:
  VideoSink(const std::string& path, double fps, cv::Size size);
  ~VideoSink();
  VideoSink(VideoSink&&) noexcept;
  VideoSink& operator=(VideoSink&&) noexcept;

  void write(const cv::Mat& frame);
  // write() in two parts, so that the costly one runs on several frames at once: encode() is
  // const and thread-safe (it checks the frame, converts gray to BGR and, for a PNG folder,
  // encodes the PNG: a 1xN CV_8U row of its bytes); write_encoded() writes what encode()
  // returned, in order, one at a time. write(f) is write_encoded(encode(f)).
  cv::Mat encode(const cv::Mat& frame) const;
  void write_encoded(const cv::Mat& encoded);
  void close();

  long long frames() const;  // written so far
  // e.g. "video 'run/out.mp4' (mp4v, 25 fps, 640x480)" or "PNG frames in 'run/frames/' (640x480)"
  std::string description() const;

 private:
  std::string path_;
  double fps_ = 0;
  cv::Size size_;
  std::string codec_;                        // fourcc; empty for a PNG folder
  std::unique_ptr<cv::VideoWriter> writer_;  // null for a PNG folder
  long long frames_ = 0;
  bool closed_ = false;
};

}  // namespace roiflow::video
