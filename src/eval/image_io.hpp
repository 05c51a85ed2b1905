// Image files in and out, with the frame-size limits every input obeys: a reader that refuses
// truncated or damaged PNG and JPEG files (decoders would report them only on stderr, or answer
// with a half-gray picture), and an atomic writer.
//
//   roiflow::eval::check_image_output("out/frame.png", "--color");  // before the long work
//   roiflow::eval::write_image_atomically("out/frame.png", bgr);
//   const cv::Mat gray = roiflow::eval::read_image("out/frame.png", cv::IMREAD_GRAYSCALE);
//   roiflow::eval::check_frame_size(gray.size(), "image 'out/frame.png'");
//   #include <opencv2/imgcodecs.hpp>
#pragma once

#include <opencv2/core.hpp>
#include <string>

#include "flow/pyramid.hpp"

namespace roiflow::eval {

inline constexpr int kMinFrameSide = flow::kMinLevelSide;  // one pyramid level
inline constexpr int kMaxFrameSide = 8192;
inline constexpr long long kMaxFramePixels = 40'000'000;

// Throws roiflow::Error when `size` is out of the limits above, naming `what` (e.g. "image
// 'a.png'") and the size. Video sources and the flow commands apply it to every image.
void check_frame_size(cv::Size size, const std::string& what);
// Why frames of `size` cannot be processed ("10000x10000: larger than ..."), or "" when they can.
std::string frame_size_problem(cv::Size size);

// The image file at `path`, decoded with cv::imdecode(`flags`). Throws roiflow::Error naming
// the file when it cannot be read or decoded, and also when a PNG or JPEG file is cut short or
// its chunk structure is damaged, which decoders would otherwise report only on stderr (and,
// for JPEG, answer with a picture whose missing part is gray). Image sequences read their
// frames with it.
cv::Mat read_image(const std::string& path, int flags);

// cv::imwrite to a partial file, then renamed over `path` (core/atomic_write.hpp); the format
// follows the extension. Throws roiflow::Error "cannot write image '<path>'" on failure.
void write_image_atomically(const std::string& path, const cv::Mat& image);
// check_output_path, and UsageError when OpenCV cannot write an image named `path`.
void check_image_output(const std::string& path, const std::string& option);

}  // namespace roiflow::eval
