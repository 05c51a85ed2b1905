// roiflow, the command-line tool: one subcommand per apps/<name>_command.cpp. A failure prints
// one line, `roiflow: error: <message>`, on stderr: exit code 2 for a bad command line (UsageError
// included), 1 at run time. Outputs are checked before any work and written atomically.
#include <CLI/CLI.hpp>
#include <cstdlib>
#include <iostream>
#include <opencv2/core/utils/logger.hpp>
#include <string>

#include "cli_common.hpp"

using namespace roiflow;

namespace {

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
  // One error line: OpenCV's and FFmpeg's own diagnostics would add lines of their own, and
  // every failure they describe reaches the user as roiflow's error anyway.
  setenv("OPENCV_FFMPEG_LOGLEVEL", "-8", 0);  // AV_LOG_QUIET, unless the user set it
  cv::utils::logging::setLogLevel(cv::utils::logging::LOG_LEVEL_ERROR);
  CLI::App app{"roiflow: realtime dense and local Lucas-Kanade optical flow", "roiflow"};
  app.require_subcommand(1);
  int exit_code = 0;  // a video run's; parse and run-time failures are caught below
  using namespace roiflow::cli;
  for (auto add : {add_flow_command, add_eval_command, add_score_command, add_track_command,
                   add_dense_command, add_demo_command, add_sweep_command, add_scaling_command,
                   add_benchmark_command, add_batch_command, add_motion_check_command})
    add(app, exit_code);
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
