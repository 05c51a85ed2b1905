// Middlebury .flo files: float32 magic 202021.25, int32 width and height, then the (u, v) float32
// pairs, little-endian, rows top to bottom; unknown pixels (|u| or |v| > 1e9) are kept as they
// are. read_flo throws roiflow::Error naming the file and the fault for a missing file, a bad
// magic, absurd dimensions (checked against the file size before allocating), a truncated or
// over-long file, or NaN values; write_flo writes atomically.
//
//   const cv::Mat flow(frame_t.size(), CV_32FC2, cv::Scalar(0.5f, -1.f));
//   roiflow::eval::write_flo("out.flo", flow);
//   const cv::Mat back = roiflow::eval::read_flo("out.flo");  // CV_32FC2, bit for bit
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
