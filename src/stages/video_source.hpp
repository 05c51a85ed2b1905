// VideoSource: frames, in order, from a video file, an image-sequence folder or a camera.
//
//   roiflow::stages::VideoSource source("data/Car4");  // or "car.mp4", "img/%04d.jpg", "0",
//                                                      // "synthetic:1000"
//   while (auto frame = source.next()) track(frame->gray, frame->index, frame->timestamp_s);
//   if (source.status().state == SourceStatus::State::kStopped) {
//     std::cerr << source.status().message << '\n';           // "stopped at frame 41: ..."
//     return 1;
//   }
//
// What the input string means, tried in this order:
//   - only digits ("0"): a camera index, opened with OpenCV's default backend. Write "./0" for
//     a file or folder called 0.
//   - an existing directory: an image sequence in DIR/img (the OTB layout) or else in DIR.
//     Numbered files (prefix, digits, extension .jpg .jpeg .png .bmp .pgm .ppm .tif .tiff) are
//     grouped by prefix and extension; the largest group wins. Its frames are the consecutive
//     run of numbers starting at the smallest one (0001.jpg, 0002.jpg, ... or 1.png, 2.png ...).
//   - an existing file: a video, decoded with FFmpeg (VideoDecoder: the gray frame is the
//     decoder's luma plane, the BGR frame one conversion; buffers recycled).
//   - a path holding one printf conversion (%d, %4d or %04d), like "img/%04d.jpg": an image
//     sequence made of the files of that folder that match, run as above.
//   - "synthetic:N" or "synthetic:N:WxH" (when no such file exists): N frames (1..10^9) of
//     eval::TrackingScene's fixed-camera scene, WxH (default 640x480, each side 64..8192; the
//     vehicle and its jump scaled with the width), rendered on the fly. The scene is 300
//     frames long and plays forwards, then backwards, then forwards again (frame i shows scene
//     frame i mod 598, mirrored past 299), so a stream of any length holds one scene and one
//     frame at a time: the input of soak runs.
//   - "synthetic:N[:WxH]:OBJECTS": N frames of eval::TrafficScene, OBJECTS (1..256) vehicles
//     crossing, entering and leaving, whose exact boxes eval::TrafficScene::ground_truth()
//     gives (eval/synthetic_input.hpp parses the spec).
//
// Frame size limits: every frame must be at most kMaxFrameSide pixels a side and kMaxFramePixels
// pixels in all (8K UHD, 7680x4320, fits), and at least kMinFrameSide a side (the smallest
// pyramid level LK can work on). A video whose container announces a size out of range is
// refused before any frame is decoded; an image is refused once decoded, before any buffer
// of the pipeline is allocated for it.
//
// Errors at construction: every one of these throws roiflow::Error naming the input: a path
// that does not exist, a directory without an image sequence, a pattern nothing matches, a
// file FFmpeg cannot open (or whose video it cannot decode), a camera that does not open, bad
// params, a frame size out of the limits above, a malformed "synthetic:" input, and an input that
// opens but yields no first frame (empty or corrupt file, `start` past the end). The first frame is
// decoded in the constructor so that size() is known and a bad input fails before any work starts.
//
// Frames are decoded on demand in next() (only the first ahead of time, so a camera's frames
// are never a frame late), each into its own buffers: a frame may travel to other threads
// while the next one is read. The class itself is not thread-safe: one caller at a time.
//
// Mid-stream policy: STOP, never skip. When a frame after the first cannot be delivered,
// next() returns std::nullopt, from then on, and status() says kStopped with the message
// "stopped at frame N: <reason>", N being the index the frame would have had. Reasons: a
// missing file in a sequence (a gap in the numbering: the files after it are not read; the
// message names the missing file), an image that cannot be decoded or is a truncated or damaged
// PNG or JPEG (see read_image), a frame whose size differs
// from the first one's (the pipeline needs one size), a video that ends more than ~1% short of
// the frame count its container announces (truncated or corrupt; OpenCV does not tell a
// decode error from the end, and counts estimated from the duration can be off by a frame or
// two), and a camera that stops delivering. Every frame delivered before is intact, so a
// caller keeps what it has written and decides whether to exit non-zero. A normal end, or
// `max_frames` reached, is kEnded with the message "end of stream". Until next() has returned
// std::nullopt the state is kStreaming.
#pragma once

#include <memory>
#include <opencv2/core.hpp>
#include <optional>
#include <string>

#include "eval/image_io.hpp"
#include "stages/deferred_image.hpp"

namespace roiflow::stages {

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

}  // namespace roiflow::stages
