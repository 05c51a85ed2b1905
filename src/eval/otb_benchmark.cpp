#include "eval/otb_benchmark.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <initializer_list>
#include <limits>
#include <map>
#include <set>
#include <string_view>
#include <system_error>

#include "core/error.hpp"
#include "core/text.hpp"

namespace roiflow::eval {
namespace fs = std::filesystem;

namespace {

constexpr const char* kGroundTruth = "groundtruth_rect.txt";

// fixed() of core/text.hpp, but "nan" for any value that is not finite (an empty sequence's).
std::string fixed_or_nan(double value, int decimals) {
  return std::isfinite(value) ? fixed(value, decimals) : std::string("nan");
}

bool regular_file(const fs::path& p) {
  std::error_code ec;
  return fs::is_regular_file(p, ec);
}

OtbSequence read_sequence(const fs::path& dir) {
  OtbSequence s;
  s.name = dir.filename().string();
  s.dir = dir.string();
  s.truth = read_ground_truth((dir / kGroundTruth).string());
  const cv::Rect2f& first = s.truth.front();
  if (!(std::isfinite(first.x) && first.width > 0 && first.height > 0)) {
    throw Error((dir / kGroundTruth).string() +
                ": the target is absent in the first frame (a tracker starts from that box)");
  }
  return s;
}

// Appends the parts in order (GCC 12 misreads `"literal" + std::string&&` chains as overlapping
// copies, -Wrestrict).
void append(std::string& out, std::initializer_list<std::string_view> parts) {
  for (std::string_view p : parts)
    out += p;
}

// A Markdown table cell: '|' escaped, line breaks as spaces.
std::string md_cell(const std::string& text) {
  std::string cell;
  for (char c : text) {
    if (c == '|') {
      cell += "\\|";
    } else {
      cell += (c == '\n' || c == '\r') ? ' ' : c;
    }
  }
  return cell;
}

std::string share_text(const BenchmarkRow& r) {
  const double share = r.lost_share();
  if (!std::isfinite(share)) return "- (0 frames)";
  return fixed(share, 2) + " (" + std::to_string(r.zero_iou_lost) + "/" +
         std::to_string(r.zero_iou) + ")";
}

}  // namespace

std::vector<OtbSequence> find_otb_sequences(const std::string& dir,
                                            std::vector<std::string>* skipped) {
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) throw Error("benchmark folder '" + dir + "' is not a directory");
  const fs::path root(dir);
  if (regular_file(root / kGroundTruth)) {
    fs::path named = root;
    if (!named.has_filename()) named = named.parent_path();  // "Car4/" names Car4
    OtbSequence s = read_sequence(root);
    s.name = fs::absolute(named).filename().string();
    return {s};
  }
  std::vector<fs::path> folders;
  for (const fs::directory_entry& e : fs::directory_iterator(root, ec)) {
    if (e.is_directory(ec)) folders.push_back(e.path());
  }
  if (ec) throw Error("cannot list benchmark folder '" + dir + "': " + ec.message());
  std::sort(folders.begin(), folders.end());
  std::vector<OtbSequence> sequences;
  for (const fs::path& f : folders) {
    if (regular_file(f / kGroundTruth)) {
      sequences.push_back(read_sequence(f));
    } else if (skipped) {
      skipped->push_back(f.filename().string());
    }
  }
  if (sequences.empty()) {
    throw Error("benchmark folder '" + dir +
                "' holds no sequence (a folder with groundtruth_rect.txt and img/)");
  }
  return sequences;
}

std::string track_log_csv(const TrackerRun& run) {
  std::string csv = std::string(kTrackCsvHeader) + "\n";
  for (std::size_t i = 0; i < run.boxes.size(); ++i) {
    TrackRecord r;
    r.frame = static_cast<long long>(i) + 1;
    r.box = run.boxes[i];
    r.lost = i < run.lost.size() && run.lost[i];
    r.ms = i < run.ms.size() ? run.ms[i] : 0.0;
    csv += track_csv_row(r);
  }
  return csv;
}

double BenchmarkRow::lost_share() const {
  if (zero_iou == 0) return std::numeric_limits<double>::quiet_NaN();
  return static_cast<double>(zero_iou_lost) / static_cast<double>(zero_iou);
}

BenchmarkRow score_run(const std::string& sequence, const std::string& tracker,
                       const std::vector<cv::Rect2f>& truth, const TrackerRun& run) {
  if (run.boxes.size() != run.lost.size()) {
    throw Error(tracker + " on " + sequence + ": " + std::to_string(run.boxes.size()) +
                " boxes but " + std::to_string(run.lost.size()) + " lost flags");
  }
  BenchmarkRow r;
  r.sequence = sequence;
  r.tracker = tracker;
  const OtbScore s = score(run.boxes, truth);
  r.frames = static_cast<long long>(run.boxes.size());
  r.scored = s.frames;
  r.auc = s.auc;
  r.precision20 = s.precision20;
  r.mean_iou = s.mean_iou;
  r.curves = otb_curves(run.boxes, truth);
  r.cpu_s = run.cpu_s;
  r.fps = run.cpu_s > 0 ? static_cast<double>(r.frames) / run.cpu_s
                        : std::numeric_limits<double>::infinity();
  const std::size_t n = std::min(run.boxes.size(), truth.size());
  for (std::size_t i = 0; i < run.boxes.size(); ++i) {
    if (run.lost[i]) ++r.lost;
  }
  for (std::size_t i = 0; i < n; ++i) {
    const cv::Rect2f& t = truth[i];
    if (!(std::isfinite(t.x) && std::isfinite(t.y) && t.width > 0 && t.height > 0)) continue;
    if (iou(run.boxes[i], t) > 0) continue;
    ++r.zero_iou;
    if (run.lost[i]) ++r.zero_iou_lost;
  }
  return r;
}

std::vector<BenchmarkRow> tracker_means(const std::vector<BenchmarkRow>& rows,
                                        const std::vector<std::string>& trackers) {
  std::vector<BenchmarkRow> means;
  std::set<std::string> first_sequences;
  for (const std::string& tracker : trackers) {
    BenchmarkRow m;
    m.sequence = "mean";
    m.tracker = tracker;
    m.sequences = 0;
    m.curves.success.assign(kSuccessThresholds, 0.0);
    m.curves.precision.assign(kPrecisionThresholds, 0.0);
    std::set<std::string> sequences;
    for (const BenchmarkRow& r : rows) {
      if (r.tracker != tracker) continue;
      sequences.insert(r.sequence);
      ++m.sequences;
      m.frames += r.frames;
      m.scored += r.scored;
      m.auc += r.auc;
      m.precision20 += r.precision20;
      m.mean_iou += r.mean_iou;
      m.cpu_s += r.cpu_s;
      m.lost += r.lost;
      m.zero_iou += r.zero_iou;
      m.zero_iou_lost += r.zero_iou_lost;
      m.curves.frames += r.curves.frames;
      for (std::size_t k = 0; k < m.curves.success.size() && k < r.curves.success.size(); ++k)
        m.curves.success[k] += r.curves.success[k];
      for (std::size_t k = 0; k < m.curves.precision.size() && k < r.curves.precision.size(); ++k)
        m.curves.precision[k] += r.curves.precision[k];
    }
    if (m.sequences == 0) throw Error("tracker '" + tracker + "' has no benchmark row");
    if (means.empty()) {
      first_sequences = sequences;
    } else if (sequences != first_sequences) {
      throw Error("tracker '" + tracker + "' ran on other sequences than '" +
                  means.front().tracker + "'");
    }
    const double n = m.sequences;
    m.auc /= n;
    m.precision20 /= n;
    m.mean_iou /= n;
    for (double& v : m.curves.success)
      v /= n;
    for (double& v : m.curves.precision)
      v /= n;
    m.fps = m.cpu_s > 0 ? static_cast<double>(m.frames) / m.cpu_s
                        : std::numeric_limits<double>::infinity();
    means.push_back(m);
  }
  return means;
}

std::string format_benchmark_markdown(const std::vector<BenchmarkRow>& rows,
                                      const std::vector<BenchmarkRow>& means) {
  std::string md = "Success AUC (OTB one-pass evaluation)\n\n| sequence |";
  std::string rule = "|---|";
  for (const BenchmarkRow& m : means) {
    append(md, {" ", md_cell(m.tracker), " |"});
    rule += "---:|";
  }
  md += "\n" + rule + "\n";
  std::vector<std::string> sequences;
  std::map<std::pair<std::string, std::string>, const BenchmarkRow*> by;
  for (const BenchmarkRow& r : rows) {
    if (std::find(sequences.begin(), sequences.end(), r.sequence) == sequences.end())
      sequences.push_back(r.sequence);
    by[{r.sequence, r.tracker}] = &r;
  }
  for (const std::string& s : sequences) {
    append(md, {"| ", md_cell(s), " |"});
    for (const BenchmarkRow& m : means) {
      const auto it = by.find({s, m.tracker});
      md += ' ';
      md += it == by.end() ? std::string("-") : fixed_or_nan(it->second->auc, 3);
      md += " |";
    }
    md += "\n";
  }
  md += "| **mean** |";
  for (const BenchmarkRow& m : means) {
    md += " **";
    md += fixed_or_nan(m.auc, 3);
    md += "** |";
  }
  md +=
      "\n\nAll figures. frames/s: frames over the CPU time of the tracker's calls (one thread, "
      "decoding excluded). lost at IoU 0: the share of the frames whose box misses the target "
      "entirely that the tracker reported lost.\n\n"
      "| sequence | tracker | frames | AUC | precision@20 | mean IoU | frames/s | lost frames | "
      "lost at IoU 0 |\n|---|---|---:|---:|---:|---:|---:|---:|---:|\n";
  const auto line = [&](const BenchmarkRow& r, bool bold) {
    const std::string b = bold ? "**" : "";
    append(md, {"| ",
                b,
                md_cell(r.sequence),
                b,
                " | ",
                md_cell(r.tracker),
                " | ",
                std::to_string(r.frames),
                " | ",
                b,
                fixed_or_nan(r.auc, 3),
                b,
                " | ",
                fixed_or_nan(r.precision20, 3),
                " | ",
                fixed_or_nan(r.mean_iou, 3),
                " | ",
                fixed_or_nan(r.fps, 1),
                " | ",
                std::to_string(r.lost),
                " | ",
                share_text(r),
                " |\n"});
  };
  for (const BenchmarkRow& r : rows)
    line(r, false);
  for (const BenchmarkRow& m : means)
    line(m, true);
  return md;
}

std::string format_benchmark_csv(const std::vector<BenchmarkRow>& rows,
                                 const std::vector<BenchmarkRow>& means) {
  std::string csv =
      "sequence,tracker,frames,scored,auc,precision20,mean_iou,fps,cpu_s,lost,zero_iou,"
      "zero_iou_lost,lost_share\n";
  const auto line = [&](const BenchmarkRow& r) {
    const double share = r.lost_share();
    csv += csv_field(r.sequence) + "," + csv_field(r.tracker) + "," + std::to_string(r.frames) +
           "," + std::to_string(r.scored) + "," + fixed_or_nan(r.auc, 4) + "," +
           fixed_or_nan(r.precision20, 4) + "," + fixed_or_nan(r.mean_iou, 4) + "," +
           fixed_or_nan(r.fps, 2) + "," + fixed_or_nan(r.cpu_s, 4) + "," + std::to_string(r.lost) +
           "," + std::to_string(r.zero_iou) + "," + std::to_string(r.zero_iou_lost) + "," +
           (std::isfinite(share) ? fixed(share, 4) : std::string()) + "\n";
  };
  for (const BenchmarkRow& r : rows)
    line(r);
  for (const BenchmarkRow& m : means)
    line(m);
  return csv;
}

}  // namespace roiflow::eval
