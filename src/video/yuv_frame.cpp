#include "video/yuv_frame.hpp"

extern "C" {
#include <libswscale/swscale.h>
}

#include <memory>
#include <string>

#include "core/error.hpp"

namespace roiflow::video {
namespace {

void check(const YuvPlanes& p) {
  const int cw = (p.y.cols + 1) / 2, ch = (p.y.rows + 1) / 2;
  const bool ok =
      p.y.type() == CV_8UC1 && !p.y.empty() && p.u.type() == CV_8UC1 && p.u.rows >= ch &&
      (p.nv12 ? p.u.cols >= 2 * cw
              : (p.u.cols >= cw && p.v.type() == CV_8UC1 && p.v.rows >= ch && p.v.cols >= cw));
  if (!ok) {
    throw Error("yuv frame: planes of " + std::to_string(p.y.cols) + "x" +
                std::to_string(p.y.rows) + " do not form a 4:2:0 frame");
  }
}

}  // namespace

cv::Mat yuv_gray(const YuvPlanes& p) {
  check(p);
  cv::Mat gray;
  if (p.full_range) {
    p.y.copyTo(gray);
  } else {
    // As VideoDecoder: video range (16..235) to full range, the BT.601 gray of the BGR picture.
    p.y.convertTo(gray, CV_8U, 255.0 / 219.0, -16.0 * 255.0 / 219.0);
  }
  return gray;
}

cv::Mat yuv_to_bgr(const YuvPlanes& p) {
  check(p);
  const int w = p.y.cols, h = p.y.rows;
  const AVPixelFormat format = p.nv12 ? AV_PIX_FMT_NV12 : AV_PIX_FMT_YUV420P;
  // SWS_BICUBIC and the source range as VideoDecoder sets them.
  std::unique_ptr<SwsContext, void (*)(SwsContext*)> context(
      sws_getContext(w, h, format, w, h, AV_PIX_FMT_BGR24, SWS_BICUBIC, nullptr, nullptr, nullptr),
      sws_freeContext);
  if (!context) throw Error("yuv frame: swscale has no conversion to BGR");
  int* inv = nullptr;
  int* table = nullptr;
  int src_range = 0, dst_range = 0, brightness = 0, contrast = 0, saturation = 0;
  if (sws_getColorspaceDetails(context.get(), &inv, &src_range, &table, &dst_range, &brightness,
                               &contrast, &saturation) >= 0 &&
      src_range != static_cast<int>(p.full_range)) {
    sws_setColorspaceDetails(context.get(), inv, p.full_range ? 1 : 0, table, dst_range, brightness,
                             contrast, saturation);
  }
  cv::Mat bgr(h, w, CV_8UC3);
  const uint8_t* src[4] = {p.y.data, p.u.data, p.nv12 ? nullptr : p.v.data, nullptr};
  const int src_stride[4] = {static_cast<int>(p.y.step), static_cast<int>(p.u.step),
                             p.nv12 ? 0 : static_cast<int>(p.v.step), 0};
  uint8_t* dst[4] = {bgr.data, nullptr, nullptr, nullptr};
  const int dst_stride[4] = {static_cast<int>(bgr.step), 0, 0, 0};
  sws_scale(context.get(), src, src_stride, 0, h, dst, dst_stride);
  return bgr;
}

}  // namespace roiflow::video
