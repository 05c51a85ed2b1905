// The bad-input table, one test per row, through the roiflow binary: every row ends in a
// one-line `roiflow: error: ...` naming the problem and a non-zero exit (or in a documented
// outcome with exit 0), never in a signal or a hang, and whatever the run had already written
// (track log, summary, annotated video) stays complete and readable.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <memory>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/videoio.hpp>
#include <random>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "eval/synthetic.hpp"
#include "eval/track_log.hpp"
#include "eval/tracking_scene.hpp"
#include "test_util.hpp"

namespace {

namespace fs = std::filesystem;
using namespace roiflow;
using test::lines_of;
using test::read_text;

// Generous: every row takes well under a second in a release build, a few under ASan.
constexpr std::chrono::seconds kTimeout(60);

struct Outcome {
  bool timed_out = false;
  int signal = 0;  // the signal that ended the process, 0 if it exited
  int exit_code = -1;
  std::string out;
  std::string err;
};

std::string shown(const std::vector<std::string>& args) {
  std::string text = "roiflow";
  for (const std::string& arg : args)
    text += " " + arg;
  return text;
}

class BadInputTest : public test::TempDirTest {
 protected:
  // Runs the CLI with `args`; killed (and reported as timed out) after kTimeout.
  Outcome run(const std::vector<std::string>& args) const {
    const std::string out_path = path("stdout.txt"), err_path = path("stderr.txt");
    int spawned = 0;
    const pid_t pid = test::spawn_cli(args, out_path, err_path, &spawned);
    Outcome outcome;
    if (pid < 0) {
      ADD_FAILURE() << "cannot start " << ROIFLOW_CLI_PATH << ": " << std::strerror(spawned);
      return outcome;
    }
    const auto deadline = std::chrono::steady_clock::now() + kTimeout;
    int status = 0;
    while (waitpid(pid, &status, WNOHANG) == 0) {
      if (std::chrono::steady_clock::now() > deadline) {
        kill(pid, SIGKILL);
        waitpid(pid, &status, 0);
        outcome.timed_out = true;
        break;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
    if (WIFSIGNALED(status)) outcome.signal = WTERMSIG(status);
    if (WIFEXITED(status)) outcome.exit_code = WEXITSTATUS(status);
    outcome.out = read_text(out_path);
    outcome.err = read_text(err_path);
    return outcome;
  }

  // The command fails with exit code `exit_code` and one error line holding `expected`.
  Outcome expect_error(const std::vector<std::string>& args, int exit_code,
                       const std::string& expected) const {
    SCOPED_TRACE(shown(args));
    const Outcome r = run(args);
    EXPECT_FALSE(r.timed_out) << "hung";
    EXPECT_EQ(r.signal, 0) << "killed by signal " << r.signal << "\n" << r.err;
    EXPECT_EQ(r.exit_code, exit_code) << r.err;
    const std::vector<std::string> lines = lines_of(r.err);
    EXPECT_EQ(lines.size(), 1u) << r.err;
    EXPECT_EQ(r.err.rfind("roiflow: error: ", 0), 0u) << r.err;
    EXPECT_NE(r.err.find(expected), std::string::npos) << "expected '" << expected << "' in\n"
                                                       << r.err;
    return r;
  }

  // The command succeeds quietly.
  Outcome expect_success(const std::vector<std::string>& args) const {
    SCOPED_TRACE(shown(args));
    const Outcome r = run(args);
    EXPECT_FALSE(r.timed_out) << "hung";
    EXPECT_EQ(r.signal, 0) << "killed by signal " << r.signal;
    EXPECT_EQ(r.exit_code, 0) << r.err;
    EXPECT_TRUE(r.err.empty()) << r.err;
    return r;
  }

  void write_bytes(const std::string& relative, const std::string& bytes) const {
    fs::create_directories(fs::path(path(relative)).parent_path());
    std::ofstream(path(relative), std::ios::binary) << bytes;
  }

  void write_image(const std::string& relative, const cv::Mat& image) const {
    fs::create_directories(fs::path(path(relative)).parent_path());
    ASSERT_TRUE(cv::imwrite(path(relative), image)) << relative;
  }

  // A translated textured pair of `size` as a.png, b.png.
  void write_pair(cv::Size size = {96, 64}) const {
    const eval::Scene scene = eval::make_translation(size, {1.3f, -0.7f});
    write_image("a.png", scene.frame0);
    write_image("b.png", scene.frame1);
  }

  // The demo's scene at 160x120, `frames` long.
  eval::TrackingScene scene(int frames = 20) const {
    eval::TrackingSceneParams params;
    params.size = {160, 120};
    params.frames = frames;
    params.object = {28.f, 18.f};
    params.jump = 10.0;
    return eval::TrackingScene(params);
  }

  // The scene as an MJPG .avi.
  void write_video(const std::string& relative, int frames = 20) const {
    const eval::TrackingScene s = scene(frames);
    cv::VideoWriter writer(path(relative), cv::CAP_FFMPEG,
                           cv::VideoWriter::fourcc('M', 'J', 'P', 'G'), 25.0, s.size());
    ASSERT_TRUE(writer.isOpened());
    for (int i = 0; i < s.frames(); ++i)
      writer.write(s.render(i));
  }

  // The scene as DIR/0001.png, 0002.png, ...
  void write_sequence(const std::string& dir, int frames = 12) const {
    const eval::TrackingScene s = scene(frames);
    for (int i = 0; i < s.frames(); ++i) {
      char name[32];
      std::snprintf(name, sizeof name, "/%04d.png", i + 1);
      write_image(dir + name, s.render(i));
    }
  }

  std::string init_box() const {
    const cv::Rect2f b = scene().box(0);
    std::ostringstream text;
    text << b.x << "," << b.y << "," << b.width << "," << b.height;
    return text.str();
  }

  // `track INPUT` with every output: the log, the summary and the annotated video.
  std::vector<std::string> track_all_outputs(const std::string& input) const {
    return {"track", input,           "--init",       init_box(),
            "--log", path("log.csv"), "--summary",    path("summary.json"),
            "--out", path("out.avi"), "--no-progress"};
  }

  // What a run cut short at frame `frames` (0-based index of the first frame missing) left:
  // a complete log of frames 1..frames in order, a summary that says so, a video that opens
  // and holds that many frames.
  void expect_outputs_hold(long long frames) const {
    const std::vector<eval::TrackRecord> log = eval::read_track_csv(path("log.csv"));
    ASSERT_EQ(static_cast<long long>(log.size()), frames);
    for (std::size_t i = 0; i < log.size(); ++i)
      EXPECT_EQ(log[i].frame, static_cast<long long>(i) + 1);
    const nlohmann::json summary = nlohmann::json::parse(read_text(path("summary.json")));
    EXPECT_EQ(summary.at("frames").get<long long>(), frames);
    EXPECT_NE(summary.at("status").get<std::string>().find("stopped at frame"), std::string::npos);
    cv::VideoCapture video(path("out.avi"), cv::CAP_FFMPEG);
    ASSERT_TRUE(video.isOpened()) << "the annotated video does not open";
    long long decoded = 0;
    for (cv::Mat frame; video.read(frame);)
      ++decoded;
    EXPECT_EQ(decoded, frames);
  }
};

// --- missing file --------------------------------------------------------------------------

TEST_F(BadInputTest, MissingFile) {
  write_pair();
  write_video("clip.avi");
  expect_error({"flow", path("none.png"), path("b.png"), "-o", path("o.flo")}, 1, path("none.png"));
  expect_error(
      {"flow", path("a.png"), path("b.png"), "-o", path("o.flo"), "--gt", path("none.flo")}, 1,
      path("none.flo"));
  expect_error({"track", path("none.avi")}, 1, "no such file or directory: '" + path("none.avi"));
  expect_error({"dense", path("none.avi"), "--out", path("d")}, 1, path("none.avi"));
  expect_error({"eval", "--pair", path("a.png"), path("none.png"), path("gt.flo")}, 1,
               path("none.png"));
  expect_error({"score", path("none.csv"), path("gt.txt")}, 1, path("none.csv"));
  expect_error({"track", path("clip.avi"), "--log", path("no/such/dir/log.csv")}, 1,
               "does not exist");
  EXPECT_FALSE(fs::exists(path("o.flo")));
}

// --- directory instead of file -------------------------------------------------------------

TEST_F(BadInputTest, DirectoryInsteadOfFile) {
  write_pair();
  write_video("clip.avi");
  fs::create_directories(path("folder"));
  expect_error({"flow", path("folder"), path("b.png"), "-o", path("o.flo")}, 1,
               path("folder") + "' is a directory");
  // A folder is a valid track input when it holds an image sequence; this one holds none.
  expect_error({"track", path("folder")}, 1, "no image sequence in '" + path("folder") + "'");
  expect_error({"score", path("folder"), path("folder")}, 1, path("folder"));
  expect_error({"track", path("clip.avi"), "--log", path("folder")}, 1, "is a directory");
  fs::create_directories(path("log.csv"));
  expect_error({"track", path("clip.avi"), "--log", path("log.csv")}, 1, "is a directory");
  expect_error({"track", path("clip.avi"), "--summary", path("folder")}, 1, "is a directory");
  expect_error({"flow", path("a.png"), path("b.png"), "-o", path("folder")}, 1, "is a directory");
}

// --- empty file ----------------------------------------------------------------------------

TEST_F(BadInputTest, EmptyFile) {
  write_pair();
  for (const char* name : {"empty.avi", "empty.png", "empty.csv", "empty.txt", "empty.flo"})
    write_bytes(name, "");
  expect_error({"track", path("empty.avi")}, 1, path("empty.avi"));
  expect_error({"dense", path("empty.avi"), "--out", path("d")}, 1, path("empty.avi"));
  expect_error({"flow", path("empty.png"), path("b.png"), "-o", path("o.flo")}, 1,
               "cannot decode image '" + path("empty.png") + "'");
  expect_error(
      {"flow", path("a.png"), path("b.png"), "-o", path("o.flo"), "--gt", path("empty.flo")}, 1,
      path("empty.flo"));
  expect_error({"score", path("empty.csv"), path("empty.txt")}, 1, path("empty.csv"));
  EXPECT_FALSE(fs::exists(path("o.flo")));
  EXPECT_FALSE(fs::exists(path("d")));
}

// --- truncated video (cut mid-file) --------------------------------------------------------

TEST_F(BadInputTest, TruncatedVideo) {
  write_video("clip.avi", 20);
  const std::string whole = read_text(path("clip.avi"));
  write_bytes("cut.avi", whole.substr(0, whole.size() * 6 / 10));
  const Outcome r = expect_error(track_all_outputs(path("cut.avi")), 1, "stopped at frame ");
  // "input stopped at frame N: ..." – the log holds frames 1..N.
  const std::size_t at = r.err.find("stopped at frame ") + std::strlen("stopped at frame ");
  const long long stopped = std::stoll(r.err.substr(at));
  EXPECT_GT(stopped, 5);
  EXPECT_LT(stopped, 20);
  expect_outputs_hold(stopped);
  // The summary of what was done still reaches stdout.
  EXPECT_NE(r.out.find(std::to_string(stopped) + " frames in"), std::string::npos) << r.out;

  // Cut inside the header: nothing can be read, nothing is written.
  write_bytes("stub.avi", whole.substr(0, 100));
  expect_error({"track", path("stub.avi"), "--log", path("stub.csv")}, 1, path("stub.avi"));
  EXPECT_FALSE(fs::exists(path("stub.csv")));
}

// --- corrupted video (random bytes flipped) ------------------------------------------------

TEST_F(BadInputTest, CorruptedVideo) {
  write_video("clip.avi", 20);
  std::string bytes = read_text(path("clip.avi"));
  // Flip bytes in the second half, where the later frames' JPEG data is: the decoder either
  // conceals the damage (a damaged picture, as any player shows it) or drops those frames, and
  // the run stops there. Either way: no crash, no hang, outputs readable.
  std::mt19937 rng(7);
  std::uniform_int_distribution<std::size_t> where(bytes.size() / 2, bytes.size() - 1);
  for (int i = 0; i < 200; ++i)
    bytes[where(rng)] ^= static_cast<char>(1 + rng() % 255);
  write_bytes("flipped.avi", bytes);
  SCOPED_TRACE(shown(track_all_outputs(path("flipped.avi"))));
  const Outcome r = run(track_all_outputs(path("flipped.avi")));
  ASSERT_FALSE(r.timed_out) << "hung";
  ASSERT_EQ(r.signal, 0) << "killed by signal " << r.signal;
  const std::vector<eval::TrackRecord> log = eval::read_track_csv(path("log.csv"));
  for (std::size_t i = 0; i < log.size(); ++i)
    EXPECT_EQ(log[i].frame, static_cast<long long>(i) + 1);
  if (r.exit_code == 0) {
    EXPECT_TRUE(r.err.empty()) << r.err;
    EXPECT_EQ(log.size(), 20u);
  } else {
    EXPECT_EQ(r.exit_code, 1) << r.err;
    EXPECT_EQ(lines_of(r.err).size(), 1u) << r.err;
    EXPECT_EQ(r.err.rfind("roiflow: error: input stopped at frame ", 0), 0u) << r.err;
    expect_outputs_hold(static_cast<long long>(log.size()));
  }
  cv::VideoCapture video(path("out.avi"), cv::CAP_FFMPEG);
  EXPECT_TRUE(video.isOpened());

  // Garbage from the first byte: refused at open.
  std::string garbage(4096, '\0');
  for (char& c : garbage)
    c = static_cast<char>(rng());
  write_bytes("garbage.avi", garbage);
  expect_error({"track", path("garbage.avi")}, 1, path("garbage.avi"));
}

// --- image sequence with a missing or unreadable frame -------------------------------------

TEST_F(BadInputTest, SequenceWithMissingFrame) {
  write_sequence("seq", 12);
  fs::remove(path("seq/0008.png"));
  expect_error(track_all_outputs(path("seq")), 1,
               "stopped at frame 7: missing file '" + path("seq/0008.png") + "'");
  expect_outputs_hold(7);
}

TEST_F(BadInputTest, SequenceWithUnreadableFrame) {
  write_sequence("seq", 12);
  write_bytes("seq/0006.png", "\x89PNG\r\n\x1a\n but the rest is not an image");
  expect_error(track_all_outputs(path("seq")), 1,
               "stopped at frame 5: cannot decode image '" + path("seq/0006.png") + "'");
  expect_outputs_hold(5);
  // A PNG cut short (a copy interrupted): refused, not half decoded.
  write_sequence("seq", 12);
  const std::string png = read_text(path("seq/0004.png"));
  write_bytes("seq/0004.png", png.substr(0, png.size() / 2));
  expect_error(
      track_all_outputs(path("seq")), 1,
      "stopped at frame 3: cannot decode image '" + path("seq/0004.png") + "': truncated PNG");
  expect_outputs_hold(3);
  // Likewise a JPEG, which the decoder would otherwise return with its missing part gray.
  const eval::TrackingScene s = scene(6);
  for (int i = 0; i < s.frames(); ++i)
    write_image("jpg/" + std::to_string(i + 1) + ".jpg", s.render(i));
  const std::string jpg = read_text(path("jpg/5.jpg"));
  write_bytes("jpg/5.jpg", jpg.substr(0, jpg.size() * 2 / 3));
  expect_error(
      {"track", path("jpg"), "--single", "--log", path("jpg.csv"), "--no-progress"}, 1,
      "stopped at frame 4: cannot decode image '" + path("jpg/5.jpg") + "': truncated JPEG");
  EXPECT_EQ(eval::read_track_csv(path("jpg.csv")).size(), 4u);
  // The first frame unreadable: nothing to start from.
  write_bytes("seq/0001.png", "");
  expect_error({"track", path("seq"), "--log", path("first.csv")}, 1, path("seq/0001.png"));
  EXPECT_FALSE(fs::exists(path("first.csv")));
}

// --- frames of changing size ---------------------------------------------------------------

TEST_F(BadInputTest, FramesOfChangingSize) {
  write_sequence("seq", 12);
  write_image("seq/0010.png", cv::Mat(100, 150, CV_8UC3, cv::Scalar(90, 100, 110)));
  expect_error(track_all_outputs(path("seq")), 1,
               "stopped at frame 9: frame size 150x100 differs from the first frame's 160x120");
  expect_outputs_hold(9);
  const Outcome dense =
      expect_error({"dense", path("seq"), "--out", path("dense.avi"), "--no-progress"}, 1,
                   "differs from the first frame's");
  cv::VideoCapture video(path("dense.avi"), cv::CAP_FFMPEG);
  ASSERT_TRUE(video.isOpened());
  EXPECT_EQ(static_cast<int>(video.get(cv::CAP_PROP_FRAME_COUNT)), 8);  // pairs before frame 9

  // flow: two images of different sizes.
  write_image("a.png", cv::Mat(40, 50, CV_8UC1, cv::Scalar(9)));
  write_image("b.png", cv::Mat(41, 50, CV_8UC1, cv::Scalar(9)));
  expect_error({"flow", path("a.png"), path("b.png"), "-o", path("o.flo")}, 1, "50x41");
}

// --- 1x1 and 10000x10000 images ------------------------------------------------------------

TEST_F(BadInputTest, TinyImage1x1) {
  write_image("one.png", cv::Mat(1, 1, CV_8UC1, cv::Scalar(128)));
  expect_error({"flow", path("one.png"), path("one.png"), "-o", path("o.flo")}, 1,
               "image '" + path("one.png") + "' is 1x1: smaller than the minimum of 12 px a side");
  write_image("tiny/0001.png", cv::Mat(1, 1, CV_8UC3, cv::Scalar(1, 2, 3)));
  write_image("tiny/0002.png", cv::Mat(1, 1, CV_8UC3, cv::Scalar(1, 2, 3)));
  expect_error({"track", path("tiny"), "--log", path("log.csv")}, 1, "1x1: smaller than");
  expect_error({"dense", path("tiny"), "--out", path("d")}, 1, "1x1: smaller than");
  EXPECT_FALSE(fs::exists(path("o.flo")));
  EXPECT_FALSE(fs::exists(path("log.csv")));

  // The smallest accepted size is processed, with every pyramid level asked for.
  write_pair({12, 12});
  expect_success({"flow", path("a.png"), path("b.png"), "-o", path("o.flo"), "--levels", "6"});
  EXPECT_TRUE(fs::exists(path("o.flo")));
}

TEST_F(BadInputTest, HugeImage10000x10000) {
  // A 1-bit PBM bitmap (P4), written row by row: 12.5 MB on disk and no 100 Mpixel buffer in
  // this process (whose peak memory other tests measure); the CLI decodes it to 100 Mpixel.
  // Named .pgm because image sequences list that extension; OpenCV reads it by its content.
  fs::create_directories(path("huge"));
  {
    std::ofstream pbm(path("huge/0001.pgm"), std::ios::binary);
    pbm << "P4\n10000 10000\n";
    const std::string row(10000 / 8, '\x55');
    for (int y = 0; y < 10000; ++y)
      pbm << row;
    ASSERT_TRUE(pbm.good());
  }
  write_pair();
  expect_error({"flow", path("huge/0001.pgm"), path("b.png"), "-o", path("o.flo")}, 1,
               "is 10000x10000: larger than the limit of 8192 px a side and 40 Mpixel");
  expect_error({"track", path("huge"), "--log", path("log.csv")}, 1, "10000x10000: larger than");
  expect_error({"dense", path("huge"), "--out", path("d")}, 1, "10000x10000: larger than");
  EXPECT_FALSE(fs::exists(path("o.flo")));
  EXPECT_FALSE(fs::exists(path("log.csv")));
}

// --- --roi larger than the frame -----------------------------------------------------------

TEST_F(BadInputTest, RoiLargerThanFrame) {
  // Documented: the local region is clipped to the frame, so a region larger than the frame
  // tracks over the whole frame, and tracks as well.
  write_video("clip.avi", 20);
  const eval::TrackingScene s = scene(20);
  std::ofstream truth(path("truth.txt"));
  for (int i = 0; i < s.frames(); ++i) {
    const cv::Rect2f b = s.box(i);
    truth << b.x << "," << b.y << "," << b.width << "," << b.height << "\n";
  }
  truth.close();
  expect_success({"track", path("clip.avi"), "--init", init_box(), "--roi", "1000", "--log",
                  path("log.csv"), "--no-progress"});
  EXPECT_EQ(eval::read_track_csv(path("log.csv")).size(), 20u);
  const Outcome score =
      expect_success({"score", path("log.csv"), path("truth.txt"), "--format", "json"});
  EXPECT_GT(nlohmann::json::parse(score.out).at("precision20").get<double>(), 0.9) << score.out;
  // Beyond the documented range: a usage error.
  expect_error({"track", path("clip.avi"), "--roi", "5000"}, 2, "--roi");
}

// --- --init outside the frame --------------------------------------------------------------

TEST_F(BadInputTest, InitOutsideFrame) {
  write_video("clip.avi", 8);
  for (const char* box : {"500,500,10,10", "-50,10,20,20", "159,119,10,10", "10,-8,20,9"})
    expect_error({"track", path("clip.avi"), "--init", box, "--log", path("log.csv")}, 2,
                 std::string("--init: the box ") + box + " lies outside the 160x120 frame");
  // Values a float holds but no pixel coordinate does.
  expect_error({"track", path("clip.avi"), "--init", "0,0,1e30,1e30"}, 2, "init box");
  expect_error({"track", path("clip.avi"), "--init", "-1e20,5,20,20"}, 2, "init box");
  expect_error({"track", path("clip.avi"), "--init", "nan,5,20,20"}, 2, "--init");
  EXPECT_FALSE(fs::exists(path("log.csv")));
  // Partly outside is fine: the part inside is tracked.
  expect_success({"track", path("clip.avi"), "--init", "-10,30,40,30", "--log", path("log.csv"),
                  "--no-progress"});
  EXPECT_EQ(eval::read_track_csv(path("log.csv")).size(), 8u);
}

// --- zero or negative parameters -----------------------------------------------------------

TEST_F(BadInputTest, ZeroOrNegativeParameters) {
  write_pair();
  write_video("clip.avi", 8);
  const std::string flo = path("o.flo");
  const std::vector<std::string> flow = {"flow", path("a.png"), path("b.png"), "-o", flo};
  const std::vector<std::string> track = {"track", path("clip.avi")};
  const std::vector<std::string> dense = {"dense", path("clip.avi"), "--out", path("d")};
  struct Row {
    std::vector<std::string> base;
    std::string option, value;
    std::string named;  // how the message names the parameter
  };
  const std::vector<Row> rows = {
      {flow, "--patch", "-3", "--patch"},
      {flow, "--levels", "0", "--levels"},
      {flow, "--iterations", "-2", "--iterations"},
      {flow, "--lambda", "0", "lambda must be in (0, 1]"},
      {flow, "--sigma", "-1", "sigma must be in [0, 20]"},
      {flow, "--robust-scale", "-1", "robust scale must be in [0, 1]"},
      {flow, "--threads", "0", "--threads"},
      {track, "--roi", "0", "--roi"},
      {track, "--roi", "-50", "--roi"},
      {track, "--start", "-1", "--start"},
      {track, "--max-frames", "-1", "--max-frames"},
      {track, "--in-flight", "-1", "--in-flight"},
      {track, "--decode-threads", "-1", "--decode-threads"},
      {dense, "--decode-threads", "65", "--decode-threads"},
      {track, "--threads", "0", "--threads"},
      {track, "--init", "5,5,0,10", "--init"},
      {track, "--init", "5,5,10,-10", "--init"},
      {dense, "--max-motion", "-1", "--max-motion"},
      {{"demo", "--dir", path("demo")}, "--frames", "-5", "--frames"},
  };
  for (const Row& row : rows) {
    std::vector<std::string> args = row.base;
    args.push_back(row.option);
    args.push_back(row.value);
    const Outcome r = expect_error(args, 2, row.named);
    // The message quotes the value, so a user sees which one was refused.
    EXPECT_NE(r.err.find(row.value), std::string::npos) << r.err;
  }
  // A synthetic stream of no frames is an input error.
  expect_error({"track", "synthetic:0"}, 1, "frame count must be in 1..");
  expect_error({"track", "synthetic:-5"}, 1, "bad synthetic input 'synthetic:-5'");
  EXPECT_FALSE(fs::exists(flo));
  EXPECT_FALSE(fs::exists(path("d")));
  EXPECT_FALSE(fs::exists(path("demo")));
}

// --- NaN in ground truth -------------------------------------------------------------------

// A .flo file written by hand, since write_flo refuses NaN.
std::string flo_bytes(int width, int height, float value) {
  std::string bytes = "PIEH";
  const std::int32_t size[2] = {width, height};
  bytes.append(reinterpret_cast<const char*>(size), sizeof size);
  const std::vector<float> data(static_cast<std::size_t>(width) * height * 2, value);
  bytes.append(reinterpret_cast<const char*>(data.data()), data.size() * sizeof(float));
  return bytes;
}

TEST_F(BadInputTest, NanInGroundTruth) {
  // Flow ground truth: NaN is not Middlebury's "unknown" (> 1e9); refused naming the pixel.
  write_pair();
  write_bytes("nan.flo", flo_bytes(96, 64, std::numeric_limits<float>::quiet_NaN()));
  expect_error({"flow", path("a.png"), path("b.png"), "-o", path("o.flo"), "--gt", path("nan.flo")},
               1, "NaN at (0,0)");
  expect_error({"eval", "--pair", path("a.png"), path("b.png"), path("nan.flo")}, 1, "NaN");
  EXPECT_FALSE(fs::exists(path("o.flo")));

  // Box ground truth: four NaN mark the target absent (documented: the frame is not scored);
  // a partly NaN box is an error naming the line.
  std::ofstream track(path("track.csv"), std::ios::binary);
  track << "frame,x,y,w,h,vx,vy,mode,lost,ms\n";
  for (int i = 1; i <= 3; ++i)
    track << i << ",10.00,10.00,20.00,20.00,0.000,0.000,local,0,0.100\n";
  track.close();
  write_bytes("absent.txt", "10,10,20,20\nNaN,NaN,NaN,NaN\n10,10,20,20\n");
  const Outcome absent =
      expect_success({"score", path("track.csv"), path("absent.txt"), "--format", "json"});
  const nlohmann::json doc = nlohmann::json::parse(absent.out);
  EXPECT_EQ(doc.at("frames").get<int>(), 2);  // the absent frame is skipped
  EXPECT_NEAR(doc.at("mean_iou").get<double>(), 1.0, 1e-9);
  write_bytes("partly.txt", "10,10,20,20\n10,NaN,20,20\n10,10,20,20\n");
  expect_error({"score", path("track.csv"), path("partly.txt")}, 1, path("partly.txt") + ":2:");
  write_bytes("all_nan.txt", "nan,nan,nan,nan\nnan,nan,nan,nan\n");
  expect_error({"score", path("track.csv"), path("all_nan.txt")}, 1, "no frame to score");
}

}  // namespace
