// What every fuzz target checks, shared with tests/eval/fuzz_regression_test.cpp so that a saved
// crash input is replayed through exactly the same code in the normal build.
//
//   roiflow::fuzz::check_flo(bytes);   // throws InvariantBroken on a bug, nothing otherwise
//
// Each check feeds the bytes to a parser. A roiflow::Error is the parser's clean refusal and is
// swallowed; a successful parse is checked against what the parser promises (sizes, finite
// values, ...) and then fed on to the code that consumes it (scoring). A broken promise throws
// InvariantBroken; any other exception escapes as it is. Under libFuzzer both end in
// std::terminate, i.e. a reported crash; sanitizers catch memory errors and undefined behaviour.
#pragma once

#include <cmath>
#include <cstdint>
#include <cstring>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "core/error.hpp"
#include "eval/flo_io.hpp"
#include "eval/kitti_flow.hpp"
#include "eval/otb_score.hpp"
#include "eval/track_log.hpp"

namespace roiflow::fuzz {

class InvariantBroken : public std::logic_error {
 public:
  using std::logic_error::logic_error;
};

inline void require(bool ok, const std::string& what) {
  if (!ok) throw InvariantBroken(what);
}

inline bool all_nan(const cv::Rect2f& r) {
  return std::isnan(r.x) && std::isnan(r.y) && std::isnan(r.width) && std::isnan(r.height);
}

inline bool finite_box(const cv::Rect2f& r) {
  return std::isfinite(r.x) && std::isfinite(r.y) && std::isfinite(r.width) &&
         std::isfinite(r.height);
}

// Scores a track against a truth (both already parsed) and checks the figures' ranges.
inline void check_score(const std::vector<cv::Rect2f>& track,
                        const std::vector<cv::Rect2f>& truth) {
  eval::OtbScore s;
  try {
    s = eval::score(track, truth);
  } catch (const Error&) {
    return;  // nothing to score
  }
  const double max_auc = 20.0 / 21.0 + 1e-9;
  require(s.frames >= 1 && s.frames <= static_cast<long long>(std::min(track.size(), truth.size())),
          "score: frames out of range");
  require(s.auc >= 0 && s.auc <= max_auc, "score: auc out of range");
  require(s.precision20 >= 0 && s.precision20 <= 1, "score: precision out of range");
  require(s.mean_iou >= 0 && s.mean_iou <= 1 + 1e-9, "score: mean IoU out of range");
}

inline void check_flo(std::string_view bytes) {
  cv::Mat flow;
  try {
    flow = eval::parse_flo(bytes, "fuzz.flo");
  } catch (const Error&) {
    return;
  }
  require(flow.type() == CV_32FC2, "flo: not CV_32FC2");
  require(flow.isContinuous(), "flo: not continuous");
  require(bytes.size() == 12 + flow.total() * 8, "flo: size does not match the byte count");
  std::int32_t header[2];
  std::memcpy(header, bytes.data() + 4, sizeof header);
  require(header[0] == flow.cols && header[1] == flow.rows, "flo: size differs from the header");
  require(std::memcmp(flow.data, bytes.data() + 12, bytes.size() - 12) == 0,
          "flo: values differ from the file's");
  const float* v = flow.ptr<float>();
  for (std::size_t i = 0; i < 2 * flow.total(); ++i)
    require(!std::isnan(v[i]), "flo: NaN accepted");
}

inline void check_ground_truth(std::string_view text) {
  std::vector<cv::Rect2f> boxes;
  try {
    boxes = eval::parse_ground_truth(text, "fuzz.txt");
  } catch (const Error&) {
    return;
  }
  require(!boxes.empty(), "ground truth: no box but no error");
  for (const cv::Rect2f& b : boxes) {
    require(all_nan(b) || (finite_box(b) && b.width >= 0 && b.height >= 0),
            "ground truth: a box that is neither absent (4 NaN) nor finite with a size >= 0");
  }
  check_score(boxes, boxes);
  // A track that is off by one frame against the same truth.
  check_score(std::vector<cv::Rect2f>(boxes.begin() + 1, boxes.end()), boxes);
}

inline void check_track_csv(std::string_view text) {
  std::vector<eval::TrackRecord> records;
  try {
    records = eval::parse_track_csv(text, "fuzz.csv");
  } catch (const Error&) {
    return;
  }
  for (const eval::TrackRecord& r : records) {
    require(r.frame >= 1, "track csv: frame < 1 accepted");
    require(finite_box(r.box) && r.box.width >= 0 && r.box.height >= 0,
            "track csv: a box that is not finite or has a negative size");
    require(std::isfinite(r.velocity.x) && std::isfinite(r.velocity.y) && std::isfinite(r.ms),
            "track csv: a velocity or time that is not finite");
  }
  std::vector<cv::Rect2f> boxes;
  try {
    boxes = eval::track_boxes(records);
  } catch (const Error&) {
    return;
  }
  require(boxes.size() == records.size(), "track_boxes: lost records");
  check_score(boxes, boxes);
}

// Decoded KITTI flow must encode back to the same pixels (invalid ones as all zero).
inline void check_kitti_round_trip(const cv::Mat& png) {
  cv::Mat flow;
  try {
    flow = eval::decode_kitti_flow(png);
  } catch (const Error&) {
    return;
  }
  require(flow.size() == png.size() && flow.type() == CV_32FC2, "kitti: size or type changed");
  const cv::Mat again = eval::encode_kitti_flow(flow);  // decoded values are always in range
  for (int y = 0; y < png.rows; ++y) {
    for (int x = 0; x < png.cols; ++x) {
      const cv::Vec3w p = png.at<cv::Vec3w>(y, x);
      const cv::Vec3w expected = p[0] == 0 ? cv::Vec3w(0, 0, 0) : cv::Vec3w(1, p[1], p[2]);
      require(again.at<cv::Vec3w>(y, x) == expected, "kitti: flow does not round-trip");
    }
  }
}

// The KITTI 16-bit PNG reader. A PNG (by its signature) goes through cv::imdecode, as
// read_kitti_flow's cv::imread, then decode_kitti_flow. Any other input is raw pixels for
// decode_kitti_flow itself: byte 0 picks the width (1..64), the rest are uint16 B G R triples
// (libpng's CRCs would otherwise keep most mutations away from our code). Other image formats
// are not fed to OpenCV: that would fuzz its other decoders (some go through a temporary file).
inline void check_kitti_flow(std::string_view bytes) {
  if (bytes.starts_with(std::string_view("\x89PNG\r\n\x1a\n", 8))) {
    const std::vector<uchar> data(bytes.begin(), bytes.end());
    cv::Mat png;
    try {
      png = cv::imdecode(data, cv::IMREAD_UNCHANGED);
    } catch (const cv::Exception&) {
      return;  // OpenCV's own refusal (imread reports it as an empty image)
    }
    check_kitti_round_trip(png);
    return;
  }
  if (bytes.empty()) return;
  const int width = 1 + static_cast<unsigned char>(bytes[0]) % 64;
  const int rows = static_cast<int>((bytes.size() - 1) / (6 * static_cast<std::size_t>(width)));
  cv::Mat raw(rows, width, CV_16UC3);
  if (rows > 0) std::memcpy(raw.data, bytes.data() + 1, raw.total() * 6);
  check_kitti_round_trip(raw);
}

}  // namespace roiflow::fuzz
