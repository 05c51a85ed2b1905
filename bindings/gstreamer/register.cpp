#include "gst_roiflow.hpp"

gboolean roiflow_gst_register(GstPlugin* plugin) {
  return gst_element_register(plugin, "roiflowtrack", GST_RANK_NONE, GST_TYPE_ROIFLOW_TRACK) &&
         gst_element_register(plugin, "roiflowflow", GST_RANK_NONE, GST_TYPE_ROIFLOW_FLOW);
}
