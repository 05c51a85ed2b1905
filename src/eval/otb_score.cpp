#include "eval/otb_score.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>
#include <string_view>
#include <system_error>

#include "core/error.hpp"
#include "core/text.hpp"
#include "core/text_file.hpp"

namespace roiflow::eval {
namespace {

constexpr int kPrecisionPixels = 20;

bool is_finite(const cv::Rect2f& r) {
  return std::isfinite(r.x) && std::isfinite(r.y) && std::isfinite(r.width) &&
         std::isfinite(r.height);
}

// Written so that NaN sizes count as empty too.
bool has_area(const cv::Rect2f& r) {
  return r.width > 0 && r.height > 0;
}

bool is_space(char c) {
  return c == ' ' || c == '\t';
}

// Values are separated by a run of spaces and tabs, or by one comma with optional spaces
// around it: `1,2,3,4`, `1 2 3 4`, `1\t2\t3\t4` and `1, 2,3 4` all hold four values, while
// `1,,2,3` holds an empty one.
std::vector<std::string_view> split_values(std::string_view line, const std::string& where) {
  std::vector<std::string_view> values;
  std::size_t i = 0;
  const auto skip_spaces = [&] {
    while (i < line.size() && is_space(line[i]))
      ++i;
  };
  skip_spaces();
  while (i < line.size()) {
    const std::size_t start = i;
    while (i < line.size() && !is_space(line[i]) && line[i] != ',')
      ++i;
    if (i == start) throw Error(where + "empty value " + std::to_string(values.size() + 1));
    values.push_back(line.substr(start, i - start));
    skip_spaces();
    if (i < line.size() && line[i] == ',') {
      ++i;
      skip_spaces();
      if (i == line.size()) throw Error(where + "empty value after the last comma");
    }
  }
  return values;
}

// The four numbers x,y,w,h of `text` (values `first`..`first + 3`), checked as described in
// the header; `line` is quoted in messages.
cv::Rect2f parse_box_values(const std::vector<std::string_view>& text, std::size_t first,
                            std::string_view line, const std::string& where) {
  double v[4];
  int nans = 0;
  for (int k = 0; k < 4; ++k) {
    const std::string_view t = text[first + k];
    const auto [end, ec] = std::from_chars(t.data(), t.data() + t.size(), v[k]);
    if (ec != std::errc() || end != t.data() + t.size() || std::isinf(v[k])) {
      throw Error(where + "value " + std::to_string(first + k + 1) + " " + quoted_excerpt(t) +
                  " is not a finite number");
    }
    // Boxes are floats: a larger value would become infinity (found by fuzzing).
    if (std::abs(v[k]) > std::numeric_limits<float>::max()) {
      throw Error(where + "value " + std::to_string(first + k + 1) + " " + quoted_excerpt(t) +
                  " is too large");
    }
    if (std::isnan(v[k])) ++nans;
  }
  if (nans != 0 && nans != 4) {
    throw Error(where + "partly NaN box " + quoted_excerpt(line) + " (an absent target is 4 NaN)");
  }
  if (v[2] < 0 || v[3] < 0) {
    throw Error(where + "negative size " + std::string(text[first + 2]) + "x" +
                std::string(text[first + 3]));
  }
  return {static_cast<float>(v[0]), static_cast<float>(v[1]), static_cast<float>(v[2]),
          static_cast<float>(v[3])};
}

// An integer value of a TinyTLP line (its frame number or its absent flag).
long long parse_tlp_integer(std::string_view t, std::size_t index, const std::string& where) {
  long long value = 0;
  const auto [end, ec] = std::from_chars(t.data(), t.data() + t.size(), value);
  if (ec != std::errc() || end != t.data() + t.size()) {
    throw Error(where + "value " + std::to_string(index + 1) + " " + quoted_excerpt(t) +
                " is not an integer");
  }
  return value;
}

constexpr std::size_t kOtbColumns = 4;      // x,y,w,h
constexpr std::size_t kTinyTlpColumns = 6;  // frame,x,y,w,h,absent

// One line of a file whose first line had `columns` values; `number` is the box's 1-based index.
cv::Rect2f parse_truth_line(std::string_view line, std::size_t columns, long long number,
                            const std::string& where) {
  const std::vector<std::string_view> text = split_values(line, where);
  if (text.size() != columns) {
    if (columns == kTinyTlpColumns) {
      throw Error(where +
                  "expected 6 values frame,x,y,w,h,absent (TinyTLP, as the first line), got " +
                  std::to_string(text.size()));
    }
    throw Error(where + "expected 4 values x,y,w,h, got " + std::to_string(text.size()) +
                (number == 1 ? " (TinyTLP files have 6: frame,x,y,w,h,absent)" : ""));
  }
  if (columns == kOtbColumns) return parse_box_values(text, 0, line, where);
  const long long frame = parse_tlp_integer(text[0], 0, where);
  if (frame != number) {
    throw Error(where + "TinyTLP frame number " + std::to_string(frame) + ", expected " +
                std::to_string(number) + " (frames must run 1, 2, 3, ...)");
  }
  const long long absent = parse_tlp_integer(text[5], 5, where);
  if (absent != 0 && absent != 1) {
    throw Error(where + "TinyTLP absent flag " + std::string(text[5]) + " is neither 0 nor 1");
  }
  const cv::Rect2f box = parse_box_values(text, 1, line, where);
  if (absent == 1) {
    const float nan = std::numeric_limits<float>::quiet_NaN();
    return {nan, nan, nan, nan};
  }
  return box;
}

}  // namespace

std::vector<cv::Rect2f> parse_ground_truth(std::string_view text, const std::string& name) {
  std::vector<cv::Rect2f> boxes;
  std::size_t columns = 0;  // the first line's count decides the format
  for_each_line(text, [&](long long number, std::string_view line) {
    if (line.find_first_not_of(" \t") == std::string_view::npos) return;
    const std::string where = name + ":" + std::to_string(number) + ": ";
    if (columns == 0) {
      const std::size_t n = split_values(line, where).size();
      columns = n == kTinyTlpColumns ? kTinyTlpColumns : kOtbColumns;
    }
    boxes.push_back(
        parse_truth_line(line, columns, static_cast<long long>(boxes.size()) + 1, where));
  });
  if (boxes.empty()) throw Error("ground truth '" + name + "' holds no box");
  return boxes;
}

std::vector<cv::Rect2f> read_ground_truth(const std::string& path) {
  return parse_ground_truth(read_text_file(path, "ground truth"), path);
}

std::vector<cv::Rect2f> track_boxes(const std::vector<TrackRecord>& records) {
  std::vector<cv::Rect2f> boxes;
  boxes.reserve(records.size());
  for (const TrackRecord& r : records) {
    const long long expected = static_cast<long long>(boxes.size()) + 1;
    if (r.frame != expected) {
      throw Error("track record " + std::to_string(expected) + " is frame " +
                  std::to_string(r.frame) + ", expected frame " + std::to_string(expected) +
                  " (frames must run 1, 2, 3, ... without gaps)");
    }
    boxes.push_back(r.box);
  }
  return boxes;
}

double iou(const cv::Rect2f& a, const cv::Rect2f& b) {
  if (!is_finite(a) || !is_finite(b) || !has_area(a) || !has_area(b)) return 0;
  // Relative to a's corner, so that far from the origin (x = 7e17, where a double's step is
  // 128) the sizes do not round away: the overlap never exceeds the smaller box and the IoU never
  // exceeds 1 (found by fuzzing).
  const double dx = double{b.x} - a.x;
  const double dy = double{b.y} - a.y;
  const double w = std::min(double{a.width}, dx + b.width) - std::max(0.0, dx);
  const double h = std::min(double{a.height}, dy + b.height) - std::max(0.0, dy);
  if (w <= 0 || h <= 0) return 0;
  const double inter = std::min(w, double{std::min(a.width, b.width)}) *
                       std::min(h, double{std::min(a.height, b.height)});
  return std::min(1.0, inter / (double{a.width} * a.height + double{b.width} * b.height - inter));
}

double center_error(const cv::Rect2f& a, const cv::Rect2f& b) {
  if (!is_finite(a) || !is_finite(b)) return std::numeric_limits<double>::infinity();
  const double dx = (double{a.x} + 0.5 * a.width) - (double{b.x} + 0.5 * b.width);
  const double dy = (double{a.y} + 0.5 * a.height) - (double{b.y} + 0.5 * b.height);
  return std::hypot(dx, dy);
}

namespace {

struct Tally {
  OtbCurves curves;
  double iou_sum = 0;
};

Tally tally_curves(const std::vector<cv::Rect2f>& track, const std::vector<cv::Rect2f>& truth) {
  const std::size_t n = std::min(track.size(), truth.size());
  std::vector<long long> above(kSuccessThresholds, 0);
  std::vector<long long> near(kPrecisionThresholds, 0);
  Tally t;
  long long& frames = t.curves.frames;
  for (std::size_t i = 0; i < n; ++i) {
    if (!is_finite(truth[i]) || !has_area(truth[i])) continue;
    const double overlap = iou(track[i], truth[i]);
    for (int k = 0; k < kSuccessThresholds; ++k) {
      // k / 20 rather than k * 0.05: the threshold 0.5 is then exactly 0.5.
      if (overlap > static_cast<double>(k) / (kSuccessThresholds - 1)) ++above[k];
    }
    const double error = center_error(track[i], truth[i]);
    for (int k = 0; k < kPrecisionThresholds; ++k) {
      if (error <= k) ++near[k];
    }
    t.iou_sum += overlap;
    ++frames;
  }
  if (frames == 0) {
    throw Error("no frame to score: the track has " + std::to_string(track.size()) +
                " boxes, the ground truth " + std::to_string(truth.size()) + ", and " +
                (n == 0
                     ? std::string("none to compare")
                     : "the target is absent in all " + std::to_string(n) + " frames they share"));
  }
  const double count = static_cast<double>(frames);
  for (long long a : above)
    t.curves.success.push_back(static_cast<double>(a) / count);
  for (long long a : near)
    t.curves.precision.push_back(static_cast<double>(a) / count);
  return t;
}

}  // namespace

OtbCurves otb_curves(const std::vector<cv::Rect2f>& track, const std::vector<cv::Rect2f>& truth) {
  return tally_curves(track, truth).curves;
}

double curve_auc(const std::vector<double>& success) {
  double sum = 0;
  for (double v : success)
    sum += v;
  return success.empty() ? 0.0 : sum / static_cast<double>(success.size());
}

OtbScore score(const std::vector<cv::Rect2f>& track, const std::vector<cv::Rect2f>& truth) {
  const Tally t = tally_curves(track, truth);
  OtbScore s;
  s.frames = t.curves.frames;
  s.auc = curve_auc(t.curves.success);
  s.precision20 = t.curves.precision[static_cast<std::size_t>(kPrecisionPixels)];
  s.mean_iou = t.iou_sum / static_cast<double>(s.frames);
  return s;
}

std::vector<cv::Rect2f> read_track_boxes(const std::string& path) {
  const std::vector<TrackRecord> records = read_track_csv(path);
  try {
    return track_boxes(records);
  } catch (const Error& e) {
    // track_boxes knows records, not the file they came from.
    throw Error("track log '" + path + "': " + e.what());
  }
}

std::string score_table(const OtbScore& s, std::size_t track_boxes, std::size_t truth_boxes) {
  return "success AUC    " + fixed(s.auc, 4) + "\nprecision@20   " + fixed(s.precision20, 4) +
         "\nmean IoU       " + fixed(s.mean_iou, 4) + "\nframes         " +
         std::to_string(s.frames) + " (track " + std::to_string(track_boxes) + ", ground truth " +
         std::to_string(truth_boxes) + ")\n";
}

cv::Rect2f parse_box(const std::string& text) {
  std::string spaced = text;
  std::replace(spaced.begin(), spaced.end(), ',', ' ');
  std::istringstream in(spaced);
  double v[4];
  for (double& x : v) {
    if (!(in >> x) || !std::isfinite(x)) throw Error("expected x,y,w,h, got '" + text + "'");
  }
  std::string rest;
  if (in >> rest) throw Error("expected 4 numbers x,y,w,h, got '" + text + "'");
  if (!(v[2] > 0 && v[3] > 0)) {
    throw Error("the box needs a positive width and height, got '" + text + "'");
  }
  return {static_cast<float>(v[0]), static_cast<float>(v[1]), static_cast<float>(v[2]),
          static_cast<float>(v[3])};
}

}  // namespace roiflow::eval
