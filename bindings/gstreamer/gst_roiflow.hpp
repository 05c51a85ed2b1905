// The GStreamer elements of libgstroiflow.so (docs/DROPIN.md):
//
//   roiflowtrack  a GstVideoFilter (GRAY8, I420, NV12; the luma plane is the gray frame) that
//                 tracks objects with tracking::ObjectTracker and attaches one
//                 GstVideoRegionOfInterestMeta per object (roi_type "roiflow", id = the object's
//                 id, a "roiflow/track" param: id, x, y, w, h, vx, vy, mode, lost, frame);
//                 optional track log (the CSV/JSON `roiflow track --log` writes) and drawing.
//   roiflowflow   dense flow between consecutive frames, output as colour-coded BGR video.
//
//   gst-launch-1.0 filesrc location=vtest.avi ! decodebin ! videoconvert !
//       roiflowtrack log=track.csv ! fakesink
//
// The plugin registers both with roiflow_gst_register(); a program (the tests) that links the
// elements statically registers them with gst_plugin_register_static(..., roiflow_gst_register,
// ...).
#pragma once

#include <gst/gst.h>

G_BEGIN_DECLS

#define GST_TYPE_ROIFLOW_TRACK (gst_roiflow_track_get_type())
GType gst_roiflow_track_get_type(void);
#define GST_TYPE_ROIFLOW_FLOW (gst_roiflow_flow_get_type())
GType gst_roiflow_flow_get_type(void);

// Registers roiflowtrack and roiflowflow with `plugin`.
gboolean roiflow_gst_register(GstPlugin* plugin);

G_END_DECLS
