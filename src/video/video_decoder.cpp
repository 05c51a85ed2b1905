#include "video/video_decoder.hpp"

extern "C" {
#include <libavcodec/avcodec.h>
#include <libavformat/avformat.h>
#include <libavutil/pixdesc.h>
#include <libswscale/swscale.h>
}

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <mutex>
#include <opencv2/imgproc.hpp>
#include <vector>

#include "core/error.hpp"

namespace roiflow::video {
namespace {

std::string av_error_text(int code) {
  char buffer[AV_ERROR_MAX_STRING_SIZE] = {};
  av_strerror(code, buffer, sizeof buffer);
  return buffer;
}

double seconds(AVRational r) {
  return r.den != 0 ? static_cast<double>(r.num) / r.den : 0.0;
}

// OpenCV's FFmpeg backend sets the log level from OPENCV_FFMPEG_LOGLEVEL; so do we, once.
void apply_log_level() {
  static std::once_flag once;
  std::call_once(once, [] {
    if (const char* level = std::getenv("OPENCV_FFMPEG_LOGLEVEL"))
      av_log_set_level(std::atoi(level));
  });
}

// Whether plane 0 of `format` is its 8-bit luma (planar or semi-planar YUV, gray), the gray
// image as it is.
bool luma_is_plane0(AVPixelFormat format) {
  const AVPixFmtDescriptor* d = av_pix_fmt_desc_get(format);
  if (d == nullptr || d->nb_components < 1) return false;
  if ((d->flags & (AV_PIX_FMT_FLAG_RGB | AV_PIX_FMT_FLAG_PAL | AV_PIX_FMT_FLAG_HWACCEL |
                   AV_PIX_FMT_FLAG_BAYER | AV_PIX_FMT_FLAG_FLOAT)) != 0)
    return false;
  const AVComponentDescriptor& y = d->comp[0];
  return y.plane == 0 && y.depth == 8 && y.step == 1 && y.shift == 0 && y.offset == 0;
}

bool full_range(const AVFrame& frame) {
  const auto format = static_cast<AVPixelFormat>(frame.format);
  const AVPixFmtDescriptor* d = av_pix_fmt_desc_get(format);
  if (d != nullptr && d->nb_components <= 2) return true;  // gray (+ alpha): no video range
  return frame.color_range == AVCOL_RANGE_JPEG || format == AV_PIX_FMT_YUVJ420P ||
         format == AV_PIX_FMT_YUVJ422P || format == AV_PIX_FMT_YUVJ444P ||
         format == AV_PIX_FMT_YUVJ440P || format == AV_PIX_FMT_YUVJ411P;
}

// A buffer of `pool` that nobody else holds (refcount 1: the pool's own reference, read
// atomically, so no other thread can be using it), or a new one, kept in the pool while it holds
// fewer than `limit`. The caller owns the pool (one thread at a time).
cv::Mat take(std::vector<cv::Mat>& pool, cv::Size size, int type, std::size_t limit) {
  for (const cv::Mat& m : pool) {
    if (m.size() == size && m.type() == type && m.u != nullptr && CV_XADD(&m.u->refcount, 0) == 1)
      return m;
  }
  cv::Mat m(size, type);
  if (pool.size() < limit) pool.push_back(m);
  return m;
}

// Converts frames of one pixel format, size and range to BGR, from any thread: each conversion
// takes a swscale context nobody is using (a new one when all are busy) and a buffer of the pool
// that nobody else holds. Shared by the decoder and the deferred pictures of its frames, so it
// outlives whichever goes first.
class BgrConverter {
 public:
  // Throws roiflow::Error when swscale has no conversion from `format` (checked here, at decode
  // time, so that a deferred conversion cannot fail for that reason later).
  BgrConverter(const std::string& path, AVPixelFormat format, cv::Size size, bool full,
               std::size_t pool_limit)
      : path_(path), format_(format), size_(size), full_(full), pool_limit_(pool_limit) {
    idle_.push_back(make_context());
  }
  ~BgrConverter() {
    for (SwsContext* c : idle_)
      sws_freeContext(c);
  }
  BgrConverter(const BgrConverter&) = delete;
  BgrConverter& operator=(const BgrConverter&) = delete;

  bool fits(const AVFrame& frame) const {
    return frame.format == format_ && frame.width == size_.width && frame.height == size_.height &&
           full_range(frame) == full_;
  }

  cv::Mat convert(const AVFrame& frame) {
    SwsContext* context = nullptr;
    cv::Mat bgr;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      if (!idle_.empty()) {
        context = idle_.back();
        idle_.pop_back();
      }
      bgr = take(pool_, size_, CV_8UC3, pool_limit_);
    }
    if (context == nullptr) context = make_context();
    uint8_t* dst[4] = {bgr.data, nullptr, nullptr, nullptr};
    const int dst_stride[4] = {static_cast<int>(bgr.step), 0, 0, 0};
    sws_scale(context, frame.data, frame.linesize, 0, size_.height, dst, dst_stride);
    std::lock_guard<std::mutex> lock(mutex_);
    idle_.push_back(context);
    return bgr;
  }

 private:
  SwsContext* make_context() const {
    const int w = size_.width, h = size_.height;
    // SWS_BICUBIC as OpenCV's backend asks (same size: it only picks the chroma filter).
    SwsContext* context = sws_getContext(w, h, format_, w, h, AV_PIX_FMT_BGR24, SWS_BICUBIC,
                                         nullptr, nullptr, nullptr);
    if (context == nullptr)
      throw Error("video '" + path_ + "': no conversion from pixel format " +
                  (av_get_pix_fmt_name(format_) ? av_get_pix_fmt_name(format_) : "?") + " to BGR");
    int* inv = nullptr;
    int* table = nullptr;
    int src_range = 0, dst_range = 0, brightness = 0, contrast = 0, saturation = 0;
    if (sws_getColorspaceDetails(context, &inv, &src_range, &table, &dst_range, &brightness,
                                 &contrast, &saturation) >= 0 &&
        src_range != static_cast<int>(full_)) {
      sws_setColorspaceDetails(context, inv, full_ ? 1 : 0, table, dst_range, brightness, contrast,
                               saturation);
    }
    return context;
  }

  std::string path_;
  AVPixelFormat format_;
  cv::Size size_;
  bool full_;
  std::size_t pool_limit_;
  std::mutex mutex_;
  std::vector<SwsContext*> idle_;  // guarded by mutex_
  std::vector<cv::Mat> pool_;      // guarded by mutex_
};

}  // namespace

struct VideoDecoder::Impl {
  std::string path;
  AVFormatContext* format = nullptr;
  AVCodecContext* codec = nullptr;
  AVPacket* packet = nullptr;
  AVFrame* frame = nullptr;
  bool defer_bgr = false;
  std::shared_ptr<BgrConverter> converter;  // for the current format; null before the first frame
  cv::Size frame_size;                      // the first frame's
  int stream = -1;
  double fps = 0;
  long long frame_count = -1;
  double time_base = 0;
  int64_t start_pts = 0;
  bool draining = false;  // the demuxer is done; the decoder gives what it still holds
  bool ended = false;
  std::vector<cv::Mat> gray_pool;
  std::size_t pool_limit = 4;

  ~Impl() {
    av_frame_free(&frame);
    av_packet_free(&packet);
    avcodec_free_context(&codec);
    avformat_close_input(&format);
  }

  // Fills `frame` with the next decoded picture: 0, AVERROR_EOF at the end, or an error.
  int decode_next(std::string& failure) {
    for (;;) {
      const int received = avcodec_receive_frame(codec, frame);
      if (received == 0) return 0;
      if (received == AVERROR_EOF) return received;
      if (received != AVERROR(EAGAIN)) {
        failure = "cannot decode frame: " + av_error_text(received);
        return received;
      }
      // A drained decoder only ever answers EOF; should one ask for more, nothing is left.
      if (draining) return AVERROR_EOF;
      // The decoder wants more input.
      const int read = av_read_frame(format, packet);
      if (read < 0) {
        // The end, or a read error in a cut or damaged file: the decoder gives what it holds,
        // and VideoSource tells a short file from the frame count it announced.
        avcodec_send_packet(codec, nullptr);
        draining = true;
        continue;
      }
      if (packet->stream_index != stream) {
        av_packet_unref(packet);
        continue;
      }
      const int sent = avcodec_send_packet(codec, packet);
      av_packet_unref(packet);
      if (sent < 0 && sent != AVERROR(EAGAIN)) {
        failure = "cannot decode packet: " + av_error_text(sent);
        return sent;
      }
    }
  }

  void convert(DecodedFrame& out) {
    const int w = frame->width, h = frame->height;
    // Checked before any buffer of the new size is allocated (a damaged stream may claim any).
    if (frame_size.empty()) frame_size = cv::Size(w, h);
    if (frame_size != cv::Size(w, h)) {
      throw Error("video '" + path + "': the frame size changed from " +
                  std::to_string(frame_size.width) + "x" + std::to_string(frame_size.height) +
                  " to " + std::to_string(w) + "x" + std::to_string(h) + " mid-stream");
    }
    const auto source_format = static_cast<AVPixelFormat>(frame->format);
    const bool full = full_range(*frame);
    if (!converter || !converter->fits(*frame))
      converter = std::make_shared<BgrConverter>(path, source_format, frame_size, full, pool_limit);
    out.deferred_bgr.reset();
    if (defer_bgr && luma_is_plane0(source_format)) {
      // The planes are kept (a reference, no copy) until somebody asks for the picture.
      std::shared_ptr<AVFrame> planes(av_frame_clone(frame), [](AVFrame* f) { av_frame_free(&f); });
      if (!planes) throw Error("video '" + path + "': out of memory");
      out.bgr.release();
      out.deferred_bgr = std::make_shared<const DeferredImage>(
          [c = converter, planes] { return c->convert(*planes); });
    } else {
      out.bgr = converter->convert(*frame);
    }

    out.gray = take(gray_pool, frame_size, CV_8UC1, pool_limit);
    if (luma_is_plane0(source_format)) {
      const cv::Mat luma(h, w, CV_8UC1, frame->data[0],
                         static_cast<std::size_t>(frame->linesize[0]));
      if (full)
        luma.copyTo(out.gray);
      else
        // Video range (16..235) to full range: the BT.601 gray of the BGR conversion.
        // convertTo's SIMD path (0.04 ms at 640x480; cv::LUT took 0.6 ms, a scalar loop 0.3).
        luma.convertTo(out.gray, CV_8U, 255.0 / 219.0, -16.0 * 255.0 / 219.0);
    } else {
      cv::cvtColor(out.bgr, out.gray, cv::COLOR_BGR2GRAY);
    }

    const int64_t pts = frame->best_effort_timestamp;
    out.timestamp_s =
        pts == AV_NOPTS_VALUE ? -1.0 : static_cast<double>(pts - start_pts) * time_base;
  }
};

VideoDecoder::VideoDecoder(const std::string& path, int threads, bool defer_bgr)
    : impl_(std::make_unique<Impl>()) {
  apply_log_level();
  Impl& d = *impl_;
  d.path = path;
  d.defer_bgr = defer_bgr;
  const std::string label = "video '" + path + "'";
  if (threads < 0)
    throw Error(label + ": decoder threads must be >= 0, got " + std::to_string(threads));
  int code = avformat_open_input(&d.format, path.c_str(), nullptr, nullptr);
  if (code < 0)
    throw Error("cannot open " + label + ": not a video FFmpeg can read (" + av_error_text(code) +
                ")");
  code = avformat_find_stream_info(d.format, nullptr);
  if (code < 0) throw Error("cannot open " + label + ": " + av_error_text(code));
  const AVCodec* decoder = nullptr;
  d.stream = av_find_best_stream(d.format, AVMEDIA_TYPE_VIDEO, -1, -1, &decoder, 0);
  if (d.stream == AVERROR_STREAM_NOT_FOUND)
    throw Error("cannot open " + label + ": no video stream");
  if (d.stream < 0 || decoder == nullptr)
    throw Error("cannot open " + label + ": no decoder for its video stream");
  AVStream* stream = d.format->streams[d.stream];
  d.codec = avcodec_alloc_context3(decoder);
  d.packet = av_packet_alloc();
  d.frame = av_frame_alloc();
  if (d.codec == nullptr || d.packet == nullptr || d.frame == nullptr)
    throw Error("cannot open " + label + ": out of memory");
  code = avcodec_parameters_to_context(d.codec, stream->codecpar);
  if (code < 0) throw Error("cannot open " + label + ": " + av_error_text(code));
  const long long pixels =
      static_cast<long long>(stream->codecpar->width) * stream->codecpar->height;
  d.codec->thread_count = threads > 0 ? threads : pixels <= kSingleThreadPixels ? 1 : 0;
  d.codec->thread_type = FF_THREAD_FRAME | FF_THREAD_SLICE;
  code = avcodec_open2(d.codec, decoder, nullptr);
  if (code < 0)
    throw Error("cannot open " + label + ": its " + decoder->name +
                " decoder fails to start: " + av_error_text(code));

  d.fps = seconds(av_guess_frame_rate(d.format, stream, nullptr));
  if (!std::isfinite(d.fps) || d.fps <= 0) d.fps = 0;
  d.time_base = seconds(stream->time_base);
  d.start_pts = stream->start_time != AV_NOPTS_VALUE ? stream->start_time : 0;
  if (stream->nb_frames > 0) {
    d.frame_count = stream->nb_frames;
  } else {
    // As OpenCV estimates it: the duration (container's, else the stream's) times the rate.
    double duration = d.format->duration != AV_NOPTS_VALUE
                          ? static_cast<double>(d.format->duration) / AV_TIME_BASE
                          : 0.0;
    if (duration <= 0 && stream->duration != AV_NOPTS_VALUE)
      duration = static_cast<double>(stream->duration) * d.time_base;
    if (duration > 0 && d.fps > 0) d.frame_count = std::llround(duration * d.fps);
  }
  // Enough buffers for the frames a pipeline keeps alive at once, at most ~256 MB of them.
  const double frame_bytes = std::max(1.0, static_cast<double>(pixels) * 4.0);
  d.pool_limit = static_cast<std::size_t>(std::clamp(256e6 / frame_bytes, 4.0, 64.0));
}

VideoDecoder::~VideoDecoder() = default;

bool VideoDecoder::read(DecodedFrame& out, std::string& failure) {
  Impl& d = *impl_;
  if (d.ended) return false;
  const int code = d.decode_next(failure);
  if (code != 0) {
    d.ended = true;
    return false;
  }
  try {
    d.convert(out);
  } catch (const Error& e) {
    failure = e.what();
    d.ended = true;
  }
  av_frame_unref(d.frame);
  return !d.ended;
}

cv::Size VideoDecoder::size() const {
  const AVCodecParameters* p = impl_->format->streams[impl_->stream]->codecpar;
  return {p->width, p->height};
}
double VideoDecoder::fps() const {
  return impl_->fps;
}
long long VideoDecoder::frame_count() const {
  return impl_->frame_count;
}
std::string VideoDecoder::codec_name() const {
  return impl_->codec->codec != nullptr ? impl_->codec->codec->name : "?";
}
int VideoDecoder::threads() const {
  return impl_->codec->thread_count;
}

}  // namespace roiflow::video
