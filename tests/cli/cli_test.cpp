// End-to-end tests of the roiflow binary: exit codes, stdout, the one-line error contract and
// the files it leaves behind.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <cstdlib>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <memory>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/videoio.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "eval/flo_io.hpp"
#include "eval/kitti_flow.hpp"
#include "eval/synthetic.hpp"
#include "eval/track_log.hpp"
#include "eval/tracking_scene.hpp"
#include "scene_video.hpp"
#include "test_util.hpp"

namespace {

namespace fs = std::filesystem;
using namespace roiflow;
using test::CliResult;
using test::lines_of;
using test::read_text;
using test::run_cli;
using test::split;

class CliTest : public test::TempDirTest {
 protected:
  CliResult run(const std::vector<std::string>& args) const {
    return run_cli(args, path("stdout.txt"), path("stderr.txt"));
  }

  struct FailureCase {
    std::vector<std::string> args;
    int exit_code;
    std::string expected;  // in the error line
  };
  // Each command line fails with one error line holding `expected` and the exit code given.
  void expect_failures(const std::vector<FailureCase>& cases) const;

  void write_image(const std::string& relative, const cv::Mat& image) const {
    fs::create_directories(fs::path(path(relative)).parent_path());
    ASSERT_TRUE(cv::imwrite(path(relative), image));
  }

  // DIR/<name>/frame10.png, frame11.png, flow10.flo of a small synthetic translation.
  void write_sequence(const std::string& tree, const std::string& name) const {
    const eval::Scene scene = eval::make_translation({96, 64}, {1.3f, -0.7f});
    write_image(tree + "/" + name + "/frame10.png", scene.frame0);
    write_image(tree + "/" + name + "/frame11.png", scene.frame1);
    eval::write_flo(path(tree + "/" + name + "/flow10.flo"), scene.flow);
  }
};

// Every failure: non-zero exit, one line on stderr in the CLI's format, nothing on stdout.
void expect_one_line_error(const CliResult& r, int exit_code) {
  EXPECT_EQ(r.exit_code, exit_code) << r.err;
  const std::vector<std::string> lines = lines_of(r.err);
  ASSERT_EQ(lines.size(), 1u) << r.err;
  EXPECT_EQ(lines[0].rfind("roiflow: error: ", 0), 0u) << lines[0];
  EXPECT_TRUE(r.out.empty()) << r.out;
}

void CliTest::expect_failures(const std::vector<FailureCase>& cases) const {
  for (const FailureCase& c : cases) {
    std::string shown;
    for (const std::string& arg : c.args)
      shown += " " + arg;
    SCOPED_TRACE("roiflow" + shown);
    const CliResult r = run(c.args);
    expect_one_line_error(r, c.exit_code);
    EXPECT_NE(r.err.find(c.expected), std::string::npos) << r.err;
  }
}

TEST_F(CliTest, FlowSyntheticWritesReadableFlowAndColour) {
  const CliResult r = run({"flow", "--synthetic", "-o", path("out.flo"), "--color", path("out.png"),
                           "--legend", path("legend.png")});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(r.err.empty()) << r.err;

  const cv::Mat flow = eval::read_flo(path("out.flo"));
  EXPECT_EQ(flow.size(), cv::Size(640, 480));
  const cv::Mat color = cv::imread(path("out.png"), cv::IMREAD_UNCHANGED);
  EXPECT_EQ(color.size(), cv::Size(640, 480));
  EXPECT_EQ(color.channels(), 3);
  EXPECT_FALSE(cv::imread(path("legend.png")).empty());

  const std::size_t epe = r.out.find("EPE ");
  ASSERT_NE(epe, std::string::npos) << r.out;
  EXPECT_LT(std::stod(r.out.substr(epe + 4)), 0.15) << r.out;  // 0.07 at the time of writing
  for (const char* metric : {"AAE", "R1", "R3"})
    EXPECT_NE(r.out.find(metric), std::string::npos);
  EXPECT_EQ(lines_of(r.out).size(), 2u) << r.out;
}

TEST_F(CliTest, FlowOnImageFilesScoresAgainstGroundTruth) {
  const eval::Scene scene = eval::make_scene(eval::SceneKind::Translation, {128, 96});
  write_image("a.png", scene.frame0);
  write_image("b.png", scene.frame1);
  eval::write_flo(path("gt.flo"), scene.flow);
  const CliResult r = run({"flow", path("a.png"), path("b.png"), "-o", path("out.flo"), "--gt",
                           path("gt.flo"), "--preset", "accurate", "--patch", "9"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("128x96"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("EPE"), std::string::npos) << r.out;
  EXPECT_EQ(eval::read_flo(path("out.flo")).size(), cv::Size(128, 96));
}

TEST_F(CliTest, EvalCsvOverMiddleburyTree) {
  write_sequence("mb", "Venus");
  write_sequence("mb", "Dimetrodon");
  const CliResult r = run({"eval", path("mb"), "--format", "csv"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const std::vector<std::string> lines = lines_of(r.out);
  ASSERT_EQ(lines.size(), 4u) << r.out;
  EXPECT_EQ(lines[0], "sequence,aae_deg,epe,r1,r3,ms");
  EXPECT_EQ(lines[1].rfind("Dimetrodon,", 0), 0u);
  EXPECT_EQ(lines[2].rfind("Venus,", 0), 0u);
  EXPECT_EQ(lines[3].rfind("mean,", 0), 0u);
  // mean,<aae .3f>,<epe .4f>,<r1 .2f>,<r3 .2f>,<ms .2f>
  const std::vector<std::string> fields = split(lines[3], ',');
  ASSERT_EQ(fields.size(), 6u) << lines[3];
  const int decimals[] = {3, 4, 2, 2, 2};
  for (int i = 0; i < 5; ++i) {
    const std::string& field = fields[i + 1];
    ASSERT_NE(field.find('.'), std::string::npos) << field;
    EXPECT_EQ(static_cast<int>(field.size() - field.find('.') - 1), decimals[i]) << field;
    EXPECT_GE(std::stod(field), 0.0) << field;
  }

  const CliResult to_file = run({"eval", path("mb"), "--format", "json", "-o", path("e.json")});
  ASSERT_EQ(to_file.exit_code, 0) << to_file.err;
  const nlohmann::json doc = nlohmann::json::parse(read_text(path("e.json")));
  EXPECT_EQ(doc["preset"], "paper");
  EXPECT_EQ(doc["rows"].size(), 2u);
  EXPECT_EQ(doc["mean"]["sequence"], "mean");

  const CliResult table = run({"eval", path("mb")});
  ASSERT_EQ(table.exit_code, 0) << table.err;
  EXPECT_EQ(table.out.rfind("sequence", 0), 0u) << table.out;
  EXPECT_NE(table.out.find("\nmean"), std::string::npos) << table.out;
}

TEST_F(CliTest, EvalPairsWithExcludeMasks) {
  write_sequence("mb", "One");
  write_sequence("mb", "Two");
  write_image("mask.png", cv::Mat(64, 96, CV_8UC1, cv::Scalar(0)));
  const CliResult r =
      run({"eval", "--format", "csv", "--pair", path("mb/One/frame10.png"),
           path("mb/One/frame11.png"), path("mb/One/flow10.flo"), "--pair",
           path("mb/Two/frame10.png"), path("mb/Two/frame11.png"), path("mb/Two/flow10.flo"),
           "--exclude-mask", path("mask.png"), "--exclude-mask", path("mask.png")});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const std::vector<std::string> lines = lines_of(r.out);
  ASSERT_EQ(lines.size(), 4u) << r.out;
  EXPECT_EQ(lines[1].rfind("pair1,", 0), 0u);
  EXPECT_EQ(lines[2].rfind("pair2,", 0), 0u);
}

TEST_F(CliTest, HelpExitsZero) {
  for (const char* sub : {"flow", "eval"}) {
    const CliResult r = run({sub, "--help"});
    EXPECT_EQ(r.exit_code, 0) << sub;
    EXPECT_NE(r.out.find("--preset"), std::string::npos) << r.out;
  }
}

TEST_F(CliTest, BadInputsFailWithOneLineAndNoOutput) {
  write_sequence("corrupt", "Venus");
  std::ofstream(path("corrupt/Venus/flow10.flo"), std::ios::binary) << "PIEH? no: bad magic";
  write_sequence("mb", "Venus");
  write_image("small.png", cv::Mat(32, 48, CV_8UC1, cv::Scalar(9)));
  const std::string flo = path("out.flo");
  const std::string png = path("out.png");
  const std::string csv = path("out.csv");
  const std::vector<std::string> synthetic = {"flow", "--synthetic", "-o", flo, "--color", png};
  const auto with = [&](std::vector<std::string> args, const std::vector<std::string>& more) {
    args.insert(args.end(), more.begin(), more.end());
    return args;
  };
  struct Case {
    std::vector<std::string> args;
    int exit_code;
  };
  const std::vector<Case> cases = {
      {{}, 2},
      {{"nonsense"}, 2},
      {{"flow", path("missing.png"), path("mb/Venus/frame11.png"), "-o", flo}, 1},
      {{"flow", path("mb/Venus/frame10.png"), path("small.png"), "-o", flo}, 1},
      {{"flow", path("mb/Venus/frame10.png"), "-o", flo}, 2},
      {{"flow", path("mb/Venus/frame10.png"), path("mb/Venus/frame11.png"), "-o", flo, "--gt",
        path("corrupt/Venus/flow10.flo")},
       1},
      {with(synthetic, {"--patch", "1"}), 2},
      {with(synthetic, {"--patch", "40"}), 2},
      {with(synthetic, {"--levels", "0"}), 2},
      {with(synthetic, {"--preset", "nope"}), 2},
      {with(synthetic, {"--sigma", "-1"}), 2},
      {with(synthetic, {"--lambda", "0"}), 2},
      {with(synthetic, {"--derivative", "sobel"}), 2},
      {with(synthetic, {"--final-median", "4"}), 2},
      {with(synthetic, {"--threads", "0"}), 2},
      {{"flow", "--synthetic", "nope", "-o", flo}, 2},
      {{"flow", "--synthetic", "-o", flo, "--color", path("out.xyz")}, 2},
      {{"flow", "--synthetic", "-o", path("no/such/dir/out.flo")}, 1},
      {{"flow", "--synthetic", "-o", dir_.string()}, 1},
      {{"flow", path("mb/Venus/frame10.png"), path("mb/Venus/frame11.png"), "-o", flo,
        "--synthetic"},
       2},
      {{"flow", "--synthetic", "-o", flo, "--color", path("no/such/dir/out.png")}, 1},
      {{"eval", path("corrupt"), "--format", "csv", "-o", csv}, 1},
      {{"eval", path("missing"), "-o", csv}, 1},
      {{"eval", "-o", csv}, 2},
      {{"eval", path("mb"), "--pair", "a.png", "b.png", "gt.flo", "-o", csv}, 2},
      {{"eval", "--pair", "a.png", "b.png"}, 2},
      {{"eval", "--pair", "a.png", "b.png", "gt.flo", "--exclude-mask", "m1.png", "--exclude-mask",
        "m2.png"},
       2},
      {{"eval", path("mb"), "--format", "xml", "-o", csv}, 2},
  };
  for (const Case& c : cases) {
    std::string shown;
    for (const std::string& arg : c.args)
      shown += " " + arg;
    SCOPED_TRACE("roiflow" + shown);
    expect_one_line_error(run(c.args), c.exit_code);
    EXPECT_FALSE(fs::exists(flo));
    EXPECT_FALSE(fs::exists(png));
    EXPECT_FALSE(fs::exists(csv));
  }
  // No partial files either: the directory holds only what the test wrote.
  for (const fs::directory_entry& entry : fs::directory_iterator(dir_)) {
    const std::string name = entry.path().filename().string();
    EXPECT_TRUE(name == "corrupt" || name == "mb" || name == "small.png" || name == "stdout.txt" ||
                name == "stderr.txt")
        << name;
  }
}

// --- roiflow score ------------------------------------------------------------------------------

// Five 40x40 ground-truth boxes, written with the separators OTB files mix, and a track log 10 px
// to the right of them: IoU 0.6 everywhere, centre error 10 px.
class CliScoreTest : public CliTest {
 protected:
  void SetUp() override {
    CliTest::SetUp();
    std::ofstream truth(path("gt.txt"), std::ios::binary);
    std::ofstream track(path("track.csv"), std::ios::binary);
    track << "frame,x,y,w,h,vx,vy,mode,lost,ms\n";
    const char* separators[] = {",", "\t", " ", ", ", ","};
    for (int i = 0; i < 5; ++i) {
      const int x = 100 + 4 * i;
      const std::string sep = separators[i];
      truth << x << sep << 50 << sep << 40 << sep << 40 << "\r\n";
      track << i + 1 << "," << x + 10 << ".00,50.00,40.00,40.00,4.000,0.000,"
            << (i == 0 ? "global" : "local") << ",0,0.250\n";
    }
  }
};

TEST_F(CliScoreTest, JsonHasExactlyTheFourMetrics) {
  const CliResult r = run({"score", path("track.csv"), path("gt.txt"), "--format", "json"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(r.err.empty()) << r.err;
  const nlohmann::json doc = nlohmann::json::parse(r.out);
  ASSERT_TRUE(doc.is_object());
  std::vector<std::string> keys;
  for (const auto& item : doc.items())
    keys.push_back(item.key());
  EXPECT_EQ(keys, (std::vector<std::string>{"auc", "frames", "mean_iou", "precision20"}));
  EXPECT_NEAR(doc["auc"].get<double>(), 12.0 / 21.0, 1e-12);
  EXPECT_NEAR(doc["precision20"].get<double>(), 1.0, 1e-12);
  EXPECT_NEAR(doc["mean_iou"].get<double>(), 0.6, 1e-12);
  EXPECT_TRUE(doc["frames"].is_number_integer());
  EXPECT_EQ(doc["frames"], 5);
}

TEST_F(CliScoreTest, TableShowsTheMetricsAndLengths) {
  const CliResult r = run({"score", path("track.csv"), path("gt.txt")});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(lines_of(r.out).size(), 4u) << r.out;
  EXPECT_NE(r.out.find("success AUC    0.5714"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("precision@20   1.0000"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("mean IoU       0.6000"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("frames         5 (track 5, ground truth 5)"), std::string::npos) << r.out;
}

TEST_F(CliScoreTest, BadInputsFailWithOneLine) {
  std::ofstream(path("bad_header.csv"), std::ios::binary) << "frame,x,y,w,h\n1,1,2,3,4\n";
  std::ofstream(path("gap.csv"), std::ios::binary)
      << "frame,x,y,w,h,vx,vy,mode,lost,ms\n1,1,2,3,4,0,0,local,0,1\n3,1,2,3,4,0,0,local,0,1\n";
  std::ofstream(path("bad_gt.txt"), std::ios::binary) << "1,2,3,4\n1,2,three,4\n";
  std::ofstream(path("absent_gt.txt"), std::ios::binary) << "0,0,0,0\nNaN,NaN,NaN,NaN\n";
  const std::vector<FailureCase> cases = {
      {{"score", path("missing.csv"), path("gt.txt")}, 1, path("missing.csv")},
      {{"score", path("track.csv"), path("missing.txt")}, 1, path("missing.txt")},
      {{"score", path("bad_header.csv"), path("gt.txt")}, 1, path("bad_header.csv") + ":1:"},
      {{"score", path("gap.csv"), path("gt.txt")}, 1, "record 2 is frame 3"},
      {{"score", path("track.csv"), path("bad_gt.txt")}, 1, path("bad_gt.txt") + ":2:"},
      {{"score", path("track.csv"), path("absent_gt.txt")}, 1, "no frame to score"},
      {{"score", path("track.csv")}, 2, "GROUNDTRUTH"},
      {{"score", path("track.csv"), path("gt.txt"), "--format", "csv"}, 2, "--format"},
  };
  expect_failures(cases);
}

// ---------------------------------------------------------------------------------------------
// roiflow track, dense, demo

class CliVideoTest : public CliTest {
 protected:
  // A short synthetic fixed-camera video (the demo's scene, 160x120) as MJPG .avi, and its
  // ground-truth boxes as an OTB file.
  void SetUp() override {
    CliTest::SetUp();
    scene_ = test::write_scene_video(path("scene.avi"), 30);
    std::ofstream truth(path("truth.txt"));
    for (int i = 0; i < scene_->frames(); ++i)
      truth << test::box_text(scene_->box(i)) << "\n";
  }
  std::string init_box() const { return test::box_text(scene_->box(0)); }
  std::unique_ptr<eval::TrackingScene> scene_;
};

TEST_F(CliVideoTest, TrackWritesLogSummaryAndVideoThatScoreReads) {
  const CliResult r = run({"track", path("scene.avi"), "--init", init_box(), "--log",
                           path("track.csv"), "--summary", path("summary.json"), "--out",
                           path("annotated.avi"), "--threads", "2", "--no-progress"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(r.err.empty()) << r.err;
  const std::vector<eval::TrackRecord> log = eval::read_track_csv(path("track.csv"));
  ASSERT_EQ(log.size(), 30u);
  for (std::size_t i = 0; i < log.size(); ++i)
    EXPECT_EQ(log[i].frame, static_cast<long long>(i) + 1);
  const auto summary = nlohmann::json::parse(read_text(path("summary.json")));
  EXPECT_EQ(summary.at("frames").get<long long>(), 30);
  EXPECT_EQ(summary.at("mode").get<std::string>(), "local");
  EXPECT_GT(summary.at("fps").get<double>(), 0.0);
  EXPECT_GT(summary.at("tracker_fps").get<double>(), 0.0);
  // The scene's 10 px jump stays inside the local region: the target is never lost, so the
  // global treatment never runs.
  EXPECT_EQ(summary.at("global_activations").get<long long>(), 0);
  EXPECT_EQ(summary.at("lost_frames").get<long long>(), 0);
  cv::VideoCapture video(path("annotated.avi"), cv::CAP_FFMPEG);
  ASSERT_TRUE(video.isOpened());
  EXPECT_EQ(static_cast<int>(video.get(cv::CAP_PROP_FRAME_COUNT)), 30);

  const CliResult s = run({"score", path("track.csv"), path("truth.txt"), "--format", "json"});
  ASSERT_EQ(s.exit_code, 0) << s.err;
  const auto score = nlohmann::json::parse(s.out);
  EXPECT_GT(score.at("precision20").get<double>(), 0.9);
  // A perfect track scores 20/21 = 0.952 (OTB's strict threshold); measured 0.948, mean IoU 0.974.
  EXPECT_GT(score.at("auc").get<double>(), 0.93);
  EXPECT_GT(score.at("mean_iou").get<double>(), 0.95);
}

TEST_F(CliVideoTest, GlobalModeActivatesTheGlobalTreatmentEveryFrame) {
  const CliResult r = run({"track", path("scene.avi"), "--init", init_box(), "--mode", "global",
                           "--summary", path("global.json"), "--no-progress"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const CliResult l = run({"track", path("scene.avi"), "--init", init_box(), "--summary",
                           path("local.json"), "--no-progress"});
  ASSERT_EQ(l.exit_code, 0) << l.err;
  const auto global = nlohmann::json::parse(read_text(path("global.json")));
  const auto local = nlohmann::json::parse(read_text(path("local.json")));
  EXPECT_EQ(global.at("mode").get<std::string>(), "global");
  EXPECT_EQ(global.at("global_activations").get<long long>(), 30);
  EXPECT_LT(local.at("global_activations").get<long long>(), 30);
}

TEST_F(CliVideoTest, DenseWritesOneColourFramePerPair) {
  const CliResult r = run({"dense", path("scene.avi"), "--out", path("flow_frames"), "--max-frames",
                           "6", "--summary", path("dense.json"), "--no-progress"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  int pngs = 0;
  for (const auto& entry : fs::directory_iterator(path("flow_frames"))) {
    EXPECT_EQ(entry.path().extension(), ".png");
    ++pngs;
  }
  EXPECT_EQ(pngs, 5);
  const auto summary = nlohmann::json::parse(read_text(path("dense.json")));
  EXPECT_EQ(summary.at("pairs").get<long long>(), 5);
  EXPECT_EQ(summary.at("mode").get<std::string>(), "dense");
}

// The raw flow of every pair as KITTI PNGs (and as .flo), equal to `roiflow flow` on the same
// frames to the format's 1/64 px; the run at 2 threads writes the same files as at 1.
TEST_F(CliVideoTest, DenseWritesTheRawFlowOfEveryPair) {
  for (const char* threads : {"1", "2"}) {
    const std::string dir = path(std::string("kitti") + threads);
    const CliResult r = run({"dense", path("scene.avi"), "--flow-out", dir, "--flow-format",
                             "kitti", "--max-frames", "5", "--threads", threads, "--no-progress"});
    ASSERT_EQ(r.exit_code, 0) << r.err;
  }
  const CliResult flo = run({"dense", path("scene.avi"), "--flow-out", path("flo"), "--out",
                             path("colour"), "--max-frames", "5", "--no-progress"});
  ASSERT_EQ(flo.exit_code, 0) << flo.err;
  for (int i = 1; i <= 4; ++i) {
    const std::string name = "00000" + std::to_string(i);
    EXPECT_EQ(read_text(path("kitti1/" + name + ".png")),
              read_text(path("kitti2/" + name + ".png")));
    const cv::Mat exact = eval::read_flo(path("flo/" + name + ".flo"));
    const cv::Mat kitti = eval::read_kitti_flow(path("kitti1/" + name + ".png"));
    ASSERT_EQ(exact.size(), cv::Size(160, 120));
    EXPECT_LE(cv::norm(exact, kitti, cv::NORM_INF), 1.0 / 128 + 1e-4) << name;
    EXPECT_FALSE(cv::imread(path("colour/" + name + ".png")).empty());
  }
  EXPECT_FALSE(fs::exists(path("flo/000005.flo")));
  EXPECT_FALSE(fs::exists(path("kitti1/000005.png")));
  const CliResult bad = run({"dense", path("scene.avi"), "--flow-out", path("x"), "--flow-format",
                             "png", "--no-progress"});
  EXPECT_NE(bad.exit_code, 0);
  EXPECT_EQ(lines_of(bad.err).size(), 1u) << bad.err;
}

TEST_F(CliVideoTest, DemoTracksTheSceneAndPrintsItsError) {
  const CliResult r = run({"demo", "--dir", path("demo"), "--frames", "60", "--no-progress"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("success AUC"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("mean centre error"), std::string::npos) << r.out;
  for (const char* file : {"demo.mp4", "track.csv", "summary.json", "groundtruth.txt"}) {
    EXPECT_TRUE(fs::exists(path("demo") + "/" + file)) << file;
  }
  EXPECT_EQ(eval::read_track_csv(path("demo/track.csv")).size(), 60u);
  const auto summary = nlohmann::json::parse(read_text(path("demo/summary.json")));
  EXPECT_GT(summary.at("score").at("precision20").get<double>(), 0.8);
  EXPECT_GE(summary.at("global_activations").get<long long>(), 1);
}

TEST_F(CliVideoTest, ATruncatedVideoStopsCleanlyWithOneLineAndKeepsWhatWasWritten) {
  const std::string whole = read_text(path("scene.avi"));
  std::ofstream(path("cut.avi"), std::ios::binary) << whole.substr(0, whole.size() / 2);
  const CliResult r = run({"track", path("cut.avi"), "--init", init_box(), "--log", path("cut.csv"),
                           "--summary", path("cut.json"), "--no-progress"});
  // The summary of what was done goes to stdout as usual; stderr holds the one error line.
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_EQ(lines_of(r.err).size(), 1u) << r.err;
  EXPECT_EQ(r.err.rfind("roiflow: error: input stopped at frame", 0), 0u) << r.err;
  EXPECT_NE(r.out.find("frames in"), std::string::npos) << r.out;
  const std::vector<eval::TrackRecord> log = eval::read_track_csv(path("cut.csv"));
  EXPECT_GT(log.size(), 5u);
  EXPECT_LT(log.size(), 30u);
  const auto summary = nlohmann::json::parse(read_text(path("cut.json")));
  EXPECT_EQ(summary.at("frames").get<std::size_t>(), log.size());
  EXPECT_NE(summary.at("status").get<std::string>().find("stopped at frame"), std::string::npos);
}

TEST_F(CliVideoTest, BadVideoCommandLinesFailWithOneLine) {
  std::ofstream(path("garbage.avi"), std::ios::binary) << "not a video at all";
  const std::vector<FailureCase> cases = {
      {{"track", path("missing.avi")}, 1, path("missing.avi")},
      {{"track", path("garbage.avi")}, 1, path("garbage.avi")},
      {{"track", path("scene.avi"), "--init", "1,2,3"}, 2, "--init"},
      {{"track", path("scene.avi"), "--init", "1,2,-3,4"}, 2, "--init"},
      {{"track", path("scene.avi"), "--init", "500,500,10,10"}, 2, "outside"},
      {{"track", path("scene.avi"), "--log", path("track.txt")}, 2, ".csv or .json"},
      {{"track", path("scene.avi"), "--roi", "0"}, 2, "--roi"},
      {{"track", path("scene.avi"), "--mode", "both"}, 2, "--mode"},
      {{"track", path("scene.avi"), "--log", path("no/such/dir/t.csv")}, 1, "no/such/dir"},
      {{"dense", path("scene.avi")}, 2, "--out"},
      {{"dense", path("scene.avi"), "--out", path("x.avi"), "--patch", "2"}, 2, "--patch"},
      {{"demo", "--frames", "1"}, 2, "--frames"},
  };
  expect_failures(cases);
  EXPECT_FALSE(fs::exists(path("track.txt")));
}

}  // namespace
