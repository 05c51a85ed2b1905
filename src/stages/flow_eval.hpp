// Flow evaluation against ground truth: Middlebury-style folders or explicit image pairs.
//
//   using namespace roiflow;
//   std::vector<stages::EvalRow> rows;
//   for (const auto& pair : stages::find_middlebury("data/middlebury"))
//     rows.push_back(stages::evaluate_pair(pair, flow::LkParams::paper()));
//   std::cout << stages::format_table(rows);   // one row per pair, then the mean
//
// Every pair is loaded as 8-bit gray, checked (all three sizes equal), run through
// flow::dense_flow (timed alone, file I/O excluded) and scored with flow::flow_errors.
// Missing or unreadable files, size mismatches and a pair with no pixel to score throw
// roiflow::Error naming the file, the sizes or the pair.
#pragma once

#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "flow/dense_lk.hpp"
#include "flow/executor.hpp"
#include "flow/metrics.hpp"

namespace roiflow::stages {

struct EvalPair {
  std::string name;
  std::string frame0;
  std::string frame1;
  std::string ground_truth;  // Middlebury .flo
  std::string exclude_mask;  // optional 8-bit image, non-zero = not scored; empty = none
};

struct EvalRow {
  std::string name;
  flow::FlowErrors errors;
  double ms = 0;  // dense_flow wall time, milliseconds
};

// Reads an image file as 8-bit gray (colour is converted). Throws roiflow::Error naming the
// file when it is missing or cannot be decoded.
cv::Mat read_gray(const std::string& path);

// Every DIR/<Seq>/ that holds frame10.png, frame11.png and flow10.flo, sorted by name. When
// DIR/<Seq>/gray/frame10.png and frame11.png exist they are used instead (the gray release).
// Throws roiflow::Error when DIR is missing, not a directory, or holds no such sequence.
std::vector<EvalPair> find_middlebury(const std::string& dir);

// `executor` runs dense_flow's row stripes; nullptr = serial.
EvalRow evaluate_pair(const EvalPair& pair, const flow::LkParams& params,
                      const flow::Executor* executor = nullptr);

// Named "mean": the mean of every metric and of ms over `rows`; `pixels` is their total.
// Throws roiflow::Error when `rows` is empty.
EvalRow mean_row(const std::vector<EvalRow>& rows);

// All three write the rows in order, then the mean row (when there are rows).
// Aligned columns: sequence, AAE(deg), EPE(px), R1(%), R3(%), ms.
std::string format_table(const std::vector<EvalRow>& rows);
// Header `sequence,aae_deg,epe,r1,r3,ms`; aae 3 decimals, epe 4, r1/r3/ms 2.
std::string format_csv(const std::vector<EvalRow>& rows);
// {"preset", "params": {...}, "rows": [{"sequence", "aae_deg", "epe", "r1", "r3", "ms"}],
//  "mean": {...} or null}, indented by 2.
std::string format_json(const std::vector<EvalRow>& rows, const std::string& preset,
                        const flow::LkParams& params);

}  // namespace roiflow::stages
