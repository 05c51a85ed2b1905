// The inputs of one dense-flow run, checked before any computation: two 8-bit gray frames from
// image files (same size, within the frame-size limits) with an optional ground-truth flow of
// that size, or a built-in synthetic pair that brings its exact ground truth. Also the
// --pair lists of `roiflow eval` and `roiflow sweep` as EvalPairs.
//
//   const roiflow::eval::FlowInput in = roiflow::eval::read_flow_input("a.png", "b.png", "gt.flo");
//   const roiflow::flow::LkParams params = roiflow::flow::LkParams::paper();
//   const cv::Mat flow = roiflow::flow::dense_flow(in.frame0, in.frame1, params).flow;
//   if (in.truth.empty()) return;
//   std::cout << roiflow::eval::errors_text(roiflow::flow::flow_errors(flow, in.truth)) << "\n";
#pragma once

#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "eval/flow_eval.hpp"
#include "eval/synthetic.hpp"
#include "flow/metrics.hpp"

namespace roiflow::eval {

struct FlowInput {
  cv::Mat frame0, frame1;  // CV_8UC1
  cv::Mat truth;           // CV_32FC2, or empty
  std::string source;      // "a.png -> b.png", "synthetic Zoom"
};

// Throws roiflow::Error naming the file for a directory, an unreadable image or ground truth,
// frames of different sizes, and a ground truth whose size is not the frames'.
FlowInput read_flow_input(const std::string& frame0, const std::string& frame1,
                          const std::string& ground_truth);
// `name` is to_string(kind) of one of synthetic_scene_kinds(); throws roiflow::Error otherwise.
FlowInput synthetic_flow_input(const std::string& name, cv::Size size);
// `roiflow flow`'s input: the pair frame0, frame1 (with the optional ground truth), or, when
// `scene` is not empty, that synthetic scene at `size`. Throws UsageError when both or neither
// are given, or a ground truth with a synthetic scene.
FlowInput flow_input(const std::string& frame0, const std::string& frame1,
                     const std::string& ground_truth, const std::string& scene, cv::Size size);
std::vector<SceneKind> synthetic_scene_kinds();

// "AAE 1.234 deg, EPE 0.1234 px, R1 1.23 %, R3 0.12 %".
std::string errors_text(const flow::FlowErrors& e);

// The pairs of `dir` (find_pairs with `find`; `skipped` gets what a partial tree lacks), else
// listed_pairs of `triples` and `exclude_masks`; UsageError when both are empty.
std::vector<EvalPair> select_pairs(const std::string& dir, const FindOptions& find,
                                   const std::vector<std::vector<std::string>>& triples,
                                   const std::vector<std::string>& exclude_masks,
                                   std::vector<std::string>* skipped);

// The first `max_pairs` (0: all) pairs of a Middlebury `dir`, else of `triples`; UsageError
// when both are empty (`roiflow sweep`).
std::vector<EvalPair> middlebury_or_listed(const std::string& dir,
                                           const std::vector<std::vector<std::string>>& triples,
                                           int max_pairs);

// Pairs "pair1", "pair2", ... from {A, B, GT} triples, with one exclude mask per pair or none
// (else UsageError).
std::vector<EvalPair> listed_pairs(const std::vector<std::vector<std::string>>& triples,
                                   const std::vector<std::string>& exclude_masks = {});

}  // namespace roiflow::eval
