// Middlebury .flo read/write.
//
//   cv::Mat gt = roiflow::eval::read_flo("flow10.flo");   // CV_32FC2
//   roiflow::eval::write_flo("out.flo", flow);
//
// Format: float32 magic 202021.25, int32 width, int32 height, then height*width (u, v) float32
// pairs, little-endian, rows top to bottom. Unknown pixels have |u| or |v| > 1e9 and are kept
// as they are. read_flo throws roiflow::Error (naming the file and what is wrong) on a missing
// file, bad magic, non-positive or absurd dimensions (checked against the file size before
// any allocation), a truncated or over-long file, or NaN values.
#pragma once

#include <opencv2/core.hpp>
#include <string>
#include <string_view>

namespace roiflow::eval {

inline constexpr float kFloMagic = 202021.25f;

cv::Mat read_flo(const std::string& path);
// The same format decoded from memory (the whole file's bytes); `name` is what error messages
// call it. Same checks and errors as read_flo.
cv::Mat parse_flo(std::string_view bytes, const std::string& name);
// Writes atomically (temporary file + rename), so a failure never leaves a half file.
void write_flo(const std::string& path, const cv::Mat& flow);

}  // namespace roiflow::eval
