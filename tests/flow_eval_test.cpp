#include "stages/flow_eval.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <functional>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "flow/error.hpp"
#include "flow/flo_io.hpp"
#include "flow/synthetic.hpp"
#include "test_util.hpp"

namespace roiflow::stages {
namespace {

namespace fs = std::filesystem;

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

std::vector<std::string> lines_of(const std::string& text) {
  std::vector<std::string> lines;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);)
    lines.push_back(line);
  return lines;
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

class FlowEvalTest : public test::TempDirTest {
 protected:
  void write_image(const std::string& relative, const cv::Mat& image) const {
    fs::create_directories(fs::path(path(relative)).parent_path());
    ASSERT_TRUE(cv::imwrite(path(relative), image));
  }

  // DIR/<name>/frame10.png, frame11.png, flow10.flo from a small synthetic translation.
  flow::Scene write_sequence(const std::string& name, bool with_flow = true) const {
    const flow::Scene scene = flow::make_translation({96, 64}, {1.3f, -0.7f});
    write_image(name + "/frame10.png", scene.frame0);
    write_image(name + "/frame11.png", scene.frame1);
    if (with_flow) flow::write_flo(path(name + "/flow10.flo"), scene.flow);
    return scene;
  }

  EvalPair translation_pair(cv::Size size) const {
    const flow::Scene scene = flow::make_translation(size, {1.3f, -0.7f}, 3);
    write_image("a.png", scene.frame0);
    write_image("b.png", scene.frame1);
    flow::write_flo(path("gt.flo"), scene.flow);
    return {"translation", path("a.png"), path("b.png"), path("gt.flo"), ""};
  }
};

TEST_F(FlowEvalTest, FindsCompleteSequencesSortedPreferringGray) {
  write_sequence("Venus");
  const flow::Scene dimetrodon = write_sequence("Dimetrodon");
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

  flow::write_flo(path("small.flo"), cv::Mat(60, 80, CV_32FC2, cv::Scalar(0, 0)));
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

}  // namespace
}  // namespace roiflow::stages
