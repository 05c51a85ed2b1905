#include "video/flow_file_sink.hpp"

#include <cstdio>
#include <filesystem>
#include <opencv2/imgcodecs.hpp>
#include <string>
#include <system_error>
#include <vector>

#include "core/atomic_write.hpp"
#include "core/error.hpp"
#include "eval/flo_io.hpp"
#include "eval/kitti_flow.hpp"

namespace roiflow::video {
namespace {

namespace fs = std::filesystem;

std::string file_name(long long number, FlowFileFormat format) {
  char name[32];
  std::snprintf(name, sizeof name, "%06lld%s", number, extension(format));
  return name;
}

}  // namespace

FlowFileFormat flow_file_format_from_string(std::string_view name) {
  if (name == "flo") return FlowFileFormat::Flo;
  if (name == "kitti") return FlowFileFormat::Kitti;
  throw Error("unknown flow file format '" + std::string(name) + "' (use flo or kitti)");
}

const char* to_string(FlowFileFormat format) {
  return format == FlowFileFormat::Flo ? "flo" : "kitti";
}

const char* extension(FlowFileFormat format) {
  return format == FlowFileFormat::Flo ? ".flo" : ".png";
}

FlowFileSink::FlowFileSink(const std::string& dir, FlowFileFormat format)
    : dir_(dir), format_(format) {
  if (dir.empty()) throw Error("flow file sink: empty folder path");
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec || !fs::is_directory(dir, ec)) {
    throw Error("flow file sink: cannot create the folder '" + dir + "'");
  }
}

cv::Mat FlowFileSink::encode(const cv::Mat& flow) const {
  if (flow.empty() || flow.type() != CV_32FC2) {
    throw Error("flow file sink '" + dir_ + "': flow must be non-empty CV_32FC2, got " +
                cv::typeToString(flow.type()));
  }
  if (format_ == FlowFileFormat::Flo) return flow;
  const cv::Mat kitti = eval::encode_kitti_flow(flow, /*out_of_range_invalid=*/true);
  std::vector<uchar> png;
  if (!cv::imencode(".png", kitti, png, {cv::IMWRITE_PNG_COMPRESSION, 1})) {
    throw Error("flow file sink '" + dir_ + "': cannot encode a KITTI flow PNG");
  }
  return cv::Mat(png, true).reshape(1, 1);
}

void FlowFileSink::write(const cv::Mat& flow) {
  write_encoded(encode(flow));
}

void FlowFileSink::write_encoded(const cv::Mat& encoded) {
  const std::string path = (fs::path(dir_) / file_name(files_ + 1, format_)).string();
  if (format_ == FlowFileFormat::Flo) {
    if (encoded.type() != CV_32FC2) {
      throw Error("flow file sink: '" + path + "': not what encode() made for this sink");
    }
    eval::write_flo(path, encoded);
  } else {
    if (encoded.type() != CV_8UC1 || encoded.rows != 1 || !encoded.isContinuous()) {
      throw Error("flow file sink: '" + path + "': not what encode() made for this sink");
    }
    write_bytes_atomically(path, "KITTI flow ", encoded.data, encoded.total());
  }
  ++files_;
}

std::string FlowFileSink::description() const {
  return std::string(format_ == FlowFileFormat::Flo ? ".flo files" : "KITTI flow PNGs") + " in '" +
         dir_ + "'";
}

}  // namespace roiflow::video
