// The fuzz targets' seed corpus: valid inputs written by the project's own writers (write_flo,
// the track-log format) plus hand-written ground truth and argument lists. fuzz/fuzz_seeds.cpp
// writes them out for scripts/fuzz.sh; tests/eval/fuzz_regression_test.cpp checks that every seed
// parses.
//
//   for (const auto& [target, seeds] : roiflow::fuzz::seed_corpus(tmp_dir)) ...
#pragma once

#include <filesystem>
#include <fstream>
#include <map>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "eval/flo_io.hpp"
#include "eval/kitti_flow.hpp"
#include "eval/track_log.hpp"

namespace roiflow::fuzz {

inline std::string file_bytes(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

// Target name (flo, ground_truth, track_csv, cli_options, kitti_flow) -> seed inputs. `scratch` is
// an existing directory for the writers' files.
inline std::map<std::string, std::vector<std::string>> seed_corpus(
    const std::filesystem::path& scratch) {
  std::map<std::string, std::vector<std::string>> seeds;

  for (const cv::Size size : {cv::Size(1, 1), cv::Size(3, 2), cv::Size(8, 5)}) {
    cv::Mat flow(size, CV_32FC2);
    cv::randu(flow, -5.f, 5.f);
    if (size.area() > 1) flow.at<cv::Vec2f>(0, 0) = cv::Vec2f(1e10f, 0.f);  // unknown pixel
    const std::filesystem::path path = scratch / "seed.flo";
    eval::write_flo(path.string(), flow);
    seeds["flo"].push_back(file_bytes(path));
  }

  for (const cv::Size size : {cv::Size(1, 1), cv::Size(5, 3)}) {
    cv::Mat flow(size, CV_32FC2);
    cv::randu(flow, -20.f, 20.f);
    if (size.area() > 1) flow.at<cv::Vec2f>(1, 2) = cv::Vec2f(1e10f, 1e10f);  // invalid pixel
    std::vector<uchar> png;
    cv::imencode(".png", eval::encode_kitti_flow(flow), png);
    seeds["kitti_flow"].emplace_back(png.begin(), png.end());
  }

  seeds["ground_truth"] = {
      "70,51,107,87\n71,51,107,87\n72,52,106,86\n",
      "70\t51\t107\t87\r\n70 51 107 87\r\n",
      "1.5, 2.5,3 4\n\nNaN,NaN,NaN,NaN\n0,0,0,0\n5,6,7,8",
  };

  {
    std::string csv = std::string(eval::kTrackCsvHeader) + "\n";
    eval::TrackRecord r;
    r.box = {70, 51, 107, 87};
    csv += eval::track_csv_row(r);
    r.frame = 2;
    r.box = {71.25f, 50.5f, 107, 87};
    r.velocity = {1.25f, -0.5f};
    r.mode = eval::TrackRecord::Mode::Global;
    r.lost = true;
    r.ms = 3.5;
    csv += eval::track_csv_row(r);
    r.frame = 3;
    r.box = {0, 0, 0, 0};
    r.ms = 0.125;
    csv += eval::track_csv_row(r);
    seeds["track_csv"].push_back(csv);
  }

  seeds["cli_options"] = {
      "--patch\n7\n--levels\n4\n--iterations\n5",
      "--preset\naccurate\n--sigma\n1.5\n--lambda\n0.001\n--robust-scale\n0.05",
      "--derivative\nscharr\n--level-median\n3\n--final-median\n5\n--threads\n2",
      "--sigma=0\n--lambda=1\n--patch=31",
  };
  return seeds;
}

}  // namespace roiflow::fuzz
