#include "eval/flo_io.hpp"

#include <bit>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <system_error>

#include "core/error.hpp"

namespace roiflow::eval {
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

namespace {

struct FloHeader {
  std::int32_t width = 0;
  std::int32_t height = 0;
};

// Checks the 12 header bytes against the total size, before anything is allocated, so a corrupt
// header cannot ask for gigabytes.
FloHeader check_header(const char* header, std::uintmax_t total_bytes, const std::string& name) {
  if (total_bytes < static_cast<std::uintmax_t>(kHeaderBytes)) {
    fail(name, std::to_string(total_bytes) + " bytes, shorter than the 12-byte header");
  }
  float magic = 0;
  FloHeader h;
  std::memcpy(&magic, header, sizeof magic);
  std::memcpy(&h.width, header + 4, sizeof h.width);
  std::memcpy(&h.height, header + 8, sizeof h.height);
  if (magic != kFloMagic) fail(name, "bad magic " + to_text(magic) + " (expected 202021.25)");
  if (h.width <= 0 || h.height <= 0 || h.width > kMaxSide || h.height > kMaxSide) {
    fail(name, "bad size " + std::to_string(h.width) + "x" + std::to_string(h.height));
  }
  const std::int64_t expected = kHeaderBytes + std::int64_t{8} * h.width * h.height;
  if (total_bytes != static_cast<std::uintmax_t>(expected)) {
    fail(name, std::to_string(h.width) + "x" + std::to_string(h.height) + " flow needs " +
                   std::to_string(expected) + " bytes, file has " + std::to_string(total_bytes) +
                   (total_bytes < static_cast<std::uintmax_t>(expected) ? " (truncated)"
                                                                        : " (trailing bytes)"));
  }
  return h;
}

void check_no_nan(const cv::Mat& flow, const std::string& name) {
  for (int y = 0; y < flow.rows; ++y) {
    const float* row = flow.ptr<float>(y);
    for (int i = 0; i < 2 * flow.cols; ++i) {
      if (std::isnan(row[i])) {
        fail(name, "NaN at (" + std::to_string(i / 2) + "," + std::to_string(y) + ")");
      }
    }
  }
}

}  // namespace

cv::Mat parse_flo(std::string_view bytes, const std::string& name) {
  if (bytes.size() < static_cast<std::size_t>(kHeaderBytes)) {
    check_header(nullptr, bytes.size(), name);  // throws "shorter than the header"
  }
  const FloHeader h = check_header(bytes.data(), bytes.size(), name);
  cv::Mat flow(h.height, h.width, CV_32FC2);
  std::memcpy(flow.data, bytes.data() + kHeaderBytes, bytes.size() - kHeaderBytes);
  check_no_nan(flow, name);
  return flow;
}

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
    check_header(nullptr, file_bytes, path);  // throws "shorter than the header"
  }
  std::ifstream in(path, std::ios::binary);
  if (!in) fail(path, "cannot open for reading");

  char header[kHeaderBytes];
  if (!in.read(header, sizeof header)) fail(path, "cannot read the header");
  const FloHeader h = check_header(header, file_bytes, path);

  cv::Mat flow(h.height, h.width, CV_32FC2);
  const std::streamsize body = static_cast<std::streamsize>(file_bytes) - kHeaderBytes;
  in.read(reinterpret_cast<char*>(flow.data), body);
  if (in.gcount() != body) fail(path, "truncated while reading");
  check_no_nan(flow, path);
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

}  // namespace roiflow::eval
