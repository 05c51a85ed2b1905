// The frames of a video file decoded with FFmpeg's libavformat/libavcodec, in order, as 8-bit
// gray (the decoder's own luma plane, no conversion) and 8-bit BGR (one conversion, or deferred),
// buffers recycled. VideoSource reads video files through it; docs/STAGES.md says why not
// cv::VideoCapture.
//
//   roiflow::video::VideoDecoder video("car.mp4");
//   roiflow::video::DecodedFrame f;
//   std::string failure;
//   while (video.read(f, failure)) std::cout << f.timestamp_s << " s\n";
//   if (!failure.empty()) std::cerr << failure << '\n';  // a decode error, not the end
#pragma once

#include <memory>
#include <opencv2/core.hpp>
#include <string>

#include "video/deferred_image.hpp"

namespace roiflow::video {

struct DecodedFrame {
  cv::Mat bgr;  // 8-bit, 3 channels; empty when `deferred_bgr` holds it
  // With defer_bgr, the BGR picture converted when first asked for (from any thread; the
  // decoder's planes are held until then). Null when `bgr` is set.
  std::shared_ptr<const DeferredImage> deferred_bgr;
  cv::Mat gray;  // 8-bit, 1 channel, the same size
  // Presentation time in seconds from the stream's start, or a negative value when the
  // container gives none for this frame.
  double timestamp_s = -1;
};

class VideoDecoder {
 public:
  static constexpr long long kSingleThreadPixels = 1280LL * 720;

  explicit VideoDecoder(const std::string& path, int threads = 0, bool defer_bgr = false);
  ~VideoDecoder();
  VideoDecoder(const VideoDecoder&) = delete;
  VideoDecoder& operator=(const VideoDecoder&) = delete;

  // The next frame into `frame` (fresh or recycled buffers: a frame handed out earlier is never
  // overwritten while its Mats are still referenced elsewhere).
  bool read(DecodedFrame& frame, std::string& failure);

  cv::Size size() const;          // as announced by the stream
  double fps() const;             // the stream's frame rate; 0 when it gives none
  long long frame_count() const;  // announced or estimated from the duration; -1 unknown
  std::string codec_name() const;
  int threads() const;  // decoder threads in use

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace roiflow::video
