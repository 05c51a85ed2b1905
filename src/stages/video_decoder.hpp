// VideoDecoder: the frames of a video file, decoded with FFmpeg's libavformat/libavcodec, as
// 8-bit BGR and 8-bit gray, in order. VideoSource reads video files through it.
//
//   roiflow::stages::VideoDecoder video("car.mp4");
//   roiflow::stages::DecodedFrame f;
//   std::string failure;
//   while (video.read(f, failure)) use(f.bgr, f.gray, f.timestamp_s);
//   if (!failure.empty()) std::cerr << failure << '\n';   // a decode error, not the end
//
// Why not cv::VideoCapture: it converts every frame to BGR, then copies it into the caller's
// Mat, and the caller converts that to gray again; with frame threads on (it always asks
// FFmpeg for them) a 640x480 MPEG-4 stream decodes slower than on one thread and keeps both
// cores of a two-core machine busy doing it (pipeline_bench BM_DecodeOpenCV: 1.6 cores, ~0.9 ms
// of CPU a frame, against ~0.45 ms here on one core). Here the gray frame is the decoder's own luma
// plane (expanded from video range 16..235 to 0..255, so it equals the BT.601 gray of the BGR frame
// within rounding), the BGR frame is converted once into its final buffer, and both come from
// a small pool of buffers that are reused once nobody else holds them (no page faults per
// frame).
//
// Deferred colour: with `defer_bgr`, frames of formats whose plane 0 is the luma (all YUV ones)
// come with an empty `bgr` and a DeferredImage that converts them on the thread that first asks
// (a swscale context and buffer pool shared with the decoder, thread-safe); the gray frame is
// always made at once. Other formats (RGB, palette) are converted at once as before.
//
// Decoder threads: `threads` > 0 asks FFmpeg for that many; 0 picks one thread for frames of
// up to kSingleThreadPixels (where FFmpeg's frame threads cost more than they give: synthetic
// 640x480 MPEG-4, 3850 frames/s on one thread vs 2370-2940 on two or three) and FFmpeg's own
// choice (one per core) for larger ones. A tracking pipeline wants its other cores for itself.
//
// Errors: the constructor throws roiflow::Error naming the file when it cannot be opened, has
// no video stream or no decoder for it, or `threads` < 0 (the frame-size limits are
// VideoSource's, checked on size() before any frame is decoded). read() returns false at the
// end of the stream (failure empty) or when a packet cannot be decoded, a frame cannot be
// converted, or the frame size changes mid-stream (failure says which): the caller stops
// there. The FFmpeg log level follows OPENCV_FFMPEG_LOGLEVEL when it is set, as with OpenCV's
// own FFmpeg backend.
#pragma once

#include <memory>
#include <opencv2/core.hpp>
#include <string>

#include "stages/deferred_image.hpp"

namespace roiflow::stages {

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

}  // namespace roiflow::stages
