#include "stages/flow_eval.hpp"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <system_error>

#include "flow/error.hpp"
#include "flow/flo_io.hpp"

namespace roiflow::stages {
namespace {

namespace fs = std::filesystem;

bool is_file(const fs::path& path) {
  std::error_code ec;
  return fs::is_regular_file(path, ec);
}

std::string size_string(cv::Size size) {
  return std::to_string(size.width) + "x" + std::to_string(size.height);
}

void check_same_size(const std::string& name, const std::string& path_a, cv::Size a,
                     const std::string& path_b, cv::Size b) {
  if (a == b) return;
  throw Error("size mismatch in pair '" + name + "': '" + path_a + "' is " + size_string(a) +
              " but '" + path_b + "' is " + size_string(b));
}

std::string fixed(double value, int decimals) {
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, "%.*f", decimals, value);
  return buffer;
}

// Sequence names come from folder names, which may hold anything a CSV reader trips on.
std::string csv_field(const std::string& text) {
  if (text.find_first_of(",\"\r\n") == std::string::npos) return text;
  std::string quoted = "\"";
  for (char c : text) {
    if (c == '"') quoted += '"';
    quoted += c;
  }
  return quoted + '"';
}

nlohmann::ordered_json row_json(const EvalRow& row) {
  return {{"sequence", row.name}, {"aae_deg", row.errors.aae_deg}, {"epe", row.errors.epe},
          {"r1", row.errors.r1},  {"r3", row.errors.r3},           {"ms", row.ms}};
}

}  // namespace

cv::Mat read_gray(const std::string& path) {
  // Checked first because cv::imread would add a warning of its own on stderr.
  if (!is_file(path)) throw Error("cannot read image '" + path + "': no such file");
  cv::Mat image = cv::imread(path, cv::IMREAD_GRAYSCALE);
  if (image.empty()) throw Error("cannot decode image '" + path + "'");
  return image;
}

std::vector<EvalPair> find_middlebury(const std::string& dir) {
  std::error_code ec;
  if (!fs::exists(dir, ec)) throw Error("Middlebury directory '" + dir + "' does not exist");
  if (!fs::is_directory(dir, ec)) throw Error("'" + dir + "' is not a directory");

  std::vector<EvalPair> pairs;
  fs::directory_iterator it(dir, ec);
  if (ec) throw Error("cannot list '" + dir + "': " + ec.message());
  for (const fs::directory_entry& entry : it) {
    if (!entry.is_directory(ec)) continue;
    const fs::path seq = entry.path();
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
  std::sort(pairs.begin(), pairs.end(),
            [](const EvalPair& a, const EvalPair& b) { return a.name < b.name; });
  return pairs;
}

EvalRow evaluate_pair(const EvalPair& pair, const flow::LkParams& params,
                      const flow::Executor* executor) {
  const cv::Mat frame0 = read_gray(pair.frame0);
  const cv::Mat frame1 = read_gray(pair.frame1);
  const cv::Mat truth = flow::read_flo(pair.ground_truth);
  check_same_size(pair.name, pair.frame0, frame0.size(), pair.frame1, frame1.size());
  check_same_size(pair.name, pair.frame0, frame0.size(), pair.ground_truth, truth.size());
  cv::Mat exclude;
  if (!pair.exclude_mask.empty()) {
    exclude = read_gray(pair.exclude_mask);
    check_same_size(pair.name, pair.frame0, frame0.size(), pair.exclude_mask, exclude.size());
  }

  flow::FlowOptions options;
  options.executor = executor;
  const auto start = std::chrono::steady_clock::now();
  const flow::FlowResult result = flow::dense_flow(frame0, frame1, params, options);
  const auto stop = std::chrono::steady_clock::now();

  EvalRow row;
  row.name = pair.name;
  row.errors = flow::flow_errors(result.flow, truth, exclude);
  // All-zero errors over no pixel would pass for a perfect score.
  if (row.errors.pixels == 0) {
    throw Error("pair '" + pair.name + "' has no pixel to score: ground truth '" +
                pair.ground_truth + "' is unknown everywhere outside the exclude mask");
  }
  row.ms = std::chrono::duration<double, std::milli>(stop - start).count();
  return row;
}

EvalRow mean_row(const std::vector<EvalRow>& rows) {
  if (rows.empty()) throw Error("mean of no evaluation rows");
  EvalRow mean;
  mean.name = "mean";
  for (const EvalRow& row : rows) {
    mean.errors.aae_deg += row.errors.aae_deg;
    mean.errors.epe += row.errors.epe;
    mean.errors.r1 += row.errors.r1;
    mean.errors.r3 += row.errors.r3;
    mean.errors.pixels += row.errors.pixels;
    mean.ms += row.ms;
  }
  const double n = static_cast<double>(rows.size());
  mean.errors.aae_deg /= n;
  mean.errors.epe /= n;
  mean.errors.r1 /= n;
  mean.errors.r3 /= n;
  mean.ms /= n;
  return mean;
}

std::string format_table(const std::vector<EvalRow>& rows) {
  std::size_t name_width = std::string("sequence").size();
  for (const EvalRow& row : rows)
    name_width = std::max(name_width, row.name.size());

  char line[128];
  std::snprintf(line, sizeof line, " %10s %10s %8s %8s %10s\n", "AAE(deg)", "EPE(px)", "R1(%)",
                "R3(%)", "ms");
  std::string out = "sequence" + std::string(name_width - 8, ' ') + line;
  const auto append = [&](const EvalRow& row) {
    std::snprintf(line, sizeof line, " %10.3f %10.4f %8.2f %8.2f %10.2f\n", row.errors.aae_deg,
                  row.errors.epe, row.errors.r1, row.errors.r3, row.ms);
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
  std::string out = "sequence,aae_deg,epe,r1,r3,ms\n";
  const auto append = [&](const EvalRow& row) {
    out += csv_field(row.name) + ',' + fixed(row.errors.aae_deg, 3) + ',' +
           fixed(row.errors.epe, 4) + ',' + fixed(row.errors.r1, 2) + ',' +
           fixed(row.errors.r3, 2) + ',' + fixed(row.ms, 2) + '\n';
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
  doc["params"] = {{"patch", params.patch},
                   {"levels", params.levels},
                   {"iterations", params.iterations},
                   {"sigma", params.sigma},
                   {"derivative", flow::to_string(params.derivative)},
                   {"lambda", params.lambda},
                   {"robust_scale", params.robust_scale},
                   {"level_median", params.level_median},
                   {"final_median", params.final_median}};
  doc["rows"] = nlohmann::ordered_json::array();
  for (const EvalRow& row : rows)
    doc["rows"].push_back(row_json(row));
  doc["mean"] = rows.empty() ? nlohmann::ordered_json() : row_json(mean_row(rows));
  return doc.dump(2) + '\n';
}

}  // namespace roiflow::stages
