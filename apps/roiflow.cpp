// roiflow — the command-line tool, one git-style subcommand per job.
//
//   roiflow flow --synthetic -o out.flo --color out.png
//   roiflow flow A.png B.png -o out.flo --gt truth.flo
//   roiflow eval data/middlebury --format csv -o errors.csv
//   roiflow eval data/sintel/training --pass final --max-pairs 50 --report sintel.html
//   roiflow score track.csv Car4/groundtruth_rect.txt --format json
//   roiflow score --mot mot.txt PETS09-S2L1/gt/gt.txt --format json
//
// Each subcommand is a thin layer: CLI11 parses, the library computes, this file prints.
// Failures print one line, `roiflow: error: <message>`, on stderr: exit code 2 for a bad
// command line (including out-of-range LK parameters), 1 for anything that fails at run time.
// Inputs and output locations are checked before any computation, and every output is written
// atomically, so a failed run leaves no file behind.
#include <CLI/CLI.hpp>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <nlohmann/json.hpp>
#include <opencv2/core/utils/logger.hpp>
#include <opencv2/imgcodecs.hpp>
#include <optional>
#include <string>
#include <vector>

#include "cli_common.hpp"
#include "core/atomic_write.hpp"
#include "core/error.hpp"
#include "eval/flo_io.hpp"
#include "eval/flow_eval.hpp"
#include "eval/otb_score.hpp"
#include "eval/synthetic.hpp"
#include "eval/track_log.hpp"
#include "flow/color_code.hpp"
#include "flow/dense_lk.hpp"
#include "flow/metrics.hpp"
#include "flow/pyramid.hpp"
#include "pipeline/tbb_executor.hpp"
#include "report/html_report.hpp"
#include "stages/video_source.hpp"

namespace {

using namespace roiflow;
using namespace roiflow::cli;

const cv::Size kSyntheticSize{640, 480};
constexpr eval::SceneKind kSceneKinds[] = {eval::SceneKind::Translation, eval::SceneKind::Rotation,
                                           eval::SceneKind::Zoom, eval::SceneKind::NonRigid,
                                           eval::SceneKind::MovingObject};

// ---------------------------------------------------------------------------------------------
// roiflow flow

struct FlowCommand {
  LkOptions lk;
  std::string frame0;
  std::string frame1;
  std::string scene;  // set by --synthetic
  std::string output;
  std::string color;
  std::string legend;
  std::string ground_truth;
};

eval::SceneKind scene_kind(const std::string& name) {
  for (eval::SceneKind kind : kSceneKinds) {
    if (name == eval::to_string(kind)) return kind;
  }
  throw UsageError("unknown synthetic scene '" + name + "'");
}

void run_flow(const FlowCommand& cmd) {
  const flow::LkParams params = lk_params(cmd.lk);
  const bool synthetic = !cmd.scene.empty();
  if (synthetic && !cmd.frame0.empty()) {
    throw UsageError("give either two images A B or --synthetic, not both");
  }
  if (synthetic && !cmd.ground_truth.empty()) {
    throw UsageError("--gt: a --synthetic scene brings its own ground truth");
  }
  if (!synthetic && cmd.frame1.empty()) {
    throw UsageError("flow needs two images A B, or --synthetic [scene]");
  }
  check_output_path(cmd.output, "-o");
  if (!cmd.color.empty()) check_image_output(cmd.color, "--color");
  if (!cmd.legend.empty()) check_image_output(cmd.legend, "--legend");

  cv::Mat frame0, frame1, truth;
  std::string source;
  if (synthetic) {
    eval::Scene scene = eval::make_scene(scene_kind(cmd.scene), kSyntheticSize);
    frame0 = scene.frame0;
    frame1 = scene.frame1;
    truth = scene.flow;
    source = "synthetic " + cmd.scene;
  } else {
    for (const std::string& image : {cmd.frame0, cmd.frame1}) {
      std::error_code ec;
      if (std::filesystem::is_directory(image, ec))
        throw Error("image '" + image + "' is a directory, not an image file");
    }
    frame0 = eval::read_gray(cmd.frame0);
    eval::check_frame_size(frame0.size(), "image '" + cmd.frame0 + "'");
    frame1 = eval::read_gray(cmd.frame1);
    eval::check_frame_size(frame1.size(), "image '" + cmd.frame1 + "'");
    if (frame0.size() != frame1.size()) {
      throw Error("'" + cmd.frame0 + "' is " + size_string(frame0.size()) + " but '" + cmd.frame1 +
                  "' is " + size_string(frame1.size()));
    }
    if (!cmd.ground_truth.empty()) {
      truth = eval::read_flo(cmd.ground_truth);
      if (truth.size() != frame0.size()) {
        throw Error("--gt: '" + cmd.ground_truth + "' is " + size_string(truth.size()) + " but '" +
                    cmd.frame0 + "' is " + size_string(frame0.size()));
      }
    }
    source = cmd.frame0 + " -> " + cmd.frame1;
  }

  const pipeline::TbbExecutor executor;
  flow::FlowOptions options;
  const auto start = std::chrono::steady_clock::now();
  const flow::FlowResult result = pipeline::run_with_threads(
      cmd.lk.threads, [&] { return flow::dense_flow(frame0, frame1, params, options, &executor); });
  const double ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  // Scored before writing so that a failure here leaves no output behind.
  std::optional<flow::FlowErrors> errors;
  if (!truth.empty()) {
    errors = flow::flow_errors(result.flow, truth);
    if (errors->pixels == 0) throw Error("--gt: '" + cmd.ground_truth + "' is unknown everywhere");
  }

  std::string written = cmd.output;
  eval::write_flo(cmd.output, result.flow);
  if (!cmd.color.empty()) {
    // Against a ground truth, the truth's largest vector saturates, so the two pictures compare.
    const float scale = truth.empty() ? -1.f : flow::max_magnitude(truth);
    eval::write_image_atomically(cmd.color, flow::flow_to_color(result.flow, scale));
    written += ", " + cmd.color;
  }
  if (!cmd.legend.empty()) {
    eval::write_image_atomically(cmd.legend, flow::color_wheel_legend());
    written += ", " + cmd.legend;
  }

  std::cout << "flow " << size_string(frame0.size()) << " (" << source << "): " << fixed(ms, 2)
            << " ms, wrote " << written << "\n";
  if (errors) std::cout << "error vs ground truth: " << errors_line(*errors) << "\n";
}

void add_flow_command(CLI::App& app, FlowCommand& cmd) {
  CLI::App* sub = app.add_subcommand(
      "flow", "Dense flow of one image pair (or a built-in synthetic pair) to a .flo file");
  sub->add_option("A", cmd.frame0, "frame t (read as 8-bit gray)")->type_name("IMAGE");
  sub->add_option("B", cmd.frame1, "frame t+1")->type_name("IMAGE");
  std::vector<std::string> scenes;
  for (eval::SceneKind kind : kSceneKinds)
    scenes.emplace_back(eval::to_string(kind));
  sub->add_option("--synthetic", cmd.scene,
                  "use a built-in " + size_string(kSyntheticSize) +
                      " pair with exact ground truth instead of A B, and print the error")
      ->type_name("SCENE")
      ->expected(0, 1)
      ->default_str(eval::to_string(eval::SceneKind::MovingObject))
      ->check(CLI::IsMember(scenes));
  sub->add_option("-o,--output", cmd.output, "the flow, Middlebury .flo")
      ->type_name("FLO")
      ->required();
  sub->add_option("--color", cmd.color,
                  "the flow in Middlebury colour coding, saturated at the 99th percentile of its "
                  "magnitudes (with --gt: at the truth's largest)")
      ->type_name("IMAGE");
  sub->add_option("--legend", cmd.legend, "the colour wheel, as a legend")->type_name("IMAGE");
  sub->add_option("--gt", cmd.ground_truth, "ground-truth flow: print the error against it")
      ->type_name("FLO");
  add_lk_options(*sub, cmd.lk);
  sub->callback([&cmd] { run_flow(cmd); });
}

// ---------------------------------------------------------------------------------------------
// roiflow eval

struct EvalCommand {
  LkOptions lk;
  std::string dir;
  std::vector<std::vector<std::string>> pairs;  // A, B, ground truth
  std::vector<std::string> exclude_masks;
  std::string layout = "auto";
  std::string pass = "auto";
  std::string scene;
  int max_pairs = 0;
  std::string format = "table";
  std::string output;
  std::string report;
};

// `skipped` receives what a partial tree lacks (see eval::find_pairs).
std::vector<eval::EvalPair> eval_pairs(const EvalCommand& cmd, std::vector<std::string>& skipped) {
  if (cmd.dir.empty() && cmd.pairs.empty()) {
    throw UsageError(
        "eval needs a Middlebury, Sintel or KITTI directory DIR or at least one --pair A B GT");
  }
  if (!cmd.dir.empty()) {
    eval::FindOptions options;
    options.layout = eval::parse_layout(cmd.layout);
    options.pass = cmd.pass;
    options.scene = cmd.scene;
    options.max_pairs = cmd.max_pairs;
    return eval::find_pairs(cmd.dir, options, &skipped);
  }
  if (!cmd.exclude_masks.empty() && cmd.exclude_masks.size() != cmd.pairs.size()) {
    throw UsageError("--exclude-mask: got " + std::to_string(cmd.exclude_masks.size()) +
                     " masks for " + std::to_string(cmd.pairs.size()) +
                     " pairs (give one per --pair, in the same order)");
  }
  std::vector<eval::EvalPair> pairs;
  for (std::size_t i = 0; i < cmd.pairs.size(); ++i) {
    const std::vector<std::string>& p = cmd.pairs[i];
    pairs.push_back({"pair" + std::to_string(i + 1), p.at(0), p.at(1), p.at(2),
                     cmd.exclude_masks.empty() ? "" : cmd.exclude_masks[i]});
  }
  return pairs;
}

void run_eval(const EvalCommand& cmd) {
  const flow::LkParams params = lk_params(cmd.lk);
  if (!cmd.output.empty()) check_output_path(cmd.output, "-o");
  if (!cmd.report.empty()) check_output_path(cmd.report, "--report");
  std::vector<std::string> skipped;
  const std::vector<eval::EvalPair> pairs = eval_pairs(cmd, skipped);
  // Partial downloads are evaluated as they are, and the gaps said once, on stderr so that
  // CSV and JSON on stdout stay machine-readable.
  if (!skipped.empty()) std::cerr << "roiflow: " << eval::skipped_line(skipped) << "\n";

  std::optional<report::HtmlReport> report;
  if (!cmd.report.empty()) {
    report.emplace("roiflow eval " + (cmd.dir.empty() ? std::string("--pair") : cmd.dir),
                   cmd.lk.preset, params);
  }
  const pipeline::TbbExecutor executor;
  std::vector<eval::EvalRow> rows;
  pipeline::run_with_threads(cmd.lk.threads, [&] {
    for (const eval::EvalPair& pair : pairs) {
      eval::EvalImages images;
      rows.push_back(eval::evaluate_pair(pair, params, &executor, report ? &images : nullptr));
      if (report) report->add(rows.back(), images);
    }
  });

  std::string text;
  if (cmd.format == "csv") {
    text = eval::format_csv(rows);
  } else if (cmd.format == "json") {
    text = eval::format_json(rows, cmd.lk.preset, params);
  } else {
    text = eval::format_table(rows);
  }
  if (report) report->write(cmd.report);
  if (cmd.output.empty()) {
    std::cout << text;
  } else {
    write_text_atomically(cmd.output, text);
    std::cout << "evaluated " << rows.size() << " pairs, wrote " << cmd.output << "\n";
  }
  if (report) std::cout << "wrote report " << cmd.report << "\n";
}

void add_eval_command(CLI::App& app, EvalCommand& cmd) {
  CLI::App* sub = app.add_subcommand(
      "eval",
      "Dense flow error (AAE, EPE, R1, R3, KITTI Fl) and time over pairs with ground truth");
  CLI::Option* dir =
      sub->add_option(
             "DIR", cmd.dir,
             "Middlebury (DIR/<seq>/frame10.png, frame11.png, flow10.flo), MPI-Sintel "
             "(flow/ with clean/ or final/) or KITTI (image_0/ or image_2/ with flow_occ/) "
             "tree; found by its layout")
          ->type_name("DIR");
  CLI::Option* pair =
      sub->add_option("--pair", cmd.pairs,
                      "an image pair and its ground truth (.flo, or KITTI 16-bit .png); repeatable")
          ->type_name("A B GT")
          ->type_size(3)
          ->allow_extra_args(false);
  sub->add_option("--exclude-mask", cmd.exclude_masks,
                  "pixels not scored (non-zero) for each --pair, in the same order")
      ->type_name("IMAGE")
      ->needs(pair);
  dir->excludes(pair);
  sub->add_option("--layout", cmd.layout, "layout of DIR (auto: found from its folders)")
      ->type_name("LAYOUT")
      ->check(CLI::IsMember({"auto", "middlebury", "sintel", "kitti"}))
      ->capture_default_str()
      ->needs(dir);
  sub->add_option("--pass", cmd.pass,
                  "Sintel rendering pass (auto: per scene, the first of clean, final, albedo "
                  "that the tree has; the pass shows in each row's name)")
      ->type_name("PASS")
      ->check(CLI::IsMember({"auto", "clean", "final", "albedo"}))
      ->capture_default_str()
      ->needs(dir);
  sub->add_option("--scene", cmd.scene,
                  "only this scene of DIR (Sintel alley_1, Middlebury Venus, KITTI 000042)")
      ->type_name("NAME")
      ->needs(dir);
  sub->add_option("--max-pairs", cmd.max_pairs,
                  "at most N pairs of DIR, evenly spaced over the sorted list (0: all)")
      ->type_name("N")
      ->check(CLI::NonNegativeNumber)
      ->needs(dir);
  sub->add_option("--format", cmd.format, "output format")
      ->type_name("FORMAT")
      ->check(CLI::IsMember({"table", "csv", "json"}))
      ->capture_default_str();
  sub->add_option("-o,--output", cmd.output, "write the results to FILE instead of stdout")
      ->type_name("FILE");
  sub->add_option("--report", cmd.report,
                  "also write a self-contained HTML report (frames, colour-coded flows, error "
                  "maps, metrics per pair)")
      ->type_name("HTML");
  add_lk_options(*sub, cmd.lk);
  sub->callback([&cmd] { run_eval(cmd); });
}

// ---------------------------------------------------------------------------------------------
// roiflow score

struct ScoreCommand {
  std::string track;
  std::string ground_truth;
  std::string format = "table";
  bool mot = false;
};

void run_score(const ScoreCommand& cmd) {
  if (cmd.mot) return print_mot_score(cmd.track, cmd.ground_truth, cmd.format);
  const std::vector<eval::TrackRecord> records = eval::read_track_csv(cmd.track);
  std::vector<cv::Rect2f> track;
  try {
    track = eval::track_boxes(records);
  } catch (const Error& e) {
    // track_boxes knows records, not the file they came from.
    throw Error("track log '" + cmd.track + "': " + e.what());
  }
  const std::vector<cv::Rect2f> truth = eval::read_ground_truth(cmd.ground_truth);
  const eval::OtbScore s = eval::score(track, truth);

  if (cmd.format == "json") {
    const nlohmann::ordered_json doc = {{"auc", s.auc},
                                        {"precision20", s.precision20},
                                        {"mean_iou", s.mean_iou},
                                        {"frames", s.frames}};
    std::cout << doc.dump(2) << "\n";
    return;
  }
  // The lengths are shown because a shorter track (--max-frames) scores only its prefix.
  std::cout << "success AUC    " << fixed(s.auc, 4) << "\n"
            << "precision@20   " << fixed(s.precision20, 4) << "\n"
            << "mean IoU       " << fixed(s.mean_iou, 4) << "\n"
            << "frames         " << s.frames << " (track " << track.size() << ", ground truth "
            << truth.size() << ")\n";
}

void add_score_command(CLI::App& app, ScoreCommand& cmd) {
  CLI::App* sub =
      app.add_subcommand("score", "OTB one-pass metrics of a track log against ground-truth boxes");
  sub->add_option("TRACK", cmd.track, "track log written by roiflow track (CSV)")
      ->type_name("CSV")
      ->required();
  sub->add_option("GROUNDTRUTH", cmd.ground_truth,
                  "one box x,y,w,h per frame, separated by commas, tabs or spaces")
      ->type_name("TXT")
      ->required();
  sub->add_option("--format", cmd.format, "output format")
      ->type_name("FORMAT")
      ->check(CLI::IsMember({"table", "json"}))
      ->capture_default_str();
  sub->add_flag("--mot", cmd.mot,
                "multi-object: TRACK and GROUNDTRUTH are MOTChallenge files (GROUNDTRUTH may be "
                "synthetic:N[:WxH]:OBJECTS); CLEAR-MOT and IDF1");
  sub->callback([&cmd] { run_score(cmd); });
}

// ---------------------------------------------------------------------------------------------

// OpenCV's messages span lines; the CLI promises one.
std::string one_line(std::string text) {
  for (char& c : text) {
    if (c == '\n' || c == '\r') c = ' ';
  }
  while (!text.empty() && text.back() == ' ')
    text.pop_back();
  return text;
}

int report_error(const std::string& message, int exit_code) {
  std::cerr << "roiflow: error: " << one_line(message) << "\n";
  return exit_code;
}

// Points at the help of the subcommand the user was typing, when CLI11 got that far.
int report_usage(const CLI::App& app, const std::string& message) {
  std::string command = "roiflow";
  for (const CLI::App* sub : app.get_subcommands())
    command += " " + sub->get_name();
  return report_error(message + " (see '" + command + " --help')", 2);
}

}  // namespace

int main(int argc, char** argv) {
  // The CLI promises one error line: OpenCV's and FFmpeg's own diagnostics (decoder complaints
  // about a damaged file, backends that cannot open a camera) would add lines of their own, and
  // every failure they describe reaches the user as roiflow's error anyway.
  setenv("OPENCV_FFMPEG_LOGLEVEL", "-8", 0);  // AV_LOG_QUIET, unless the user set it
  cv::utils::logging::setLogLevel(cv::utils::logging::LOG_LEVEL_ERROR);
  CLI::App app{"roiflow: realtime dense and local Lucas-Kanade optical flow", "roiflow"};
  app.require_subcommand(1);
  FlowCommand flow_cmd;
  EvalCommand eval_cmd;
  ScoreCommand score_cmd;
  add_flow_command(app, flow_cmd);
  add_eval_command(app, eval_cmd);
  add_score_command(app, score_cmd);
  int exit_code = 0;
  add_video_commands(app, exit_code);
  add_sweep_command(app);
  add_scaling_command(app);
  add_benchmark_command(app);
  add_batch_command(app, exit_code);
  add_motion_check_command(app, exit_code);

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    // --help and --help-all are "errors" with exit code 0 that print the help.
    if (e.get_exit_code() == static_cast<int>(CLI::ExitCodes::Success)) return app.exit(e);
    return report_usage(app, e.what());
  } catch (const UsageError& e) {
    return report_usage(app, e.what());
  } catch (const cv::Exception& e) {
    return report_error("OpenCV: " + e.err, 1);
  } catch (const std::exception& e) {
    return report_error(e.what(), 1);
  } catch (...) {
    return report_error("unexpected failure", 1);
  }
  return exit_code;
}
