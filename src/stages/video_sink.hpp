// VideoSink: frames out, as a video file or a folder of numbered PNG images.
//
//   roiflow::stages::VideoSink sink("run/annotated.mp4", source.fps(), source.size());
//   while (...) sink.write(annotate_frame(frame.image, out));   // 8-bit BGR or gray
//   cv::Mat png = sink.encode(picture);      // on any thread (e.g. a parallel graph node) ...
//   sink.write_encoded(png);                 // ... then written in order
//   std::cerr << sink.description() << ": " << sink.frames() << " frames\n";
//   sink.close();                                                // or let the destructor do it
//
// What the path means:
//   - an extension .mp4 or .mov (MPEG-4 part 2, fourcc mp4v), .avi (Motion JPEG, MJPG) or .mkv
//     (mp4v), in any case: a video written with OpenCV's FFmpeg backend;
//   - no extension, a trailing '/', or an existing directory: a folder of PNG frames
//     000001.png, 000002.png, ... (1-based, like the track log's frames), created if missing;
//     each frame is written atomically (see atomic_write.hpp), so the folder only ever holds
//     whole images;
//   - any other extension throws: "out.png" or "out.jpg" is more likely a mistake than a
//     folder's name (write "out.png/" to mean one).
// Errors throw roiflow::Error naming the path: bad fps or size, a video the backend cannot
// open (e.g. its directory does not exist), a folder that cannot be created, a frame that is
// empty, not 8-bit gray or BGR (gray is converted), or of another size than the sink's, and
// a write after close().
//
// close() is idempotent and the destructor calls it (never throwing), so a run interrupted by
// an exception still leaves a playable video holding every frame written so far. (A process
// killed outright cannot finalise an .mp4's index; .avi and PNG folders survive that better.)
// Not thread-safe, but for encode(): one writer at a time.
#pragma once

#include <memory>
#include <opencv2/core.hpp>
#include <string>

namespace cv {
class VideoWriter;
}

namespace roiflow::stages {

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

}  // namespace roiflow::stages
