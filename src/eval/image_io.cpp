#include "eval/image_io.hpp"

#include <algorithm>
#include <cctype>
#include <fstream>
#include <iterator>
#include <opencv2/imgcodecs.hpp>
#include <string_view>
#include <vector>

#include "core/atomic_write.hpp"
#include "core/error.hpp"

namespace roiflow::eval {
namespace {

std::string quoted(const std::string& text) {
  return "'" + text + "'";
}

std::string size_string(cv::Size size) {
  return std::to_string(size.width) + "x" + std::to_string(size.height);
}

// Why `bytes`, a PNG or JPEG file, is cut short or damaged in its structure, or "" when it
// looks whole (other formats: ""). Decoders print their complaints about such files on stderr
// and, for JPEG, return the picture with its missing part gray: a silently wrong frame.
std::string image_damage(const std::vector<uchar>& bytes) {
  const auto byte_at = [&](std::size_t i) { return static_cast<unsigned>(bytes[i]); };
  static constexpr unsigned char kPng[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
  if (bytes.size() >= 8 && std::equal(kPng, kPng + 8, bytes.begin())) {
    // Chunks: 4-byte big-endian length, 4-letter type, data, 4-byte CRC; the last is IEND.
    std::size_t at = 8;
    while (at + 12 <= bytes.size()) {
      const std::size_t length =
          byte_at(at) << 24 | byte_at(at + 1) << 16 | byte_at(at + 2) << 8 | byte_at(at + 3);
      for (std::size_t k = at + 4; k < at + 8; ++k)
        if (!std::isalpha(static_cast<unsigned char>(bytes[k])))
          return "damaged PNG (no valid chunk at byte " + std::to_string(at) + ")";
      if (std::string_view(reinterpret_cast<const char*>(&bytes[at + 4]), 4) == "IEND") return {};
      if (length > bytes.size() - at - 12) break;
      at += length + 12;
    }
    return "truncated PNG (it ends before its IEND chunk)";
  }
  if (bytes.size() >= 3 && byte_at(0) == 0xFF && byte_at(1) == 0xD8 && byte_at(2) == 0xFF) {
    // Inside entropy-coded data 0xFF is always followed by 0x00 or a restart marker, so an
    // FF D9 after the first start-of-scan (FF DA) is the end-of-image marker.
    bool scan = false;
    for (std::size_t i = 2; i + 1 < bytes.size(); ++i) {
      if (byte_at(i) != 0xFF) continue;
      if (byte_at(i + 1) == 0xDA) scan = true;
      if (scan && byte_at(i + 1) == 0xD9) return {};
    }
    return "truncated JPEG (no end-of-image marker after its image data)";
  }
  return {};
}

}  // namespace

// Why frames of `size` cannot be processed ("10000x10000: larger than ..."), or "" when they can.
std::string frame_size_problem(cv::Size size) {
  const long long pixels = static_cast<long long>(size.width) * size.height;
  if (size.width > kMaxFrameSide || size.height > kMaxFrameSide || pixels > kMaxFramePixels)
    return size_string(size) + ": larger than the limit of " + std::to_string(kMaxFrameSide) +
           " px a side and " + std::to_string(kMaxFramePixels / 1'000'000) + " Mpixel";
  if (size.width < kMinFrameSide || size.height < kMinFrameSide)
    return size_string(size) + ": smaller than the minimum of " + std::to_string(kMinFrameSide) +
           " px a side";
  return {};
}

cv::Mat read_image(const std::string& path, int flags) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error("cannot open image " + quoted(path));
  const std::vector<uchar> bytes((std::istreambuf_iterator<char>(in)),
                                 std::istreambuf_iterator<char>());
  if (in.bad()) throw Error("cannot read image " + quoted(path));
  if (bytes.empty()) throw Error("cannot decode image " + quoted(path) + ": empty file");
  if (const std::string damage = image_damage(bytes); !damage.empty())
    throw Error("cannot decode image " + quoted(path) + ": " + damage);
  cv::Mat image = cv::imdecode(bytes, flags);
  if (image.empty()) throw Error("cannot decode image " + quoted(path));
  return image;
}

void check_frame_size(cv::Size size, const std::string& what) {
  if (const std::string problem = frame_size_problem(size); !problem.empty())
    throw Error(what + " is " + problem);
}

void write_image_atomically(const std::string& path, const cv::Mat& image) {
  write_atomically(path, "image ",
                   [&](const std::string& partial) { return cv::imwrite(partial, image); });
}

void check_image_output(const std::string& path, const std::string& option) {
  check_output_path(path, option);
  if (!cv::haveImageWriter(path)) {
    throw UsageError(option + ": cannot write an image named '" + path +
                     "' (use an extension such as .png)");
  }
}

}  // namespace roiflow::eval
