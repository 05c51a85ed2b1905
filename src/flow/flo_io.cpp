#include "flow/flo_io.hpp"

#include <bit>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <system_error>

#include "flow/error.hpp"

namespace roiflow::flow {
namespace {

// The format is little-endian and we read/write raw memory; a big-endian port would need
// byte swapping here and nowhere else.
static_assert(std::endian::native == std::endian::little, ".flo I/O assumes a little-endian host");

constexpr std::int64_t kHeaderBytes = 12;
// Larger than any real flow field, small enough that 8 * W * H cannot overflow int64.
constexpr std::int32_t kMaxSide = 100000;

[[noreturn]] void fail(const std::string& path, const std::string& what) {
  throw Error("flow file '" + path + "': " + what);
}

std::string to_text(double value) {
  std::ostringstream s;
  s.precision(9);
  s << value;
  return s.str();
}

}  // namespace

cv::Mat read_flo(const std::string& path) {
  namespace fs = std::filesystem;
  std::error_code ec;
  const fs::file_status status = fs::status(path, ec);
  if (!fs::exists(status)) fail(path, "no such file");
  // An ifstream happily "opens" a directory on Linux and then reads nothing.
  if (!fs::is_regular_file(status)) fail(path, "not a regular file");
  const std::uintmax_t file_bytes = fs::file_size(path, ec);
  if (ec) fail(path, "cannot get size: " + ec.message());

  if (file_bytes < static_cast<std::uintmax_t>(kHeaderBytes)) {
    fail(path, std::to_string(file_bytes) + " bytes, shorter than the 12-byte header");
  }
  std::ifstream in(path, std::ios::binary);
  if (!in) fail(path, "cannot open for reading");

  float magic = 0;
  std::int32_t width = 0;
  std::int32_t height = 0;
  in.read(reinterpret_cast<char*>(&magic), sizeof magic);
  in.read(reinterpret_cast<char*>(&width), sizeof width);
  in.read(reinterpret_cast<char*>(&height), sizeof height);
  if (!in) fail(path, "cannot read the header");
  if (magic != kFloMagic) fail(path, "bad magic " + to_text(magic) + " (expected 202021.25)");
  if (width <= 0 || height <= 0 || width > kMaxSide || height > kMaxSide) {
    fail(path, "bad size " + std::to_string(width) + "x" + std::to_string(height));
  }
  // Checked before allocating, so a corrupt header cannot ask for gigabytes.
  const std::int64_t expected = kHeaderBytes + std::int64_t{8} * width * height;
  if (static_cast<std::int64_t>(file_bytes) != expected) {
    fail(path, std::to_string(width) + "x" + std::to_string(height) + " flow needs " +
                   std::to_string(expected) + " bytes, file has " + std::to_string(file_bytes) +
                   (static_cast<std::int64_t>(file_bytes) < expected ? " (truncated)"
                                                                     : " (trailing bytes)"));
  }

  cv::Mat flow(height, width, CV_32FC2);
  in.read(reinterpret_cast<char*>(flow.data), expected - kHeaderBytes);
  if (in.gcount() != expected - kHeaderBytes) fail(path, "truncated while reading");
  for (int y = 0; y < height; ++y) {
    const float* row = flow.ptr<float>(y);
    for (int i = 0; i < 2 * width; ++i) {
      if (std::isnan(row[i])) {
        fail(path, "NaN at (" + std::to_string(i / 2) + "," + std::to_string(y) + ")");
      }
    }
  }
  return flow;
}

void write_flo(const std::string& path, const cv::Mat& flow) {
  if (flow.empty()) throw Error("write_flo('" + path + "'): flow is empty");
  if (flow.type() != CV_32FC2) {
    throw Error("write_flo('" + path + "'): flow must be CV_32FC2, got " +
                cv::typeToString(flow.type()));
  }
  const std::string tmp_path = path + ".tmp";
  std::error_code ec;
  {
    std::ofstream out(tmp_path, std::ios::binary | std::ios::trunc);
    if (!out) throw Error("write_flo: cannot create '" + tmp_path + "'");
    const std::int32_t width = flow.cols;
    const std::int32_t height = flow.rows;
    out.write(reinterpret_cast<const char*>(&kFloMagic), sizeof kFloMagic);
    out.write(reinterpret_cast<const char*>(&width), sizeof width);
    out.write(reinterpret_cast<const char*>(&height), sizeof height);
    // Row by row: a ROI view of a larger flow is not continuous.
    for (int y = 0; y < flow.rows; ++y) {
      out.write(flow.ptr<char>(y), static_cast<std::streamsize>(flow.cols) * 8);
    }
    out.close();
    if (!out) {
      std::filesystem::remove(tmp_path, ec);
      throw Error("write_flo: failed writing '" + tmp_path + "'");
    }
  }
  std::filesystem::rename(tmp_path, path, ec);
  if (ec) {
    const std::string reason = ec.message();
    std::filesystem::remove(tmp_path, ec);
    throw Error("write_flo: cannot rename '" + tmp_path + "' to '" + path + "': " + reason);
  }
}

}  // namespace roiflow::flow
