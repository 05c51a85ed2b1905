// Frames, in order, from a video file (FFmpeg), an image-sequence folder (OTB's img/ layout or
// numbered files), a printf pattern ("img/%04d.jpg"), a camera index ("0") or a generated stream
// ("synthetic:N[:WxH][:OBJECTS]"). Bad inputs and frame sizes out of the limits throw
// roiflow::Error at construction (the first frame is decoded there); mid-stream the policy is
// STOP, never skip: next() ends and status() says where and why. docs/STAGES.md has details.
//
//   roiflow::video::VideoSource source("synthetic:10");  // or "car.mp4", "data/Car4", "0"
//   while (auto frame = source.next()) std::cout << frame->index << " " << frame->timestamp_s;
//   if (source.status().state == roiflow::video::SourceStatus::State::kStopped) {
//     std::cerr << source.status().message << '\n';  // "stopped at frame 41: ..."
//   }
#pragma once

#include <memory>
#include <opencv2/core.hpp>
#include <optional>
#include <string>

#include "eval/image_io.hpp"
#include "video/deferred_image.hpp"

namespace roiflow::video {

struct VideoSourceParams {
  double fps = 25;           // frame rate of image sequences, and of videos or cameras that
                             // report none; > 0
  long long start = 0;       // index of the first frame delivered; a video decodes and drops
                             // the earlier ones (exact whatever the key frames, not instant)
  long long max_frames = 0;  // at most this many frames are delivered; 0 = all
  int decode_threads = 0;    // a video's FFmpeg decoder threads; 0 = automatic (see
                             // VideoDecoder); >= 0
  // A video's frames come with `image` empty and their BGR picture in `deferred_image`,
  // converted from the decoder's planes only when Frame::picture() first asks for it (on the
  // asking thread): for pipelines that need the gray frame only, or colour for a few frames
  // (tracking without a video sink: 40 % of decoding saved). Other inputs ignore it.
  bool defer_colour = false;
};

struct Frame {
  long long index = 0;  // 0-based position in the input (so the first frame has index `start`)
  // Seconds since the input's frame 0: the container's presentation time for videos (when it
  // increases, else the previous one + 1/fps), index / fps for image sequences, and the
  // wall-clock time since opening for cameras.
  double timestamp_s = 0;
  cv::Mat image;  // as decoded: 8-bit BGR or 8-bit gray; empty when `deferred_image` holds it
  cv::Mat gray;   // 8-bit gray, the same size; shares `image`'s data when that is gray
  std::shared_ptr<const DeferredImage> deferred_image;  // see VideoSourceParams::defer_colour

  // The picture as decoded (BGR or gray): `image`, else the deferred one (converted now, once;
  // thread-safe), else `gray`.
  cv::Mat picture() const { return picture_of(image, deferred_image, gray); }
};

struct SourceStatus {
  enum class State { kStreaming, kEnded, kStopped };
  State state = State::kStreaming;
  std::string message = "streaming";  // "streaming", "end of stream", "stopped at frame N: ..."
};

class VideoSource {
 public:
  explicit VideoSource(const std::string& input, const VideoSourceParams& params = {});
  ~VideoSource();
  VideoSource(VideoSource&&) noexcept;
  VideoSource& operator=(VideoSource&&) noexcept;

  // The next frame in order, or std::nullopt at the end or after a stop (see status()).
  std::optional<Frame> next();

  cv::Size size() const;  // every frame's size: the first frame's
  double fps() const;
  long long frame_count_hint() const;  // frames next() will deliver if all goes well; -1 unknown
  // e.g. "video 'car.avi' (25 fps, 300 frames, FFmpeg mpeg4), 640x480"
  std::string description() const;
  const SourceStatus& status() const;

  class Reader;  // one per kind of input, defined in the .cpp (public so that they can derive)

 private:
  std::unique_ptr<Reader> reader_;
  VideoSourceParams params_;
  cv::Size size_;
  std::optional<Frame> pending_;  // the first frame, decoded by the constructor
  long long delivered_ = 0;
  SourceStatus status_;

  // Frame `index`, or std::nullopt with `failure` empty at a normal end, else saying why.
  std::optional<Frame> read_frame(long long index, std::string& failure);
};

}  // namespace roiflow::video
