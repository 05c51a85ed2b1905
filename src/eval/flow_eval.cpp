#include "eval/flow_eval.hpp"

#include <algorithm>
#include <cctype>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <system_error>

#include "core/error.hpp"
#include "core/text.hpp"
#include "eval/flo_io.hpp"
#include "eval/kitti_flow.hpp"

namespace roiflow::eval {
namespace {

namespace fs = std::filesystem;

bool is_file(const fs::path& path) {
  std::error_code ec;
  return fs::is_regular_file(path, ec);
}

bool is_dir(const fs::path& path) {
  std::error_code ec;
  return fs::is_directory(path, ec);
}

void check_dir(const std::string& dir, const std::string& what) {
  std::error_code ec;
  if (!fs::exists(dir, ec)) throw Error(what + " directory '" + dir + "' does not exist");
  if (!fs::is_directory(dir, ec)) throw Error("'" + dir + "' is not a directory");
}

// Entries of `dir` (not recursive), sorted by name, so that pair order never depends on the
// file system.
std::vector<fs::path> sorted_entries(const fs::path& dir) {
  std::error_code ec;
  fs::directory_iterator it(dir, ec);
  if (ec) throw Error("cannot list '" + dir.string() + "': " + ec.message());
  std::vector<fs::path> entries;
  for (const fs::directory_entry& entry : it)
    entries.push_back(entry.path());
  std::sort(entries.begin(), entries.end());
  return entries;
}

// Sintel and KITTI archives unpack to a folder with training/ (and testing/, no ground truth).
fs::path benchmark_root(const std::string& dir, const char* marker) {
  const fs::path root(dir);
  if (!is_dir(root / marker) && is_dir(root / "training" / marker)) return root / "training";
  return root;
}

bool is_sintel_root(const fs::path& root) {
  return is_dir(root / "flow") &&
         (is_dir(root / "clean") || is_dir(root / "final") || is_dir(root / "albedo"));
}

bool is_kitti_root(const fs::path& root) {
  return (is_dir(root / "image_0") || is_dir(root / "image_2")) &&
         (is_dir(root / "flow_occ") || is_dir(root / "flow_noc"));
}

// "frame_0007.flo" -> 7; -1 when the name is not frame_<digits>.flo.
int sintel_frame_number(const std::string& filename) {
  const std::string prefix = "frame_";
  const std::string suffix = ".flo";
  if (filename.size() <= prefix.size() + suffix.size() || filename.rfind(prefix, 0) != 0 ||
      filename.compare(filename.size() - suffix.size(), suffix.size(), suffix) != 0) {
    return -1;
  }
  const std::string digits =
      filename.substr(prefix.size(), filename.size() - prefix.size() - suffix.size());
  if (digits.size() > 6 ||
      !std::all_of(digits.begin(), digits.end(), [](unsigned char c) { return std::isdigit(c); })) {
    return -1;
  }
  return std::stoi(digits);
}

std::string sintel_frame_name(int number) {
  char name[32];
  std::snprintf(name, sizeof name, "frame_%04d", number);
  return name;
}

std::string scene_of(const EvalPair& pair) {
  return pair.name.substr(0, pair.name.find_first_of("/ "));
}

bool has_extension(const std::string& path, const std::string& extension) {
  std::string ext = fs::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return ext == extension;
}

// Any non-zero pixel of either mask; either may be empty.
cv::Mat mask_union(const cv::Mat& a, const cv::Mat& b) {
  if (a.empty()) return b;
  if (b.empty()) return a;
  return a | b;
}

void check_same_size(const std::string& name, const std::string& path_a, cv::Size a,
                     const std::string& path_b, cv::Size b) {
  if (a == b) return;
  throw Error("size mismatch in pair '" + name + "': '" + path_a + "' is " + size_text(a) +
              " but '" + path_b + "' is " + size_text(b));
}

nlohmann::ordered_json errors_json(const flow::FlowErrors& e) {
  return {{"aae_deg", e.aae_deg}, {"epe", e.epe}, {"r1", e.r1},
          {"r3", e.r3},           {"fl", e.fl},   {"pixels", e.pixels}};
}

nlohmann::ordered_json row_json(const EvalRow& row) {
  nlohmann::ordered_json json = {{"sequence", row.name}};
  json.update(errors_json(row.errors));
  json["ms"] = row.ms;
  if (row.noc) json["noc"] = errors_json(*row.noc);
  return json;
}

bool extended(const std::vector<EvalRow>& rows) {
  return std::any_of(rows.begin(), rows.end(),
                     [](const EvalRow& row) { return row.noc.has_value() || row.kitti; });
}

void add_errors(flow::FlowErrors& sum, const flow::FlowErrors& e) {
  sum.aae_deg += e.aae_deg;
  sum.epe += e.epe;
  sum.r1 += e.r1;
  sum.r3 += e.r3;
  sum.fl += e.fl;
  sum.pixels += e.pixels;
}

void divide_errors(flow::FlowErrors& sum, double n) {
  sum.aae_deg /= n;
  sum.epe /= n;
  sum.r1 /= n;
  sum.r3 /= n;
  sum.fl /= n;
}

}  // namespace

cv::Mat read_gray(const std::string& path) {
  // Checked first because cv::imread would add a warning of its own on stderr.
  if (!is_file(path)) throw Error("cannot read image '" + path + "': no such file");
  cv::Mat image = cv::imread(path, cv::IMREAD_GRAYSCALE);
  if (image.empty()) throw Error("cannot decode image '" + path + "'");
  return image;
}

cv::Mat read_flow_ground_truth(const std::string& path) {
  return has_extension(path, ".png") ? read_kitti_flow(path) : eval::read_flo(path);
}

const char* to_string(Layout layout) {
  switch (layout) {
    case Layout::Auto:
      return "auto";
    case Layout::Middlebury:
      return "middlebury";
    case Layout::Sintel:
      return "sintel";
    case Layout::Kitti:
      return "kitti";
  }
  return "?";
}

Layout parse_layout(const std::string& name) {
  for (Layout layout : {Layout::Auto, Layout::Middlebury, Layout::Sintel, Layout::Kitti}) {
    if (name == to_string(layout)) return layout;
  }
  throw Error("unknown evaluation layout '" + name + "' (auto, middlebury, sintel or kitti)");
}

std::vector<EvalPair> find_middlebury(const std::string& dir) {
  check_dir(dir, "Middlebury");
  std::vector<EvalPair> pairs;
  for (const fs::path& seq : sorted_entries(dir)) {
    if (!is_dir(seq)) continue;
    const fs::path flo = seq / "flow10.flo";
    if (!is_file(seq / "frame10.png") || !is_file(seq / "frame11.png") || !is_file(flo)) continue;
    const fs::path gray = seq / "gray";
    const bool use_gray = is_file(gray / "frame10.png") && is_file(gray / "frame11.png");
    const fs::path frames = use_gray ? gray : seq;
    pairs.push_back({seq.filename().string(), (frames / "frame10.png").string(),
                     (frames / "frame11.png").string(), flo.string(), ""});
  }
  if (pairs.empty()) {
    throw Error("no Middlebury sequence in '" + dir +
                "' (expected <dir>/<sequence>/ with frame10.png, frame11.png and flow10.flo)");
  }
  return pairs;
}

namespace {

// Where find_* put what they left out: a list when the caller accepts partial trees, else
// nothing (the first gap is an error, as it always was).
class Gaps {
 public:
  explicit Gaps(std::vector<std::string>* skipped) : skipped_(skipped) {}
  // `what` is left out because of `why`; throws `context` + `why` when partial trees are not
  // accepted.
  void skip(const std::string& what, const std::string& context, const std::string& why) const {
    if (!skipped_) throw Error(context + why);
    skipped_->push_back(what + " (" + why + ")");
  }
  bool partial() const { return skipped_ != nullptr; }

 private:
  std::vector<std::string>* skipped_;
};

bool valid_pass_name(const std::string& pass) {
  return !pass.empty() && pass.find_first_of("/\\") == std::string::npos && pass != "." &&
         pass != "..";
}

// The pass a Sintel scene is read from: `pass` itself, or for "auto" the first of clean,
// final, albedo that has the scene's folder. Empty when the scene has none.
std::string scene_pass(const fs::path& root, const std::string& scene, const std::string& pass) {
  if (pass != "auto") return is_dir(root / pass / scene) ? pass : std::string();
  for (const char* candidate : {"clean", "final", "albedo"}) {
    if (is_dir(root / candidate / scene)) return candidate;
  }
  return {};
}

// The pairs of one Sintel scene read from `pass`; gaps are skipped or thrown through `gaps`.
void sintel_scene_pairs(const fs::path& root, const fs::path& scene_dir, const std::string& pass,
                        const Gaps& gaps, std::vector<EvalPair>& pairs) {
  const std::string scene = scene_dir.filename().string();
  const fs::path occlusions = root / "occlusions" / scene;
  const fs::path invalid = root / "invalid" / scene;
  for (const fs::path& flo : sorted_entries(scene_dir)) {
    const int number = sintel_frame_number(flo.filename().string());
    if (number < 0 || !is_file(flo)) continue;
    const std::string frame = sintel_frame_name(number);
    const std::string name = scene + "/" + frame;
    EvalPair pair;
    // The pass is part of the name: rows of one tree may come from different passes.
    pair.name = name + " (" + pass + ")";
    pair.frame0 = (root / pass / scene / (frame + ".png")).string();
    pair.frame1 = (root / pass / scene / (sintel_frame_name(number + 1) + ".png")).string();
    pair.ground_truth = flo.string();
    const std::string context = "Sintel pair '" + name + "': ";
    bool complete = true;
    for (const std::string* file : {&pair.frame0, &pair.frame1}) {
      if (complete && !is_file(*file)) {
        gaps.skip("Sintel pair " + name, context, "missing file '" + *file + "'");
        complete = false;
      }
    }
    if (complete && is_dir(invalid)) {
      // Without its invalid mask a pair would score pixels that have no true flow.
      pair.exclude_mask = (invalid / (frame + ".png")).string();
      if (!is_file(pair.exclude_mask)) {
        gaps.skip("Sintel pair " + name, context, "missing file '" + pair.exclude_mask + "'");
        complete = false;
      }
    }
    if (!complete) continue;
    if (is_dir(occlusions)) {
      const std::string mask = (occlusions / (frame + ".png")).string();
      if (is_file(mask)) {
        pair.occlusion_mask = mask;
      } else {
        gaps.skip("the non-occluded figures of Sintel pair " + name, context,
                  "missing file '" + mask + "'");
      }
    }
    pairs.push_back(std::move(pair));
  }
}

}  // namespace

std::vector<EvalPair> find_sintel(const std::string& dir, const std::string& pass,
                                  std::vector<std::string>* skipped) {
  check_dir(dir, "Sintel");
  const fs::path root = benchmark_root(dir, "flow");
  if (!is_dir(root / "flow")) {
    throw Error("no Sintel tree in '" + dir + "' (expected flow/<scene>/frame_NNNN.flo)");
  }
  if (!valid_pass_name(pass)) {
    throw Error("Sintel pass must be auto or a folder name such as clean or final, got '" + pass +
                "'");
  }
  if (pass != "auto" && !is_dir(root / pass)) {
    throw Error("Sintel tree '" + root.string() + "' has no '" + pass + "' pass (no folder '" +
                (root / pass).string() + "')");
  }
  const Gaps gaps(skipped);
  std::vector<EvalPair> pairs;
  for (const fs::path& scene_dir : sorted_entries(root / "flow")) {
    if (!is_dir(scene_dir)) continue;
    const std::string scene = scene_dir.filename().string();
    const std::string chosen = scene_pass(root, scene, pass);
    if (chosen.empty()) {
      // Strict: the first missing frame names the file, as it always did.
      if (!gaps.partial()) {
        sintel_scene_pairs(root, scene_dir, pass == "auto" ? "clean" : pass, gaps, pairs);
        continue;
      }
      gaps.skip("Sintel scene " + scene, "",
                pass == "auto" ? "no clean/, final/ or albedo/ folder of the scene"
                               : "no " + pass + "/" + scene + "/ folder");
      continue;
    }
    sintel_scene_pairs(root, scene_dir, chosen, gaps, pairs);
  }
  if (pairs.empty() && skipped && !skipped->empty()) {
    throw Error("no Sintel pair to evaluate in '" + dir + "': " + skipped_line(*skipped));
  }
  if (pairs.empty()) {
    throw Error("no Sintel pair in '" + dir + "' (expected flow/<scene>/frame_NNNN.flo)");
  }
  return pairs;
}

std::vector<EvalPair> find_kitti(const std::string& dir, std::vector<std::string>* skipped) {
  check_dir(dir, "KITTI");
  const fs::path root = benchmark_root(dir, "flow_occ");
  if (!is_dir(root / "flow_occ")) {
    throw Error("no KITTI ground truth in '" + dir + "' (expected flow_occ/NNNNNN_10.png)");
  }
  // KITTI 2012 has gray image_0/, KITTI 2015 colour image_2/.
  const fs::path images = is_dir(root / "image_0") ? root / "image_0" : root / "image_2";
  if (!is_dir(images)) {
    throw Error("KITTI tree '" + root.string() +
                "' has flow_occ/ but neither image_0/ nor image_2/");
  }
  const Gaps gaps(skipped);
  const fs::path noc = root / "flow_noc";
  const std::string suffix = "_10.png";
  const auto is_truth = [&](const fs::path& file) {
    const std::string filename = file.filename().string();
    return filename.size() > suffix.size() &&
           filename.compare(filename.size() - suffix.size(), suffix.size(), suffix) == 0 &&
           is_file(file);
  };
  std::vector<EvalPair> pairs;
  for (const fs::path& truth : sorted_entries(root / "flow_occ")) {
    if (!is_truth(truth)) continue;
    const std::string filename = truth.filename().string();
    const std::string id = filename.substr(0, filename.size() - suffix.size());
    EvalPair pair;
    pair.name = id;
    pair.frame0 = (images / (id + "_10.png")).string();
    pair.frame1 = (images / (id + "_11.png")).string();
    pair.ground_truth = truth.string();
    const std::string context = "KITTI pair '" + id + "': ";
    if (!is_file(pair.frame0) || !is_file(pair.frame1)) {
      gaps.skip("KITTI pair " + id, context,
                "missing file '" + (is_file(pair.frame0) ? pair.frame1 : pair.frame0) + "'");
      continue;
    }
    if (is_dir(noc)) {
      const std::string noc_truth = (noc / filename).string();
      if (is_file(noc_truth)) {
        pair.noc_ground_truth = noc_truth;
      } else {
        gaps.skip("the non-occluded figures of KITTI pair " + id, context,
                  "missing file '" + noc_truth + "'");
      }
    }
    pairs.push_back(std::move(pair));
  }
  if (is_dir(noc) && gaps.partial()) {
    // Pairs with only the non-occluded truth are not scored as if it were all of it.
    for (const fs::path& truth : sorted_entries(noc)) {
      if (is_truth(truth) && !is_file(root / "flow_occ" / truth.filename())) {
        const std::string name = truth.filename().string();
        gaps.skip("KITTI pair " + name.substr(0, name.size() - suffix.size()), "",
                  "flow_noc/" + name + " without flow_occ/" + name);
      }
    }
  }
  if (pairs.empty() && skipped && !skipped->empty()) {
    throw Error("no KITTI pair to evaluate in '" + dir + "': " + skipped_line(*skipped));
  }
  if (pairs.empty()) {
    throw Error("no KITTI pair in '" + dir + "' (expected flow_occ/NNNNNN_10.png)");
  }
  return pairs;
}

std::string skipped_line(const std::vector<std::string>& skipped) {
  if (skipped.empty()) return {};
  std::string line = "skipped " + std::to_string(skipped.size()) + ": ";
  for (std::size_t i = 0; i < skipped.size(); ++i)
    line += (i ? "; " : "") + skipped[i];
  return line;
}

Layout detect_layout(const std::string& dir) {
  check_dir(dir, "evaluation");
  if (is_sintel_root(dir) || is_sintel_root(fs::path(dir) / "training")) return Layout::Sintel;
  if (is_kitti_root(dir) || is_kitti_root(fs::path(dir) / "training")) return Layout::Kitti;
  for (const fs::path& seq : sorted_entries(dir)) {
    if (is_file(seq / "flow10.flo")) return Layout::Middlebury;
  }
  throw Error("'" + dir +
              "' holds no Middlebury, Sintel or KITTI layout (expected <sequence>/flow10.flo, "
              "or flow/ with clean/ or final/, or image_0/ or image_2/ with flow_occ/)");
}

std::vector<EvalPair> find_pairs(const std::string& dir, const FindOptions& options,
                                 std::vector<std::string>* skipped) {
  if (options.max_pairs < 0) {
    throw Error("max pairs must be >= 0 (0 = all), got " + std::to_string(options.max_pairs));
  }
  const Layout layout = options.layout == Layout::Auto ? detect_layout(dir) : options.layout;
  std::vector<EvalPair> pairs;
  switch (layout) {
    case Layout::Sintel:
      pairs = find_sintel(dir, options.pass, skipped);
      break;
    case Layout::Kitti:
      pairs = find_kitti(dir, skipped);
      break;
    case Layout::Auto:
    case Layout::Middlebury:
      pairs = find_middlebury(dir);
      break;
  }
  if (!options.scene.empty()) {
    std::vector<EvalPair> kept;
    for (const EvalPair& pair : pairs) {
      if (scene_of(pair) == options.scene) kept.push_back(pair);
    }
    if (kept.empty()) {
      // Pairs are sorted, so the pairs of a scene are consecutive.
      std::string scenes;
      std::string last;
      for (const EvalPair& pair : pairs) {
        const std::string scene = scene_of(pair);
        if (scene == last) continue;
        if (scenes.size() > 200) {
          scenes += ", ...";
          break;
        }
        scenes += (last.empty() ? "" : ", ") + scene;
        last = scene;
      }
      throw Error("no scene '" + options.scene + "' in '" + dir + "' (" + to_string(layout) +
                  " scenes: " + scenes + ")");
    }
    pairs = std::move(kept);
  }
  const std::size_t max = static_cast<std::size_t>(options.max_pairs);
  if (max > 0 && pairs.size() > max) {
    // Evenly spaced rather than the first N, which would all come from the first scene.
    std::vector<EvalPair> kept;
    for (std::size_t i = 0; i < max; ++i)
      kept.push_back(pairs[i * pairs.size() / max]);
    pairs = std::move(kept);
  }
  return pairs;
}

EvalRow evaluate_pair(const EvalPair& pair, const flow::LkParams& params, const Executor* executor,
                      EvalImages* images) {
  const cv::Mat frame0 = read_gray(pair.frame0);
  const cv::Mat frame1 = read_gray(pair.frame1);
  const cv::Mat truth = read_flow_ground_truth(pair.ground_truth);
  check_same_size(pair.name, pair.frame0, frame0.size(), pair.frame1, frame1.size());
  check_same_size(pair.name, pair.frame0, frame0.size(), pair.ground_truth, truth.size());
  const auto optional_mask = [&](const std::string& path) {
    if (path.empty()) return cv::Mat();
    cv::Mat mask = read_gray(path);
    check_same_size(pair.name, pair.frame0, frame0.size(), path, mask.size());
    return mask;
  };
  const cv::Mat exclude = optional_mask(pair.exclude_mask);
  const cv::Mat occluded = optional_mask(pair.occlusion_mask);
  cv::Mat noc_truth;
  if (!pair.noc_ground_truth.empty()) {
    noc_truth = read_flow_ground_truth(pair.noc_ground_truth);
    check_same_size(pair.name, pair.frame0, frame0.size(), pair.noc_ground_truth, noc_truth.size());
  }

  // The workspace is allocated before the clock starts: `ms` is the flow's time, as in a video
  // loop that keeps its DenseLK.
  flow::DenseLK lk(params, executor);
  lk.reserve(frame0.size());
  const auto start = std::chrono::steady_clock::now();
  const flow::FlowResult result = lk.calc(frame0, frame1);
  const auto stop = std::chrono::steady_clock::now();

  EvalRow row;
  row.name = pair.name;
  row.errors = flow::flow_errors(result.flow, truth, exclude);
  // All-zero errors over no pixel would pass for a perfect score.
  if (row.errors.pixels == 0) {
    throw Error("pair '" + pair.name + "' has no pixel to score: ground truth '" +
                pair.ground_truth + "' is unknown everywhere outside the exclude mask");
  }
  if (!occluded.empty() || !noc_truth.empty()) {
    const flow::FlowErrors noc = flow::flow_errors(
        result.flow, noc_truth.empty() ? truth : noc_truth, mask_union(exclude, occluded));
    // A pair occluded everywhere has no noc figures rather than perfect ones.
    if (noc.pixels > 0) row.noc = noc;
  }
  row.kitti = has_extension(pair.ground_truth, ".png");
  row.ms = std::chrono::duration<double, std::milli>(stop - start).count();
  if (images) {
    images->frame0 = frame0;
    images->frame1 = frame1;
    images->truth = truth;
    images->estimate = result.flow;
    images->scored = cv::Mat(truth.size(), CV_8UC1);
    for (int y = 0; y < truth.rows; ++y) {
      const float* gt = truth.ptr<float>(y);
      const uchar* ex = exclude.empty() ? nullptr : exclude.ptr<uchar>(y);
      uchar* out = images->scored.ptr<uchar>(y);
      for (int x = 0; x < truth.cols; ++x)
        out[x] = (ex && ex[x]) || !flow::is_known_flow(gt[2 * x], gt[2 * x + 1]) ? 0 : 255;
    }
  }
  return row;
}

EvalRow mean_row(const std::vector<EvalRow>& rows) {
  if (rows.empty()) throw Error("mean of no evaluation rows");
  EvalRow mean;
  mean.name = "mean";
  flow::FlowErrors noc;
  int noc_rows = 0;
  for (const EvalRow& row : rows) {
    add_errors(mean.errors, row.errors);
    if (row.noc) {
      add_errors(noc, *row.noc);
      ++noc_rows;
    }
    mean.kitti = mean.kitti || row.kitti;
    mean.ms += row.ms;
  }
  divide_errors(mean.errors, static_cast<double>(rows.size()));
  mean.ms /= static_cast<double>(rows.size());
  if (noc_rows > 0) {
    divide_errors(noc, noc_rows);
    mean.noc = noc;
  }
  return mean;
}

std::string format_table(const std::vector<EvalRow>& rows) {
  std::size_t name_width = std::string("sequence").size();
  for (const EvalRow& row : rows)
    name_width = std::max(name_width, row.name.size());

  const bool wide = extended(rows);
  char line[160];
  char extra[80] = "";
  if (wide) std::snprintf(extra, sizeof extra, " %8s %10s %10s", "Fl(%)", "EPE-noc", "Fl-noc(%)");
  std::snprintf(line, sizeof line, " %10s %10s %8s %8s%s %10s\n", "AAE(deg)", "EPE(px)", "R1(%)",
                "R3(%)", extra, "ms");
  std::string out = "sequence" + std::string(name_width - 8, ' ') + line;
  const auto append = [&](const EvalRow& row) {
    if (wide && row.noc) {
      std::snprintf(extra, sizeof extra, " %8.2f %10.4f %10.2f", row.errors.fl, row.noc->epe,
                    row.noc->fl);
    } else if (wide) {
      std::snprintf(extra, sizeof extra, " %8.2f %10s %10s", row.errors.fl, "-", "-");
    }
    std::snprintf(line, sizeof line, " %10.3f %10.4f %8.2f %8.2f%s %10.2f\n", row.errors.aae_deg,
                  row.errors.epe, row.errors.r1, row.errors.r3, extra, row.ms);
    out += row.name + std::string(name_width - row.name.size(), ' ') + line;
  };
  for (const EvalRow& row : rows)
    append(row);
  if (!rows.empty()) {
    out += std::string(out.find('\n'), '-') + '\n';
    append(mean_row(rows));
  }
  return out;
}

std::string format_csv(const std::vector<EvalRow>& rows) {
  const bool wide = extended(rows);
  std::string out = "sequence,aae_deg,epe,r1,r3,ms";
  out += wide ? ",fl,aae_deg_noc,epe_noc,r1_noc,r3_noc,fl_noc\n" : "\n";
  const auto append = [&](const EvalRow& row) {
    out += csv_field(row.name) + ',' + fixed(row.errors.aae_deg, 3) + ',' +
           fixed(row.errors.epe, 4) + ',' + fixed(row.errors.r1, 2) + ',' +
           fixed(row.errors.r3, 2) + ',' + fixed(row.ms, 2);
    if (wide) {
      out += ',' + fixed(row.errors.fl, 2);
      if (row.noc) {
        out += ',' + fixed(row.noc->aae_deg, 3) + ',' + fixed(row.noc->epe, 4) + ',' +
               fixed(row.noc->r1, 2) + ',' + fixed(row.noc->r3, 2) + ',' + fixed(row.noc->fl, 2);
      } else {
        out += ",,,,,";
      }
    }
    out += '\n';
  };
  for (const EvalRow& row : rows)
    append(row);
  if (!rows.empty()) append(mean_row(rows));
  return out;
}

std::string format_json(const std::vector<EvalRow>& rows, const std::string& preset,
                        const flow::LkParams& params) {
  nlohmann::ordered_json doc;
  doc["preset"] = preset;
  doc["params"] = params_json(params);
  doc["rows"] = nlohmann::ordered_json::array();
  for (const EvalRow& row : rows)
    doc["rows"].push_back(row_json(row));
  doc["mean"] = rows.empty() ? nlohmann::ordered_json() : row_json(mean_row(rows));
  return doc.dump(2) + '\n';
}

nlohmann::ordered_json params_json(const flow::LkParams& params) {
  return {{"patch", params.patch},
          {"levels", params.levels},
          {"iterations", params.iterations},
          {"finest_iterations", params.finest_iterations},
          {"sigma", params.sigma},
          {"derivative", flow::to_string(params.derivative)},
          {"lambda", params.lambda},
          {"robust_scale", params.robust_scale},
          {"level_median", params.level_median},
          {"final_median", params.final_median},
          {"expected_motion", params.expected_motion},
          {"coarsest_side", params.coarsest_side},
          {"search_radius", params.search_radius},
          {"fuse_far_step", params.fuse_far_step},
          {"fuse_far_finest_level", params.fuse_far_finest_level},
          {"fuse_step", params.fuse_step},
          {"fuse_finest_level", params.fuse_finest_level},
          {"mask_outside", params.mask_outside},
          {"finest_level", params.finest_level}};
}

}  // namespace roiflow::eval
