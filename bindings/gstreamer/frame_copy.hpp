// The gray frame (and, on demand, its BGR picture) of a mapped GstVideoFrame, for the elements.
//
//   roiflow::gst::OwnedFrame f = roiflow::gst::copy_frame(frame);   // GRAY8, I420 or NV12
//   tracker.update({index, {}, f.gray, nullptr, f.picture});
//
// The planes are copied: the tracker and the flow keep the previous frame after the buffer has
// gone back to its pool. I420 and NV12 frames become gray and BGR exactly as `roiflow track`'s
// decoder makes them (video/yuv_frame.hpp: video-range luma expanded to 0..255, swscale for
// the picture), so the element tracks as the CLI does on the same decoded video; the BGR
// picture (which the tracker asks for to learn appearance and background) is converted only
// when asked. GRAY8 frames are the gray frame and their own picture.
#pragma once

#include <gst/video/video.h>

#include <cstring>
#include <memory>
#include <opencv2/core.hpp>

#include "video/deferred_image.hpp"
#include "video/yuv_frame.hpp"

namespace roiflow::gst {

struct OwnedFrame {
  cv::Mat gray;                                         // CV_8UC1, owned
  std::shared_ptr<const video::DeferredImage> picture;  // BGR on demand; null = the gray frame
};

// Plane `plane` of `frame` (rows x row_bytes), copied.
inline cv::Mat copy_plane(const GstVideoFrame* frame, int plane, int rows, int row_bytes) {
  const cv::Mat view(rows, row_bytes, CV_8UC1, GST_VIDEO_FRAME_PLANE_DATA(frame, plane),
                     static_cast<std::size_t>(GST_VIDEO_FRAME_PLANE_STRIDE(frame, plane)));
  return view.clone();
}

inline OwnedFrame copy_frame(const GstVideoFrame* frame) {
  const int w = GST_VIDEO_FRAME_WIDTH(frame);
  const int h = GST_VIDEO_FRAME_HEIGHT(frame);
  const GstVideoFormat format = GST_VIDEO_FRAME_FORMAT(frame);
  OwnedFrame out;
  if (format != GST_VIDEO_FORMAT_I420 && format != GST_VIDEO_FORMAT_NV12) {
    out.gray = copy_plane(frame, 0, h, w);
    return out;
  }
  video::YuvPlanes planes;
  const int cw = (w + 1) / 2, ch = (h + 1) / 2;
  planes.nv12 = format == GST_VIDEO_FORMAT_NV12;
  planes.full_range = frame->info.colorimetry.range == GST_VIDEO_COLOR_RANGE_0_255;
  planes.y = copy_plane(frame, 0, h, w);
  planes.u = copy_plane(frame, 1, ch, planes.nv12 ? 2 * cw : cw);
  if (!planes.nv12) planes.v = copy_plane(frame, 2, ch, cw);
  out.gray = video::yuv_gray(planes);
  out.picture =
      std::make_shared<video::DeferredImage>([planes] { return video::yuv_to_bgr(planes); });
  return out;
}

}  // namespace roiflow::gst
