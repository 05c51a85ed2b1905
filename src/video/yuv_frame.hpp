// YUV 4:2:0 frames from elsewhere (a GStreamer buffer, a camera API) turned into the gray frame
// and the BGR picture exactly as VideoDecoder turns FFmpeg's frames into them, so that a
// tracker fed from there sees what `roiflow track` sees on the same decoded video.
//
//   using namespace roiflow;
//   const cv::Mat luma(240, 320, CV_8UC1, cv::Scalar(90)), cb(120, 160, CV_8UC1, 128), cr = cb;
//   video::YuvPlanes p;                       // the planes, copied or borrowed
//   p.y = luma; p.u = cb; p.v = cr;            // I420; NV12: p.u = interleaved CbCr, p.nv12 = true
//   p.full_range = false;                      // video range 16..235 (most video)
//   cv::Mat gray = video::yuv_gray(p);        // 8-bit, full range (the BT.601 gray)
//   cv::Mat colour = video::yuv_to_bgr(p);       // 8-bit BGR, swscale (bicubic chroma)
//
// yuv_gray expands video-range luma to 0..255 (full range copies it); yuv_to_bgr converts with
// the same swscale settings as VideoDecoder. Both throw roiflow::Error on planes whose sizes do
// not fit a 4:2:0 frame.
#pragma once

#include <opencv2/core.hpp>

namespace roiflow::video {

struct YuvPlanes {
  cv::Mat y;  // CV_8UC1, w x h
  cv::Mat
      u;  // CV_8UC1: I420 Cb, (w+1)/2 x (h+1)/2; NV12: interleaved CbCr, 2 * ((w+1)/2) bytes a row
  cv::Mat v;  // CV_8UC1: I420 Cr, as u; NV12: unused
  bool nv12 = false;
  bool full_range = false;  // 0..255 (JPEG) rather than 16..235
};

cv::Mat yuv_gray(const YuvPlanes& planes);
cv::Mat yuv_to_bgr(const YuvPlanes& planes);

}  // namespace roiflow::video
