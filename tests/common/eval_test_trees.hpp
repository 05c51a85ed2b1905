// Tiny MPI-Sintel and KITTI trees for the evaluation tests (flow_eval, html_report, eval CLI).
//
//   roiflow::test::write_sintel_tree(dir_ / "sintel", {"alley_1", "cave_2"}, 3);
//   roiflow::test::write_kitti_tree(dir_ / "kitti", {0, 7});
//
// Every pair is the "hand case": two uniform 40x30 frames, so dense LK estimates zero flow and
// the endpoint error at a pixel is the length of its ground truth, which makes the expected
// figures a hand computation:
//   ground truth (3, 4) for x < 20 (|.| = 5: EPE 5, a KITTI outlier: 5 > 3 and 5 > 5 % of 5),
//                (0.5, 0) for x >= 20 (EPE 0.5: no outlier);
//   invalid (not scored at all) for y < 10; occluded (scored in "all" only) for x < 10.
// Scored "all": 20 rows x 40 = 800 px, 400 at EPE 5 and 400 at 0.5:
//   EPE = (400 * 5 + 400 * 0.5) / 800 = 2.75, Fl = 400 / 800 = 50 %.
// Non-occluded: 20 rows x 30 = 600 px, 200 at EPE 5 and 400 at 0.5:
//   EPE = (200 * 5 + 400 * 0.5) / 600 = 2.0, Fl = 200 / 600 = 33.3 %.
#pragma once

#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <opencv2/imgcodecs.hpp>
#include <string>
#include <vector>

#include "eval/flo_io.hpp"
#include "eval/kitti_flow.hpp"

namespace roiflow::test {

inline const cv::Size kHandSize{40, 30};
inline constexpr long long kHandPixelsAll = 800;
inline constexpr long long kHandPixelsNoc = 600;
inline constexpr double kHandEpeAll = 2.75;
inline constexpr double kHandEpeNoc = 2.0;
inline constexpr double kHandFlAll = 50.0;
inline constexpr double kHandFlNoc = 100.0 / 3.0;

inline cv::Mat hand_truth() {
  cv::Mat flow(kHandSize, CV_32FC2, cv::Scalar(0.5, 0));
  flow.colRange(0, 20).setTo(cv::Scalar(3, 4));
  return flow;
}

inline cv::Mat hand_invalid() {
  cv::Mat mask(kHandSize, CV_8UC1, cv::Scalar(0));
  mask.rowRange(0, 10).setTo(255);
  return mask;
}

inline cv::Mat hand_occluded() {
  cv::Mat mask(kHandSize, CV_8UC1, cv::Scalar(0));
  mask.colRange(0, 10).setTo(255);
  return mask;
}

inline cv::Mat hand_frame() {
  return cv::Mat(kHandSize, CV_8UC1, cv::Scalar(100));
}

inline void write_png(const std::filesystem::path& path, const cv::Mat& image) {
  std::filesystem::create_directories(path.parent_path());
  ASSERT_TRUE(cv::imwrite(path.string(), image)) << path;
}

inline std::string sintel_frame(int number, const char* extension) {
  char name[32];
  std::snprintf(name, sizeof name, "frame_%04d%s", number, extension);
  return name;
}

inline std::string kitti_name(int id, const char* suffix) {
  char name[32];
  std::snprintf(name, sizeof name, "%06d%s", id, suffix);
  return name;
}

// root/{clean,final}/<scene>/frame_0001..N+1.png, flow/<scene>/frame_0001..N.flo and, with
// `masks`, occlusions/ and invalid/ <scene>/frame_0001..N.png.
inline void write_sintel_tree(const std::filesystem::path& root,
                              const std::vector<std::string>& scenes, int pairs,
                              bool masks = true) {
  for (const std::string& scene : scenes) {
    for (int i = 1; i <= pairs + 1; ++i) {
      for (const char* pass : {"clean", "final"})
        write_png(root / pass / scene / sintel_frame(i, ".png"), hand_frame());
    }
    std::filesystem::create_directories(root / "flow" / scene);
    for (int i = 1; i <= pairs; ++i) {
      eval::write_flo((root / "flow" / scene / sintel_frame(i, ".flo")).string(), hand_truth());
      if (masks) {
        write_png(root / "occlusions" / scene / sintel_frame(i, ".png"), hand_occluded());
        write_png(root / "invalid" / scene / sintel_frame(i, ".png"), hand_invalid());
      }
    }
  }
}

// root/<images>/NNNNNN_10.png, NNNNNN_11.png, flow_occ/NNNNNN_10.png (invalid: y < 10) and,
// with `noc`, flow_noc/NNNNNN_10.png (invalid also where occluded, x < 10).
inline void write_kitti_tree(const std::filesystem::path& root, const std::vector<int>& ids,
                             const std::string& images = "image_0", bool noc = true) {
  cv::Mat occ = hand_truth();
  occ.setTo(cv::Scalar(eval::kKittiInvalidFlow, eval::kKittiInvalidFlow), hand_invalid());
  cv::Mat non_occluded = occ.clone();
  non_occluded.setTo(cv::Scalar(eval::kKittiInvalidFlow, eval::kKittiInvalidFlow), hand_occluded());
  for (int id : ids) {
    write_png(root / images / kitti_name(id, "_10.png"), hand_frame());
    write_png(root / images / kitti_name(id, "_11.png"), hand_frame());
    write_png(root / "flow_occ" / kitti_name(id, "_10.png"), eval::encode_kitti_flow(occ));
    if (noc) {
      write_png(root / "flow_noc" / kitti_name(id, "_10.png"),
                eval::encode_kitti_flow(non_occluded));
    }
  }
}

}  // namespace roiflow::test
