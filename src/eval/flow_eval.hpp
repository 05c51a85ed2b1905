// Flow evaluation against ground truth over Middlebury, MPI-Sintel and KITTI trees or explicit
// pairs: every pair is loaded as 8-bit gray, checked, run through dense LK (timed alone, file
// I/O excluded) and scored with flow::flow_errors over all scored pixels and, where the dataset
// marks occlusions (Sintel masks, KITTI flow_noc), over the non-occluded ones; then the rows are
// formatted as a table, CSV or JSON. Missing files, size mismatches, broken trees and pairs with
// nothing to score throw roiflow::Error naming the file or pair.
//
//   roiflow::eval::FindOptions find;
//   find.max_pairs = 20;
//   std::vector<roiflow::eval::EvalRow> rows;
//   for (const auto& pair : roiflow::eval::find_pairs("data/sintel/training", find))
//     rows.push_back(roiflow::eval::evaluate_pair(pair, roiflow::flow::LkParams::paper()));
//   std::cout << roiflow::eval::format_table(rows);  // one row per pair, then the mean
#pragma once

#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>
#include <optional>
#include <string>
#include <vector>

#include "core/executor.hpp"
#include "flow/dense_lk.hpp"
#include "flow/metrics.hpp"

namespace roiflow::eval {

struct EvalPair {
  std::string name;  // "Venus", "alley_1/frame_0001" (scene/frame), "000042"
  std::string frame0;
  std::string frame1;
  std::string ground_truth;  // Middlebury .flo, or a KITTI 16-bit .png (chosen by extension)
  std::string exclude_mask;  // optional 8-bit image, non-zero = not scored; empty = none
  // Optional 8-bit image, non-zero = occluded: scored in the "all" figures, not in "noc".
  // (Default-initialised, like the next one, so that {name, a, b, gt, mask} stays warning-free.)
  std::string occlusion_mask = {};
  // Optional ground truth of the non-occluded pixels only (KITTI flow_noc), same formats.
  std::string noc_ground_truth = {};
};

struct EvalRow {
  std::string name;
  flow::FlowErrors errors;                   // every scored pixel
  std::optional<flow::FlowErrors> noc = {};  // non-occluded pixels, when the pair tells which
  bool kitti = false;  // KITTI ground truth: the outputs show Fl, KITTI's own metric
  double ms = 0;       // dense_flow wall time, milliseconds
};

// What evaluate_pair read and computed, for a report (html_report.hpp).
struct EvalImages {
  cv::Mat frame0, frame1;  // CV_8UC1
  cv::Mat truth;           // CV_32FC2, unknown (|u| > 1e9) where there is no ground truth
  cv::Mat estimate;        // CV_32FC2
  cv::Mat scored;          // CV_8UC1, 255 where the pixel counts in EvalRow::errors
};

enum class Layout { Auto, Middlebury, Sintel, Kitti };
// "auto", "middlebury", "sintel", "kitti"; parse_layout throws roiflow::Error on anything else.
const char* to_string(Layout layout);
Layout parse_layout(const std::string& name);

struct FindOptions {
  Layout layout = Layout::Auto;
  // Sintel rendering pass: a folder next to flow/ (clean, final), or "auto": per scene, the
  // first of clean, final, albedo that the tree has.
  std::string pass = "auto";
  std::string scene;  // keep only this scene ("alley_1", "Venus", "000042"); "" = all
  int max_pairs = 0;  // > 0: at most this many pairs, evenly spaced over the sorted list
};

// Reads an image file as 8-bit gray (colour is converted). Throws roiflow::Error naming the
// file when it is missing or cannot be decoded.
cv::Mat read_gray(const std::string& path);
// A .png is KITTI 16-bit flow (kitti_flow.hpp, invalid pixels unknown), anything else .flo.
cv::Mat read_flow_ground_truth(const std::string& path);

// Every DIR/<Seq>/ that holds frame10.png, frame11.png and flow10.flo, sorted by name. When
// DIR/<Seq>/gray/frame10.png and frame11.png exist they are used instead (the gray release).
// Throws roiflow::Error when DIR is missing, not a directory, or holds no such sequence.
std::vector<EvalPair> find_middlebury(const std::string& dir);

// Partial trees. The finders below take `skipped`: when it is null a tree must be complete
// (every gap throws roiflow::Error naming the missing file); when it is given, what is there is
// evaluated and every part left out is appended to it as "what (why)", e.g.
// "the non-occluded figures of KITTI pair 000000 (... missing file '.../flow_noc/000000_10.png')".
// A tree where nothing is left to evaluate throws either way. skipped_line() makes the one line
// a caller prints about them ("" when nothing was skipped).

// MPI-Sintel: DIR (or DIR/training) holds flow/<scene>/frame_NNNN.flo and
// <pass>/<scene>/frame_NNNN.png; each .flo is the pair (NNNN, NNNN+1). When
// occlusions/<scene>/ and invalid/<scene>/ exist, frame_NNNN.png there is the pair's occlusion
// mask and exclude mask. `pass` "auto" reads each scene from the first of clean/, final/,
// albedo/ that has it (partial downloads ship one pass per scene); the pass read is part of
// each pair's name: "alley_1/frame_0001 (clean)". Sorted by scene, then frame. Throws
// roiflow::Error when a named pass folder is missing or there is no pair at all; partial: a
// scene without the pass and a pair without a frame or invalid mask are skipped, a pair without
// its occlusion mask loses its non-occluded figures.
std::vector<EvalPair> find_sintel(const std::string& dir, const std::string& pass = "auto",
                                  std::vector<std::string>* skipped = nullptr);

// KITTI 2012 (image_0/) or 2015 (image_2/): DIR (or DIR/training) holds
// image_N/NNNNNN_10.png, NNNNNN_11.png and flow_occ/NNNNNN_10.png (all pixels); when flow_noc/
// exists, flow_noc/NNNNNN_10.png is the non-occluded ground truth. Sorted by name. Throws
// roiflow::Error when flow_occ/ is missing or there is no pair at all; partial: a pair without a
// frame is skipped, a pair without its flow_noc file loses its non-occluded figures, and a
// flow_noc file without flow_occ is reported, not scored.
std::vector<EvalPair> find_kitti(const std::string& dir,
                                 std::vector<std::string>* skipped = nullptr);

// Which layout DIR holds: Sintel (flow/ with clean/ or final/), KITTI (image_0/ or image_2/
// with flow_occ/ or flow_noc/), each possibly under DIR/training, else Middlebury (a
// sub-folder with flow10.flo). Throws roiflow::Error naming DIR when it is none of them.
Layout detect_layout(const std::string& dir);

// The pairs of DIR in options.layout (Auto: detect_layout), filtered by scene, then thinned to
// max_pairs; `skipped` as above. Throws roiflow::Error for an unknown scene or a negative
// max_pairs.
std::vector<EvalPair> find_pairs(const std::string& dir, const FindOptions& options = {},
                                 std::vector<std::string>* skipped = nullptr);

// "skipped N: a (why); b (why)", or "" when `skipped` is empty.
std::string skipped_line(const std::vector<std::string>& skipped);

// `executor` runs dense_flow's row stripes; nullptr = serial. `images`, when given, receives
// the frames, ground truth, estimate and scored mask.
EvalRow evaluate_pair(const EvalPair& pair, const flow::LkParams& params,
                      const Executor* executor = nullptr, EvalImages* images = nullptr);

// Named "mean": the mean of every metric and of ms over `rows`; `pixels` is their total. The
// non-occluded figures are the mean over the rows that have them (none: no noc). Throws
// roiflow::Error when `rows` is empty.
EvalRow mean_row(const std::vector<EvalRow>& rows);

// All three write the rows in order, then the mean row (when there are rows).
// "Extended" output, when any row has noc figures or KITTI ground truth, adds Fl (%) and the
// non-occluded figures; otherwise the output is exactly the Middlebury one.
// Aligned columns: sequence, AAE(deg), EPE(px), R1(%), R3(%), [Fl(%), EPE-noc, Fl-noc(%),] ms;
// "-" where a row has no noc figures.
std::string format_table(const std::vector<EvalRow>& rows);
// Header `sequence,aae_deg,epe,r1,r3,ms`; aae 3 decimals, epe 4, r1/r3/ms 2. Extended output
// appends `fl,aae_deg_noc,epe_noc,r1_noc,r3_noc,fl_noc` (same decimals; empty fields where a
// row has no noc figures), so the first six columns stay where scripts expect them.
std::string format_csv(const std::vector<EvalRow>& rows);
// {"preset", "params": {...}, "rows": [{"sequence", "aae_deg", "epe", "r1", "r3", "fl",
//  "pixels", "ms", "noc": {"aae_deg", "epe", "r1", "r3", "fl", "pixels"} when present}],
//  "mean": {...} or null}, indented by 2.
std::string format_json(const std::vector<EvalRow>& rows, const std::string& preset,
                        const flow::LkParams& params);
// The LK parameters as format_json writes them under "params".
nlohmann::ordered_json params_json(const flow::LkParams& params);

}  // namespace roiflow::eval
