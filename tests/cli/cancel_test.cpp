// SIGINT / SIGTERM during `roiflow track` and `roiflow dense`: the run stops within a second,
// closes what it wrote (a playable video, a log complete up to its last frame), prints and writes
// the summary, and exits with 128 + the signal (130 / 143).
//
// The binary runs as a child process (posix_spawn) on a long image sequence: hard links to a
// few rendered frames, so that thousands of frames cost nothing to create.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/videoio.hpp>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "eval/track_log.hpp"
#include "eval/tracking_scene.hpp"
#include "test_util.hpp"

namespace {

namespace fs = std::filesystem;
using namespace roiflow;
using test::lines_of;
using test::read_text;
using Clock = std::chrono::steady_clock;

struct Exit {
  int code = -1;       // exit status, or -1 when killed by a signal
  int signal = 0;      // the signal that killed it
  double stop_s = -1;  // from the signal sent to the exit
  bool timed_out = false;
};

class CancelTest : public test::TempDirTest {
 protected:
  static constexpr int kDistinct = 24;  // rendered frames, played forwards then backwards
  static constexpr int kFrames = 6000;  // links in the sequence: far more than a test waits for

  void SetUp() override {
    TempDirTest::SetUp();
    eval::TrackingSceneParams params;
    params.size = {320, 240};
    params.frames = kDistinct;
    params.object = {40.f, 28.f};
    const eval::TrackingScene scene(params);
    fs::create_directories(path("seq"));
    for (int i = 0; i < kDistinct; ++i) {
      ASSERT_TRUE(cv::imwrite(path("render_" + std::to_string(i) + ".png"), scene.render(i)));
    }
    for (int k = 0; k < kFrames; ++k) {
      const int cycle = k % (2 * kDistinct);
      const int i = cycle < kDistinct ? cycle : 2 * kDistinct - 1 - cycle;
      char name[32];
      std::snprintf(name, sizeof name, "%05d.png", k + 1);
      fs::create_hard_link(path("render_" + std::to_string(i) + ".png"), dir_ / "seq" / name);
    }
    const cv::Rect2f b = scene.box(0);
    init_ = std::to_string(b.x) + "," + std::to_string(b.y) + "," + std::to_string(b.width) + "," +
            std::to_string(b.height);
  }

  // Starts the CLI with stdout and stderr going to files.
  pid_t spawn(const std::vector<std::string>& args) const {
    return test::spawn_cli(args, path("stdout.txt"), path("stderr.txt"));
  }

  // Waits (up to `limit_s`) until `ready` holds or the child has exited; false when it exited.
  template <class Ready>
  static bool wait_until(pid_t pid, Ready ready, double limit_s) {
    const auto start = Clock::now();
    while (std::chrono::duration<double>(Clock::now() - start).count() < limit_s) {
      if (ready()) return true;
      int status = 0;
      if (waitpid(pid, &status, WNOHANG) == pid) return false;
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    return ready();
  }

  // Sends `sig` and waits for the exit (SIGKILL after 20 s, reported as timed_out).
  static Exit stop(pid_t pid, int sig) {
    Exit e;
    const auto sent = Clock::now();
    kill(pid, sig);
    int status = 0;
    while (waitpid(pid, &status, WNOHANG) != pid) {
      if (std::chrono::duration<double>(Clock::now() - sent).count() > 20) {
        e.timed_out = true;
        kill(pid, SIGKILL);
        waitpid(pid, &status, 0);
        break;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
    e.stop_s = std::chrono::duration<double>(Clock::now() - sent).count();
    if (WIFEXITED(status)) e.code = WEXITSTATUS(status);
    if (WIFSIGNALED(status)) e.signal = WTERMSIG(status);
    return e;
  }

  // Rows in the CSV log so far (complete lines after the header).
  long long log_rows() const {
    std::ifstream in(path("l.csv"));
    long long lines = 0;
    for (std::string line; std::getline(in, line);)
      ++lines;
    return lines > 0 ? lines - 1 : 0;
  }

  // The video plays: it opens and yields frames of the input's size. Returns how many.
  long long check_video(const std::string& video) const {
    cv::VideoCapture capture(video, cv::CAP_FFMPEG);
    EXPECT_TRUE(capture.isOpened()) << video;
    long long frames = 0;
    cv::Mat frame;
    while (capture.read(frame)) {
      EXPECT_EQ(frame.size(), cv::Size(320, 240));
      ++frames;
    }
    EXPECT_GT(frames, 0) << video;
    return frames;
  }

  void track_and_interrupt(int sig) {
    const pid_t pid =
        spawn({"track", path("seq"), "--init", init_, "--log", path("l.csv"), "--out",
               path("v.avi"), "--summary", path("s.json"), "--no-progress", "--threads", "2"});
    ASSERT_GT(pid, 0);
    const bool running = wait_until(
        pid, [&] { return log_rows() >= 20; }, 30);
    if (!running) {
      stop(pid, SIGKILL);
      FAIL() << "track ended or wrote no rows before the signal: " << read_text(path("stderr.txt"));
    }
    const Exit e = stop(pid, sig);
    std::printf("track: %s stopped the run in %.3f s after %lld logged frames\n",
                sig == SIGINT ? "SIGINT" : "SIGTERM", e.stop_s, log_rows());
    ASSERT_FALSE(e.timed_out) << "track did not stop within 20 s";
    EXPECT_EQ(e.signal, 0) << "killed by signal " << e.signal;
    EXPECT_EQ(e.code, 128 + sig) << read_text(path("stderr.txt"));
    EXPECT_LT(e.stop_s, 5.0);  // the contract is one second; generous for loaded machines

    // The log: the header, then frames 1..N in order, every line complete.
    const std::string text = read_text(path("l.csv"));
    ASSERT_FALSE(text.empty());
    EXPECT_EQ(text.back(), '\n') << "the last line is torn";
    const std::vector<eval::TrackRecord> log = eval::read_track_csv(path("l.csv"));
    ASSERT_GE(log.size(), 20u);
    EXPECT_LT(log.size(), static_cast<std::size_t>(kFrames)) << "the run was not cut short";
    for (std::size_t i = 0; i < log.size(); ++i)
      ASSERT_EQ(log[i].frame, static_cast<long long>(i) + 1);

    // The summary: written, printed, and counting the frames the log holds.
    const auto summary = nlohmann::json::parse(read_text(path("s.json")));
    EXPECT_EQ(summary.at("frames").get<long long>(), static_cast<long long>(log.size()));
    EXPECT_NE(summary.at("status").get<std::string>().find("interrupted"), std::string::npos);
    const std::string out = read_text(path("stdout.txt"));
    EXPECT_NE(out.find(std::to_string(log.size()) + " frames"), std::string::npos) << out;
    const std::vector<std::string> err = lines_of(read_text(path("stderr.txt")));
    ASSERT_EQ(err.size(), 1u) << read_text(path("stderr.txt"));
    EXPECT_NE(err[0].find(sig == SIGINT ? "SIGINT" : "SIGTERM"), std::string::npos) << err[0];

    // The video: playable, one annotated frame per logged frame.
    EXPECT_EQ(check_video(path("v.avi")), static_cast<long long>(log.size()));
  }

  std::string init_;
};

TEST_F(CancelTest, SigintStopsTrackWithCompleteOutputsAndExitCode130) {
  track_and_interrupt(SIGINT);
}

TEST_F(CancelTest, SigtermStopsTrackWithCompleteOutputsAndExitCode143) {
  track_and_interrupt(SIGTERM);
}

TEST_F(CancelTest, SigintStopsDenseWithAPlayableVideoAndExitCode130) {
  const pid_t pid = spawn({"dense", path("seq"), "--out", path("d.avi"), "--summary",
                           path("d.json"), "--no-progress", "--threads", "2"});
  ASSERT_GT(pid, 0);
  // Started writing: the video holds some frames' worth of bytes.
  const bool running = wait_until(
      pid,
      [&] {
        std::error_code ec;
        const auto size = fs::file_size(path("d.avi"), ec);
        return !ec && size > 100000;
      },
      30);
  if (!running) {
    stop(pid, SIGKILL);
    FAIL() << "dense ended or wrote nothing before the signal: " << read_text(path("stderr.txt"));
  }
  const Exit e = stop(pid, SIGINT);
  std::printf("dense: SIGINT stopped the run in %.3f s\n", e.stop_s);
  ASSERT_FALSE(e.timed_out) << "dense did not stop within 20 s";
  EXPECT_EQ(e.signal, 0) << "killed by signal " << e.signal;
  EXPECT_EQ(e.code, 130) << read_text(path("stderr.txt"));
  EXPECT_LT(e.stop_s, 5.0);

  const auto summary = nlohmann::json::parse(read_text(path("d.json")));
  const long long pairs = summary.at("pairs").get<long long>();
  EXPECT_GT(pairs, 0);
  EXPECT_LT(pairs, kFrames - 1) << "the run was not cut short";
  EXPECT_NE(summary.at("status").get<std::string>().find("interrupted"), std::string::npos);
  const std::string out = read_text(path("stdout.txt"));
  EXPECT_NE(out.find(std::to_string(pairs) + " pairs"), std::string::npos) << out;
  const std::vector<std::string> err = lines_of(read_text(path("stderr.txt")));
  ASSERT_EQ(err.size(), 1u) << read_text(path("stderr.txt"));
  EXPECT_NE(err[0].find("SIGINT"), std::string::npos) << err[0];
  EXPECT_EQ(check_video(path("d.avi")), pairs);
}

}  // namespace
