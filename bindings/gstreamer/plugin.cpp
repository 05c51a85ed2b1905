// libgstroiflow.so: the plugin entry point (the elements: gst_roiflow.hpp).
#include "gst_roiflow.hpp"

#ifndef ROIFLOW_VERSION
#define ROIFLOW_VERSION "0.0.0"
#endif
#define PACKAGE "roiflow"

GST_PLUGIN_DEFINE(GST_VERSION_MAJOR, GST_VERSION_MINOR, roiflow,
                  "roiflow: dense Lucas-Kanade flow and ROI tracking", roiflow_gst_register,
                  ROIFLOW_VERSION, GST_LICENSE_UNKNOWN, "roiflow", "unknown")
