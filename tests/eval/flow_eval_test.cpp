#include "eval/flow_eval.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <functional>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "core/error.hpp"
#include "eval/flo_io.hpp"
#include "eval/kitti_flow.hpp"
#include "eval/synthetic.hpp"
#include "eval_test_trees.hpp"
#include "test_util.hpp"

namespace roiflow::eval {
namespace {

namespace fs = std::filesystem;
using test::lines_of;

// The message of the roiflow::Error `f` throws, or a failure when it throws nothing.
std::string error_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const Error& e) {
    return e.what();
  }
  ADD_FAILURE() << "expected roiflow::Error";
  return "";
}

EvalRow row(const std::string& name, double aae, double epe, double r1, double r3, double ms) {
  EvalRow r;
  r.name = name;
  r.errors.aae_deg = aae;
  r.errors.epe = epe;
  r.errors.r1 = r1;
  r.errors.r3 = r3;
  r.errors.pixels = 100;
  r.ms = ms;
  return r;
}

flow::FlowErrors errors(double aae, double epe, double r1, double r3, double fl) {
  flow::FlowErrors e;
  e.aae_deg = aae;
  e.epe = epe;
  e.r1 = r1;
  e.r3 = r3;
  e.fl = fl;
  e.pixels = 50;
  return e;
}

class FlowEvalTest : public test::TempDirTest {
 protected:
  void write_image(const std::string& relative, const cv::Mat& image) const {
    fs::create_directories(fs::path(path(relative)).parent_path());
    ASSERT_TRUE(cv::imwrite(path(relative), image));
  }

  // DIR/<name>/frame10.png, frame11.png, flow10.flo from a small synthetic translation.
  eval::Scene write_sequence(const std::string& name, bool with_flow = true) const {
    const eval::Scene scene = eval::make_translation({96, 64}, {1.3f, -0.7f});
    write_image(name + "/frame10.png", scene.frame0);
    write_image(name + "/frame11.png", scene.frame1);
    if (with_flow) eval::write_flo(path(name + "/flow10.flo"), scene.flow);
    return scene;
  }

  EvalPair translation_pair(cv::Size size) const {
    const eval::Scene scene = eval::make_translation(size, {1.3f, -0.7f}, 3);
    write_image("a.png", scene.frame0);
    write_image("b.png", scene.frame1);
    eval::write_flo(path("gt.flo"), scene.flow);
    return {"translation", path("a.png"), path("b.png"), path("gt.flo"), ""};
  }
};

TEST_F(FlowEvalTest, FindsCompleteSequencesSortedPreferringGray) {
  write_sequence("Venus");
  const eval::Scene dimetrodon = write_sequence("Dimetrodon");
  write_image("Dimetrodon/gray/frame10.png", dimetrodon.frame0);
  write_image("Dimetrodon/gray/frame11.png", dimetrodon.frame1);
  write_sequence("Grove");
  write_image("Grove/gray/frame10.png", dimetrodon.frame0);  // half a gray pair: not used
  write_sequence("NoFlow", /*with_flow=*/false);
  std::ofstream(path("README.txt")) << "not a sequence\n";

  const std::vector<EvalPair> pairs = find_middlebury(dir_.string());
  ASSERT_EQ(pairs.size(), 3u);
  EXPECT_EQ(pairs[0].name, "Dimetrodon");
  EXPECT_EQ(pairs[0].frame0, path("Dimetrodon/gray/frame10.png"));
  EXPECT_EQ(pairs[0].frame1, path("Dimetrodon/gray/frame11.png"));
  EXPECT_EQ(pairs[0].ground_truth, path("Dimetrodon/flow10.flo"));
  EXPECT_EQ(pairs[1].name, "Grove");
  EXPECT_EQ(pairs[1].frame0, path("Grove/frame10.png"));
  EXPECT_EQ(pairs[2].name, "Venus");
  EXPECT_EQ(pairs[2].frame0, path("Venus/frame10.png"));
  EXPECT_EQ(pairs[2].frame1, path("Venus/frame11.png"));
  EXPECT_EQ(pairs[2].ground_truth, path("Venus/flow10.flo"));
  for (const EvalPair& pair : pairs)
    EXPECT_TRUE(pair.exclude_mask.empty());
}

TEST_F(FlowEvalTest, FindMiddleburyErrorsNameTheDirectory) {
  const std::string missing = path("missing");
  EXPECT_NE(error_of([&] { find_middlebury(missing); }).find(missing), std::string::npos);

  EXPECT_NE(error_of([&] { find_middlebury(dir_.string()); }).find(dir_.string()),
            std::string::npos);

  write_sequence("NoFlow", /*with_flow=*/false);
  EXPECT_NE(error_of([&] { find_middlebury(dir_.string()); }).find("no Middlebury sequence"),
            std::string::npos);

  const std::string file = path("file.txt");
  std::ofstream(file) << "x";
  EXPECT_NE(error_of([&] { find_middlebury(file); }).find(file), std::string::npos);
}

TEST_F(FlowEvalTest, EvaluatesTranslationAccurately) {
  const EvalPair pair = translation_pair({160, 120});
  const EvalRow result = evaluate_pair(pair, flow::LkParams::paper());
  EXPECT_EQ(result.name, "translation");
  EXPECT_EQ(result.errors.pixels, 160 * 120);
  EXPECT_LT(result.errors.epe, 0.1);  // 0.04 at the time of writing; one level gives 0.3
  EXPECT_LT(result.errors.aae_deg, 3.0);
  EXPECT_GT(result.ms, 0.0);
}

TEST_F(FlowEvalTest, ExcludeMaskDropsItsPixels) {
  EvalPair pair = translation_pair({160, 120});
  cv::Mat mask(120, 160, CV_8UC1, cv::Scalar(0));
  mask.colRange(0, 40).setTo(255);
  write_image("mask.png", mask);
  pair.exclude_mask = path("mask.png");
  EXPECT_EQ(evaluate_pair(pair, flow::LkParams::paper()).errors.pixels, 120 * 120);

  write_image("small_mask.png", cv::Mat(60, 80, CV_8UC1, cv::Scalar(0)));
  pair.exclude_mask = path("small_mask.png");
  const std::string message = error_of([&] { evaluate_pair(pair, flow::LkParams::paper()); });
  EXPECT_NE(message.find("160x120"), std::string::npos) << message;
  EXPECT_NE(message.find("80x60"), std::string::npos) << message;

  write_image("everything.png", cv::Mat(120, 160, CV_8UC1, cv::Scalar(1)));
  pair.exclude_mask = path("everything.png");
  EXPECT_NE(error_of([&] { evaluate_pair(pair, flow::LkParams::paper()); }).find("no pixel"),
            std::string::npos);
}

TEST_F(FlowEvalTest, SizeMismatchNamesBothSizes) {
  EvalPair pair = translation_pair({160, 120});
  write_image("small.png", cv::Mat(60, 80, CV_8UC1, cv::Scalar(7)));
  EvalPair frames = pair;
  frames.frame1 = path("small.png");
  std::string message = error_of([&] { evaluate_pair(frames, flow::LkParams::paper()); });
  EXPECT_NE(message.find("160x120"), std::string::npos) << message;
  EXPECT_NE(message.find("80x60"), std::string::npos) << message;

  eval::write_flo(path("small.flo"), cv::Mat(60, 80, CV_32FC2, cv::Scalar(0, 0)));
  EvalPair truth = pair;
  truth.ground_truth = path("small.flo");
  message = error_of([&] { evaluate_pair(truth, flow::LkParams::paper()); });
  EXPECT_NE(message.find("small.flo"), std::string::npos) << message;
  EXPECT_NE(message.find("80x60"), std::string::npos) << message;
}

TEST_F(FlowEvalTest, UnreadableInputsNameTheFile) {
  EvalPair pair = translation_pair({64, 48});
  EvalPair missing = pair;
  missing.frame0 = path("nope.png");
  EXPECT_NE(error_of([&] { evaluate_pair(missing, flow::LkParams::paper()); }).find("nope.png"),
            std::string::npos);

  std::ofstream(path("garbage.png")) << "not a png";
  EvalPair garbage = pair;
  garbage.frame1 = path("garbage.png");
  EXPECT_NE(error_of([&] { evaluate_pair(garbage, flow::LkParams::paper()); }).find("garbage.png"),
            std::string::npos);

  std::ofstream(path("bad.flo")) << "PIEH but not really a flow file";
  EvalPair truth = pair;
  truth.ground_truth = path("bad.flo");
  EXPECT_NE(error_of([&] { evaluate_pair(truth, flow::LkParams::paper()); }).find("bad.flo"),
            std::string::npos);
}

TEST_F(FlowEvalTest, MeanRowAveragesEveryMetric) {
  const EvalRow mean = mean_row({row("a", 1, 0.1, 2, 0, 10), row("b", 3, 0.3, 4, 1, 30)});
  EXPECT_EQ(mean.name, "mean");
  EXPECT_DOUBLE_EQ(mean.errors.aae_deg, 2.0);
  EXPECT_DOUBLE_EQ(mean.errors.epe, 0.2);
  EXPECT_DOUBLE_EQ(mean.errors.r1, 3.0);
  EXPECT_DOUBLE_EQ(mean.errors.r3, 0.5);
  EXPECT_DOUBLE_EQ(mean.ms, 20.0);
  EXPECT_EQ(mean.errors.pixels, 200);
  EXPECT_THROW(mean_row({}), Error);
}

TEST_F(FlowEvalTest, CsvIsExact) {
  const std::vector<EvalRow> rows = {row("Venus", 1.23456, 0.123456, 1.005, 0.5, 12.345),
                                     row("has,comma", 2, 0.2, 3, 1.5, 20)};
  EXPECT_EQ(format_csv(rows),
            "sequence,aae_deg,epe,r1,r3,ms\n"
            "Venus,1.235,0.1235,1.00,0.50,12.35\n"
            "\"has,comma\",2.000,0.2000,3.00,1.50,20.00\n"
            "mean,1.617,0.1617,2.00,1.00,16.17\n");
  EXPECT_EQ(format_csv({}), "sequence,aae_deg,epe,r1,r3,ms\n");
}

TEST_F(FlowEvalTest, TableColumnsAlign) {
  const std::vector<std::string> lines = lines_of(format_table(
      {row("Dimetrodon", 1.5, 0.25, 3, 0.5, 12.5), row("Urban2", 10.25, 1.5, 20, 5, 130)}));
  ASSERT_EQ(lines.size(), 5u);  // header, two rows, rule, mean
  EXPECT_EQ(lines[0].rfind("sequence", 0), 0u);
  EXPECT_NE(lines[0].find("AAE(deg)"), std::string::npos);
  EXPECT_EQ(lines[1].rfind("Dimetrodon", 0), 0u);
  EXPECT_EQ(lines[3].find_first_not_of('-'), std::string::npos);
  EXPECT_EQ(lines[4].rfind("mean", 0), 0u);
  EXPECT_NE(lines[4].find("5.875"), std::string::npos);
  for (const std::string& line : lines)
    EXPECT_EQ(line.size(), lines[0].size()) << line;
  // Right-aligned numbers: every row's EPE column ends where the header's does.
  const std::size_t epe_end = lines[0].find("EPE(px)") + 7;
  EXPECT_EQ(lines[1].substr(epe_end - 6, 6), "0.2500");
  EXPECT_EQ(lines[2].substr(epe_end - 6, 6), "1.5000");
}

TEST_F(FlowEvalTest, JsonHoldsPresetParamsRowsAndMean) {
  flow::LkParams params = flow::LkParams::paper();
  params.patch = 7;
  const nlohmann::json doc = nlohmann::json::parse(
      format_json({row("a", 1, 0.1, 2, 0, 10), row("b", 3, 0.3, 4, 1, 30)}, "paper", params));
  EXPECT_EQ(doc["preset"], "paper");
  EXPECT_EQ(doc["params"]["patch"], 7);
  EXPECT_EQ(doc["params"]["derivative"], "hs");
  ASSERT_EQ(doc["rows"].size(), 2u);
  EXPECT_EQ(doc["rows"][1]["sequence"], "b");
  EXPECT_DOUBLE_EQ(doc["rows"][1]["epe"].get<double>(), 0.3);
  EXPECT_DOUBLE_EQ(doc["rows"][0]["ms"].get<double>(), 10.0);
  EXPECT_EQ(doc["mean"]["sequence"], "mean");
  EXPECT_DOUBLE_EQ(doc["mean"]["aae_deg"].get<double>(), 2.0);
  EXPECT_DOUBLE_EQ(doc["mean"]["r3"].get<double>(), 0.5);

  EXPECT_TRUE(nlohmann::json::parse(format_json({}, "paper", params))["mean"].is_null());
}

// --- Sintel and KITTI ------------------------------------------------------------------------

TEST_F(FlowEvalTest, DetectsEachLayoutAlsoUnderTraining) {
  write_sequence("mb/Venus");
  test::write_sintel_tree(dir_ / "sintel", {"alley_1"}, 1);
  test::write_sintel_tree(dir_ / "sintel_archive/training", {"alley_1"}, 1);
  test::write_kitti_tree(dir_ / "kitti2012", {0});
  test::write_kitti_tree(dir_ / "kitti2015/training", {0}, "image_2");
  EXPECT_EQ(detect_layout(path("mb")), Layout::Middlebury);
  EXPECT_EQ(detect_layout(path("sintel")), Layout::Sintel);
  EXPECT_EQ(detect_layout(path("sintel_archive")), Layout::Sintel);
  EXPECT_EQ(detect_layout(path("kitti2012")), Layout::Kitti);
  EXPECT_EQ(detect_layout(path("kitti2015")), Layout::Kitti);

  fs::create_directories(path("empty"));
  const std::string message = error_of([&] { detect_layout(path("empty")); });
  EXPECT_NE(message.find(path("empty")), std::string::npos) << message;
  EXPECT_NE(message.find("Middlebury, Sintel or KITTI"), std::string::npos) << message;
  EXPECT_NE(error_of([&] { detect_layout(path("missing")); }).find("does not exist"),
            std::string::npos);

  for (const char* name : {"auto", "middlebury", "sintel", "kitti"})
    EXPECT_STREQ(to_string(parse_layout(name)), name);
  EXPECT_NE(error_of([&] { parse_layout("hd1k"); }).find("hd1k"), std::string::npos);
}

TEST_F(FlowEvalTest, FindsSintelPairsWithMasksSortedBySceneAndFrame) {
  test::write_sintel_tree(dir_ / "training", {"cave_2", "alley_1"}, 2);
  std::ofstream(path("training/flow/alley_1/notes.txt")) << "not a frame";
  const std::vector<EvalPair> pairs = find_sintel(dir_.string());
  ASSERT_EQ(pairs.size(), 4u);
  const fs::path root = dir_ / "training";
  EXPECT_EQ(pairs[0].name, "alley_1/frame_0001");
  EXPECT_EQ(pairs[0].frame0, (root / "clean/alley_1/frame_0001.png").string());
  EXPECT_EQ(pairs[0].frame1, (root / "clean/alley_1/frame_0002.png").string());
  EXPECT_EQ(pairs[0].ground_truth, (root / "flow/alley_1/frame_0001.flo").string());
  EXPECT_EQ(pairs[0].occlusion_mask, (root / "occlusions/alley_1/frame_0001.png").string());
  EXPECT_EQ(pairs[0].exclude_mask, (root / "invalid/alley_1/frame_0001.png").string());
  EXPECT_TRUE(pairs[0].noc_ground_truth.empty());
  EXPECT_EQ(pairs[1].name, "alley_1/frame_0002");
  EXPECT_EQ(pairs[1].frame1, (root / "clean/alley_1/frame_0003.png").string());
  EXPECT_EQ(pairs[2].name, "cave_2/frame_0001");
  EXPECT_EQ(pairs[3].name, "cave_2/frame_0002");

  const std::vector<EvalPair> final_pass = find_sintel(dir_.string(), "final");
  EXPECT_EQ(final_pass[3].frame0, (root / "final/cave_2/frame_0002.png").string());

  // Without occlusions/ and invalid/ there are no masks (and no error).
  test::write_sintel_tree(dir_ / "plain", {"market_5"}, 1, /*masks=*/false);
  const std::vector<EvalPair> plain = find_sintel(path("plain"));
  ASSERT_EQ(plain.size(), 1u);
  EXPECT_TRUE(plain[0].occlusion_mask.empty());
  EXPECT_TRUE(plain[0].exclude_mask.empty());
}

TEST_F(FlowEvalTest, BrokenSintelTreesNameWhatIsMissing) {
  test::write_sintel_tree(dir_, {"alley_1"}, 2);
  std::string message = error_of([&] { find_sintel(dir_.string(), "albedo"); });
  EXPECT_NE(message.find("'albedo' pass"), std::string::npos) << message;
  EXPECT_NE(error_of([&] { find_sintel(dir_.string(), "../x"); }).find("../x"), std::string::npos);

  fs::remove(path("clean/alley_1/frame_0003.png"));
  message = error_of([&] { find_sintel(dir_.string()); });
  EXPECT_NE(message.find("alley_1/frame_0002"), std::string::npos) << message;
  EXPECT_NE(message.find("frame_0003.png"), std::string::npos) << message;
  EXPECT_EQ(find_sintel(dir_.string(), "final").size(), 2u);

  fs::remove(path("occlusions/alley_1/frame_0001.png"));
  message = error_of([&] { find_sintel(dir_.string(), "final"); });
  EXPECT_NE(message.find("occlusions"), std::string::npos) << message;

  fs::create_directories(path("nothing/flow"));
  fs::create_directories(path("nothing/clean"));
  EXPECT_NE(error_of([&] { find_sintel(path("nothing")); }).find("no Sintel pair"),
            std::string::npos);
  EXPECT_NE(error_of([&] { find_sintel(path("nothing/clean")); }).find("no Sintel tree"),
            std::string::npos);
}

TEST_F(FlowEvalTest, FindsKitti2012And2015PairsWithNoc) {
  test::write_kitti_tree(dir_ / "k12", {7, 0});
  std::ofstream(path("k12/flow_occ/000000_11.png")) << "second frame: not ground truth";
  const std::vector<EvalPair> pairs = find_kitti(path("k12"));
  ASSERT_EQ(pairs.size(), 2u);
  EXPECT_EQ(pairs[0].name, "000000");
  EXPECT_EQ(pairs[0].frame0, path("k12/image_0/000000_10.png"));
  EXPECT_EQ(pairs[0].frame1, path("k12/image_0/000000_11.png"));
  EXPECT_EQ(pairs[0].ground_truth, path("k12/flow_occ/000000_10.png"));
  EXPECT_EQ(pairs[0].noc_ground_truth, path("k12/flow_noc/000000_10.png"));
  EXPECT_TRUE(pairs[0].exclude_mask.empty());
  EXPECT_TRUE(pairs[0].occlusion_mask.empty());
  EXPECT_EQ(pairs[1].name, "000007");

  test::write_kitti_tree(dir_ / "k15/training", {3}, "image_2", /*noc=*/false);
  const std::vector<EvalPair> k15 = find_kitti(path("k15"));
  ASSERT_EQ(k15.size(), 1u);
  EXPECT_EQ(k15[0].frame0, (dir_ / "k15/training/image_2/000003_10.png").string());
  EXPECT_TRUE(k15[0].noc_ground_truth.empty());
}

TEST_F(FlowEvalTest, BrokenKittiTreesNameWhatIsMissing) {
  test::write_kitti_tree(dir_, {0, 1});
  fs::remove(path("image_0/000001_11.png"));
  std::string message = error_of([&] { find_kitti(dir_.string()); });
  EXPECT_NE(message.find("000001_11.png"), std::string::npos) << message;

  test::write_kitti_tree(dir_, {1});
  fs::remove(path("flow_noc/000000_10.png"));
  EXPECT_NE(error_of([&] { find_kitti(dir_.string()); }).find("flow_noc"), std::string::npos);

  fs::create_directories(path("only_noc/flow_noc"));
  fs::create_directories(path("only_noc/image_0"));
  EXPECT_NE(error_of([&] { find_kitti(path("only_noc")); }).find("flow_occ"), std::string::npos);
  fs::create_directories(path("no_images/flow_occ"));
  EXPECT_NE(error_of([&] { find_kitti(path("no_images")); }).find("image_0"), std::string::npos);
  fs::create_directories(path("no_pairs/flow_occ"));
  fs::create_directories(path("no_pairs/image_2"));
  EXPECT_NE(error_of([&] { find_kitti(path("no_pairs")); }).find("no KITTI pair"),
            std::string::npos);
}

TEST_F(FlowEvalTest, FindPairsFiltersBySceneThinsEvenlyAndHonoursTheLayout) {
  test::write_sintel_tree(dir_, {"alley_1", "bamboo_1", "cave_2"}, 4);
  EXPECT_EQ(find_pairs(dir_.string()).size(), 12u);

  FindOptions options;
  options.scene = "bamboo_1";
  const std::vector<EvalPair> bamboo = find_pairs(dir_.string(), options);
  ASSERT_EQ(bamboo.size(), 4u);
  for (const EvalPair& pair : bamboo)
    EXPECT_EQ(pair.name.rfind("bamboo_1/", 0), 0u) << pair.name;

  options.scene.clear();
  options.max_pairs = 3;  // one from each scene, not the first three of alley_1
  const std::vector<EvalPair> three = find_pairs(dir_.string(), options);
  ASSERT_EQ(three.size(), 3u);
  EXPECT_EQ(three[0].name, "alley_1/frame_0001");
  EXPECT_EQ(three[1].name, "bamboo_1/frame_0001");
  EXPECT_EQ(three[2].name, "cave_2/frame_0001");
  options.max_pairs = 50;
  EXPECT_EQ(find_pairs(dir_.string(), options).size(), 12u);

  options.max_pairs = 0;
  options.scene = "ambush_9";
  const std::string message = error_of([&] { find_pairs(dir_.string(), options); });
  EXPECT_NE(message.find("ambush_9"), std::string::npos) << message;
  EXPECT_NE(message.find("alley_1, bamboo_1, cave_2"), std::string::npos) << message;

  options.scene.clear();
  options.max_pairs = -1;
  EXPECT_NE(error_of([&] { find_pairs(dir_.string(), options); }).find("-1"), std::string::npos);

  options.max_pairs = 0;
  options.layout = Layout::Kitti;  // forced: this is no KITTI tree
  EXPECT_NE(error_of([&] { find_pairs(dir_.string(), options); }).find("KITTI"), std::string::npos);
  options.layout = Layout::Middlebury;
  EXPECT_NE(error_of([&] { find_pairs(dir_.string(), options); }).find("no Middlebury sequence"),
            std::string::npos);
}

// See eval_test_trees.hpp for the hand computation of the expected figures.
void expect_hand_case(const EvalRow& row) {
  EXPECT_EQ(row.errors.pixels, test::kHandPixelsAll);
  EXPECT_NEAR(row.errors.epe, test::kHandEpeAll, 1e-6);
  EXPECT_NEAR(row.errors.fl, test::kHandFlAll, 1e-9);
  EXPECT_NEAR(row.errors.r3, 50.0, 1e-9);  // the EPE-5 half
  EXPECT_NEAR(row.errors.r1, 50.0, 1e-9);  // 0.5 is not over 1
  ASSERT_TRUE(row.noc.has_value());
  EXPECT_EQ(row.noc->pixels, test::kHandPixelsNoc);
  EXPECT_NEAR(row.noc->epe, test::kHandEpeNoc, 1e-6);
  EXPECT_NEAR(row.noc->fl, test::kHandFlNoc, 1e-9);
}

TEST_F(FlowEvalTest, SintelEpeMatchesTheHandComputation) {
  test::write_sintel_tree(dir_, {"alley_1"}, 1);
  const std::vector<EvalPair> pairs = find_pairs(dir_.string());
  ASSERT_EQ(pairs.size(), 1u);
  const EvalRow row = evaluate_pair(pairs[0], flow::LkParams::paper());
  expect_hand_case(row);
  EXPECT_FALSE(row.kitti);
}

TEST_F(FlowEvalTest, KittiEpeMatchesTheHandComputation) {
  test::write_kitti_tree(dir_, {4});
  const std::vector<EvalPair> pairs = find_pairs(dir_.string());
  ASSERT_EQ(pairs.size(), 1u);
  const EvalRow row = evaluate_pair(pairs[0], flow::LkParams::paper());
  expect_hand_case(row);
  EXPECT_TRUE(row.kitti);

  // Without flow_noc: the "all" figures only.
  test::write_kitti_tree(dir_ / "occ_only", {4}, "image_2", /*noc=*/false);
  const EvalRow occ = evaluate_pair(find_kitti(path("occ_only"))[0], flow::LkParams::paper());
  EXPECT_NEAR(occ.errors.epe, test::kHandEpeAll, 1e-6);
  EXPECT_FALSE(occ.noc.has_value());
}

TEST_F(FlowEvalTest, KittiGroundTruthMovesTheRightWay) {
  // A textured translation: swapped or mis-signed u/v channels would give an EPE of pixels.
  const eval::Scene scene = eval::make_translation({128, 96}, {2.5f, -1.25f}, 5);
  test::write_png(dir_ / "image_2/000000_10.png", scene.frame0);
  test::write_png(dir_ / "image_2/000000_11.png", scene.frame1);
  fs::create_directories(path("flow_occ"));
  write_kitti_flow(path("flow_occ/000000_10.png"), scene.flow);
  const EvalRow row = evaluate_pair(find_pairs(dir_.string())[0], flow::LkParams::paper());
  EXPECT_EQ(row.errors.pixels, 128 * 96);
  EXPECT_LT(row.errors.epe, 0.1);
  EXPECT_LT(row.errors.fl, 1.0);
}

TEST_F(FlowEvalTest, EvalImagesHoldWhatWasScored) {
  test::write_sintel_tree(dir_, {"alley_1"}, 1);
  EvalImages images;
  const EvalRow row =
      evaluate_pair(find_pairs(dir_.string())[0], flow::LkParams::paper(), nullptr, &images);
  EXPECT_EQ(images.frame0.size(), test::kHandSize);
  EXPECT_EQ(images.frame1.type(), CV_8UC1);
  EXPECT_EQ(cv::norm(images.truth, test::hand_truth(), cv::NORM_INF), 0.0);
  EXPECT_EQ(images.estimate.type(), CV_32FC2);
  ASSERT_EQ(images.scored.type(), CV_8UC1);
  EXPECT_EQ(cv::countNonZero(images.scored), row.errors.pixels);
  EXPECT_EQ(cv::countNonZero(images.scored.rowRange(0, 10)), 0);  // the invalid rows
}

TEST_F(FlowEvalTest, MaskAndNocSizeMismatchesNameTheFile) {
  test::write_sintel_tree(dir_, {"alley_1"}, 1);
  test::write_png(dir_ / "occlusions/alley_1/frame_0001.png", cv::Mat(5, 7, CV_8UC1));
  std::string message =
      error_of([&] { evaluate_pair(find_sintel(dir_.string())[0], flow::LkParams::paper()); });
  EXPECT_NE(message.find("occlusions"), std::string::npos) << message;
  EXPECT_NE(message.find("7x5"), std::string::npos) << message;

  test::write_kitti_tree(dir_ / "k", {0});
  write_kitti_flow(path("k/flow_noc/000000_10.png"), cv::Mat(6, 9, CV_32FC2, cv::Scalar(1, 1)));
  message = error_of([&] { evaluate_pair(find_kitti(path("k"))[0], flow::LkParams::paper()); });
  EXPECT_NE(message.find("flow_noc"), std::string::npos) << message;
  EXPECT_NE(message.find("9x6"), std::string::npos) << message;
}

TEST_F(FlowEvalTest, MeanRowAveragesNocOverTheRowsThatHaveIt) {
  EvalRow a = row("a", 1, 0.1, 2, 0, 10);
  a.noc = errors(2, 0.2, 4, 1, 3);
  a.errors.fl = 6;
  EvalRow b = row("b", 3, 0.3, 4, 1, 30);
  EvalRow c = row("c", 5, 0.5, 6, 2, 50);
  c.noc = errors(4, 0.4, 8, 3, 5);
  c.kitti = true;
  const EvalRow mean = mean_row({a, b, c});
  EXPECT_DOUBLE_EQ(mean.errors.epe, 0.3);
  EXPECT_DOUBLE_EQ(mean.errors.fl, 2.0);
  ASSERT_TRUE(mean.noc.has_value());
  EXPECT_DOUBLE_EQ(mean.noc->epe, 0.3);
  EXPECT_DOUBLE_EQ(mean.noc->fl, 4.0);
  EXPECT_EQ(mean.noc->pixels, 100);
  EXPECT_TRUE(mean.kitti);
  EXPECT_FALSE(mean_row({b}).noc.has_value());
}

TEST_F(FlowEvalTest, ExtendedCsvAppendsFlAndNocColumns) {
  EvalRow a = row("alley_1/frame_0001", 1.23456, 0.123456, 1.005, 0.5, 12.345);
  a.errors.fl = 0.3;
  a.noc = errors(1.5, 0.1, 1, 0.25, 0.126);
  const EvalRow b = row("b", 2, 0.2, 3, 1.5, 20);
  EXPECT_EQ(format_csv({a, b}),
            "sequence,aae_deg,epe,r1,r3,ms,fl,aae_deg_noc,epe_noc,r1_noc,r3_noc,fl_noc\n"
            "alley_1/frame_0001,1.235,0.1235,1.00,0.50,12.35,0.30,1.500,0.1000,1.00,0.25,0.13\n"
            "b,2.000,0.2000,3.00,1.50,20.00,0.00,,,,,\n"
            "mean,1.617,0.1617,2.00,1.00,16.17,0.15,1.500,0.1000,1.00,0.25,0.13\n");
  EvalRow kitti_only = b;
  kitti_only.kitti = true;
  EXPECT_EQ(lines_of(format_csv({kitti_only}))[0],
            "sequence,aae_deg,epe,r1,r3,ms,fl,aae_deg_noc,epe_noc,r1_noc,r3_noc,fl_noc");
}

TEST_F(FlowEvalTest, ExtendedTableAlignsAndShowsADashWithoutNoc) {
  EvalRow a = row("alley_1/frame_0001", 1.5, 0.25, 3, 0.5, 12.5);
  a.errors.fl = 12.5;
  a.noc = errors(1, 0.125, 2, 0.25, 7.25);
  const std::vector<std::string> lines =
      lines_of(format_table({a, row("Urban2", 10.25, 1.5, 20, 5, 130)}));
  ASSERT_EQ(lines.size(), 5u);
  for (const char* header : {"Fl(%)", "EPE-noc", "Fl-noc(%)"})
    EXPECT_NE(lines[0].find(header), std::string::npos) << header;
  for (const std::string& line : lines)
    EXPECT_EQ(line.size(), lines[0].size()) << line;
  const std::size_t noc_end = lines[0].find("EPE-noc") + 7;
  EXPECT_EQ(lines[1].substr(noc_end - 6, 6), "0.1250");
  EXPECT_EQ(lines[2].substr(noc_end - 1, 1), "-");
  EXPECT_EQ(lines[4].substr(noc_end - 6, 6), "0.1250");  // mean over the one row with noc
  EXPECT_LT(lines[0].find("Fl(%)"), lines[0].find("ms"));
}

TEST_F(FlowEvalTest, JsonHoldsFlPixelsAndNoc) {
  EvalRow a = row("a", 1, 0.1, 2, 0, 10);
  a.errors.fl = 6;
  a.noc = errors(2, 0.2, 4, 1, 3);
  const nlohmann::json doc = nlohmann::json::parse(
      format_json({a, row("b", 3, 0.3, 4, 1, 30)}, "paper", flow::LkParams::paper()));
  EXPECT_DOUBLE_EQ(doc["rows"][0]["fl"].get<double>(), 6.0);
  EXPECT_EQ(doc["rows"][0]["pixels"], 100);
  EXPECT_DOUBLE_EQ(doc["rows"][0]["noc"]["epe"].get<double>(), 0.2);
  EXPECT_EQ(doc["rows"][0]["noc"]["pixels"], 50);
  EXPECT_FALSE(doc["rows"][1].contains("noc"));
  EXPECT_DOUBLE_EQ(doc["mean"]["noc"]["fl"].get<double>(), 3.0);
}

}  // namespace
}  // namespace roiflow::eval
