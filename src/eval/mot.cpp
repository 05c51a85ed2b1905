#include "eval/mot.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>
#include <system_error>
#include <unordered_map>
#include <utility>

#include "core/assignment.hpp"
#include "core/atomic_write.hpp"
#include "core/error.hpp"
#include "core/text.hpp"
#include "core/text_file.hpp"
#include "eval/line_error_impl.hpp"

namespace roiflow::eval {
namespace {

constexpr double kIouThreshold = 0.5;
// TrackEval compares with 0.5 - machine epsilon: a box pair at exactly 0.5 matches.
constexpr double kIouGate = kIouThreshold - std::numeric_limits<double>::epsilon();
constexpr int kDistractorClasses[] = {2, 7, 8, 12};
constexpr int kPedestrian = 1;

using detail::LineError;

std::string_view trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t'))
    s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t'))
    s.remove_suffix(1);
  return s;
}

std::vector<std::string_view> split_fields(std::string_view line) {
  std::vector<std::string_view> fields;
  if (line.find(',') != std::string_view::npos) {
    for (const std::string_view field : split_view(line, ','))
      fields.push_back(trim(field));
    return fields;
  }
  for (std::size_t start = 0; start < line.size();) {
    start = line.find_first_not_of(" \t", start);
    if (start == std::string_view::npos) break;
    const std::size_t end = std::min(line.find_first_of(" \t", start), line.size());
    fields.push_back(line.substr(start, end - start));
    start = end;
  }
  return fields;
}

// Frames and ids are integers; some tools write them as "1.0" or "1.000000".
int parse_mot_integer(std::string_view field, const char* name, int min, const LineError& error) {
  const double value = error.number(field, name);
  if (value != std::floor(value) || value < min || value > std::numeric_limits<int>::max()) {
    error.fail(std::string(name) + " " + quoted_excerpt(field) +
               " is not an integer >= " + std::to_string(min));
  }
  return static_cast<int>(value);
}

MotBox parse_mot_row(const std::vector<std::string_view>& f, const LineError& error) {
  if (f.size() < 6 || f.size() > 10) {
    error.fail("expected 6 to 10 fields (frame,id,x,y,w,h,conf,...), got " +
               std::to_string(f.size()));
  }
  MotBox b;
  b.frame = parse_mot_integer(f[0], "frame", 1, error);
  b.id = parse_mot_integer(f[1], "id", 0, error);
  b.box.x = error.number(f[2], "x");
  b.box.y = error.number(f[3], "y");
  b.box.width = error.number(f[4], "w");
  b.box.height = error.number(f[5], "h");
  if (b.box.width < 0 || b.box.height < 0) {
    error.fail("negative box size " + std::string(f[4]) + "x" + std::string(f[5]));
  }
  if (f.size() >= 7) b.conf = error.number(f[6], "conf");
  if (f.size() == 8 || f.size() == 9) {
    b.object_class = parse_mot_integer(f[7], "class", 1, error);
    if (b.object_class > 13) {
      error.fail("class " + quoted_excerpt(f[7]) + " is not a MOTChallenge class (1..13)");
    }
  }
  if (f.size() == 9) {
    b.visibility = error.number(f[8], "visibility");
    if (b.visibility < 0 || b.visibility > 1) {
      error.fail("visibility " + quoted_excerpt(f[8]) + " is not in 0..1");
    }
  }
  return b;
}

std::string fixed2(double value) {
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, "%.2f", value);
  std::string text = buffer;
  if (text.front() == '-' && text.find_first_not_of("-0.") == std::string::npos) text.erase(0, 1);
  return text;
}

bool by_frame_then_id(const MotBox& a, const MotBox& b) {
  return a.frame != b.frame ? a.frame < b.frame : a.id < b.id;
}

bool is_distractor(int object_class) {
  return std::find(std::begin(kDistractorClasses), std::end(kDistractorClasses), object_class) !=
         std::end(kDistractorClasses);
}

struct Frame {
  std::vector<const MotBox*> gt;
  std::vector<const MotBox*> pred;
};

std::vector<double> iou_matrix(const std::vector<const MotBox*>& gt,
                               const std::vector<const MotBox*>& pred) {
  std::vector<double> m(gt.size() * pred.size());
  for (std::size_t i = 0; i < gt.size(); ++i)
    for (std::size_t j = 0; j < pred.size(); ++j)
      m[i * pred.size() + j] = mot_iou(gt[i]->box, pred[j]->box);
  return m;
}

// TrackEval's preprocessing: tracker boxes matched to a distractor are dropped. The matching
// maximises the summed IoU of pairs at IoU >= 0.5 over all ground-truth boxes of the frame.
void remove_distractor_matches(Frame& frame) {
  const bool any = std::any_of(frame.gt.begin(), frame.gt.end(),
                               [](const MotBox* b) { return is_distractor(b->object_class); });
  if (!any || frame.pred.empty()) return;
  const std::vector<double> iou = iou_matrix(frame.gt, frame.pred);
  std::vector<double> cost(iou.size());
  for (std::size_t k = 0; k < iou.size(); ++k)
    cost[k] = iou[k] >= kIouGate ? -iou[k] : 0.0;
  const int rows = static_cast<int>(frame.gt.size());
  const int cols = static_cast<int>(frame.pred.size());
  const Assignment a = solve_assignment(cost, rows, cols);
  std::vector<const MotBox*> kept;
  for (int j = 0; j < cols; ++j) {
    const int i = a.col_to_row[j];
    const bool drop = i >= 0 && iou[static_cast<std::size_t>(i) * cols + j] >= kIouGate &&
                      is_distractor(frame.gt[i]->object_class);
    if (!drop) kept.push_back(frame.pred[j]);
  }
  frame.pred = std::move(kept);
}

bool scored_gt(const MotBox& b) {
  return b.conf != 0 && (b.object_class == 0 || b.object_class == kPedestrian);
}

}  // namespace

double mot_iou(const cv::Rect2d& a, const cv::Rect2d& b) {
  if (!(a.width > 0 && a.height > 0 && b.width > 0 && b.height > 0)) return 0;
  const double w = std::min(a.x + a.width, b.x + b.width) - std::max(a.x, b.x);
  const double h = std::min(a.y + a.height, b.y + b.height) - std::max(a.y, b.y);
  if (w <= 0 || h <= 0) return 0;
  const double inter = w * h;
  return inter / (a.width * a.height + b.width * b.height - inter);
}

std::vector<MotBox> parse_mot(std::string_view text, const std::string& name) {
  std::vector<MotBox> boxes;
  std::vector<long long> line_of;
  for_each_line(text, [&](long long number, std::string_view line) {
    if (trim(line).empty()) return;
    boxes.push_back(parse_mot_row(split_fields(line), LineError(name, number)));
    line_of.push_back(number);
  });
  std::vector<std::size_t> order(boxes.size());
  for (std::size_t i = 0; i < order.size(); ++i)
    order[i] = i;
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    return by_frame_then_id(boxes[a], boxes[b]);
  });
  std::vector<MotBox> sorted;
  sorted.reserve(boxes.size());
  for (std::size_t k = 0; k < order.size(); ++k) {
    const MotBox& b = boxes[order[k]];
    if (!sorted.empty() && sorted.back().frame == b.frame && sorted.back().id == b.id) {
      LineError(name, line_of[order[k]])
          .fail("id " + std::to_string(b.id) + " appears twice in frame " +
                std::to_string(b.frame) + " (also line " + std::to_string(line_of[order[k - 1]]) +
                ")");
    }
    sorted.push_back(b);
  }
  return sorted;
}

std::vector<MotBox> read_mot(const std::string& path, const std::string& what) {
  return parse_mot(read_text_file(path, what), path);
}

std::string format_mot(std::vector<MotBox> boxes) {
  std::stable_sort(boxes.begin(), boxes.end(), by_frame_then_id);
  std::string text;
  for (const MotBox& b : boxes) {
    text += std::to_string(b.frame) + "," + std::to_string(b.id) + "," + fixed2(b.box.x) + "," +
            fixed2(b.box.y) + "," + fixed2(b.box.width) + "," + fixed2(b.box.height) + "," +
            number_text(b.conf) + ",-1,-1,-1\n";
  }
  return text;
}

void write_mot(const std::string& path, const std::vector<MotBox>& boxes) {
  write_text_atomically(path, format_mot(boxes));
}

MotScore score_mot(const std::vector<MotBox>& pred, const std::vector<MotBox>& gt) {
  std::map<int, Frame> frames;
  for (const MotBox& b : gt)
    frames[b.frame].gt.push_back(&b);
  for (const MotBox& b : pred)
    frames[b.frame].pred.push_back(&b);

  MotScore s;
  std::unordered_map<int, int> last_match;  // gt id -> hypothesis id it was last matched to
  std::map<int, long long> gt_count, pred_count;
  std::map<std::pair<int, int>, long long> overlaps;  // (gt id, pred id) -> frames at IoU >= 0.5
  double iou_sum = 0;

  for (auto& [number, frame] : frames) {
    remove_distractor_matches(frame);
    std::erase_if(frame.gt, [](const MotBox* b) { return !scored_gt(*b); });
    if (frame.gt.empty() && frame.pred.empty()) continue;
    ++s.frames;
    auto by_id = [](const MotBox* a, const MotBox* b) { return a->id < b->id; };
    std::sort(frame.gt.begin(), frame.gt.end(), by_id);
    std::sort(frame.pred.begin(), frame.pred.end(), by_id);
    const int rows = static_cast<int>(frame.gt.size());
    const int cols = static_cast<int>(frame.pred.size());
    const std::vector<double> iou = iou_matrix(frame.gt, frame.pred);
    s.gt_boxes += rows;
    s.pred_boxes += cols;
    for (const MotBox* g : frame.gt)
      ++gt_count[g->id];
    for (const MotBox* p : frame.pred)
      ++pred_count[p->id];
    for (int i = 0; i < rows; ++i)
      for (int j = 0; j < cols; ++j)
        if (iou[static_cast<std::size_t>(i) * cols + j] >= kIouGate)
          ++overlaps[{frame.gt[i]->id, frame.pred[j]->id}];

    std::vector<char> gt_done(rows, 0), pred_done(cols, 0);
    auto match = [&](int i, int j) {
      gt_done[i] = pred_done[j] = 1;
      ++s.matches;
      iou_sum += iou[static_cast<std::size_t>(i) * cols + j];
      const auto it = last_match.find(frame.gt[i]->id);
      if (it != last_match.end() && it->second != frame.pred[j]->id) ++s.id_switches;
      last_match[frame.gt[i]->id] = frame.pred[j]->id;
    };
    // 1. Keep earlier correspondences that still hold.
    for (int i = 0; i < rows; ++i) {
      const auto it = last_match.find(frame.gt[i]->id);
      if (it == last_match.end()) continue;
      for (int j = 0; j < cols; ++j) {
        if (pred_done[j] || frame.pred[j]->id != it->second) continue;
        if (iou[static_cast<std::size_t>(i) * cols + j] >= kIouGate) match(i, j);
        break;
      }
    }
    // 2. Optimal assignment of the rest: most pairs at IoU >= 0.5, then least sum of 1 - IoU.
    std::vector<double> cost(iou.size(), std::numeric_limits<double>::infinity());
    for (int i = 0; i < rows; ++i) {
      for (int j = 0; j < cols; ++j) {
        const std::size_t k = static_cast<std::size_t>(i) * cols + j;
        if (!gt_done[i] && !pred_done[j] && iou[k] >= kIouGate) cost[k] = 1 - iou[k];
      }
    }
    const Assignment a = solve_assignment(cost, rows, cols);
    for (int i = 0; i < rows; ++i) {
      if (a.row_to_col[i] >= 0) match(i, a.row_to_col[i]);
    }
    for (int i = 0; i < rows; ++i)
      s.fn += !gt_done[i];
    for (int j = 0; j < cols; ++j)
      s.fp += !pred_done[j];
  }
  if (s.gt_boxes == 0) throw Error("the ground truth has no box to score (all conf 0 or empty)");

  s.objects = static_cast<long long>(gt_count.size());
  s.tracks = static_cast<long long>(pred_count.size());
  s.mota = 1.0 - static_cast<double>(s.fn + s.fp + s.id_switches) / static_cast<double>(s.gt_boxes);
  s.motp = s.matches > 0 ? iou_sum / static_cast<double>(s.matches) : 0.0;

  // IDF1: the pairing of ids with the most overlapping frames (negated counts, no gate).
  std::map<int, int> gt_index, pred_index;
  for (const auto& [id, count] : gt_count)
    gt_index.emplace(id, static_cast<int>(gt_index.size()));
  for (const auto& [id, count] : pred_count)
    pred_index.emplace(id, static_cast<int>(pred_index.size()));
  const int rows = static_cast<int>(gt_index.size());
  const int cols = static_cast<int>(pred_index.size());
  std::vector<double> cost(static_cast<std::size_t>(rows) * cols, 0.0);
  for (const auto& [ids, count] : overlaps) {
    cost[static_cast<std::size_t>(gt_index[ids.first]) * cols + pred_index[ids.second]] =
        -static_cast<double>(count);
  }
  const double idtp = -solve_assignment(cost, rows, cols).cost;
  s.idf1 = 2 * idtp / static_cast<double>(s.gt_boxes + s.pred_boxes);
  s.idr = idtp / static_cast<double>(s.gt_boxes);
  s.idp = s.pred_boxes > 0 ? idtp / static_cast<double>(s.pred_boxes) : 0.0;
  return s;
}

}  // namespace roiflow::eval
