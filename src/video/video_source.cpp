#include "video/video_source.hpp"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>
#include <string_view>
#include <system_error>
#include <utility>
#include <vector>

#include "core/error.hpp"
#include "core/text.hpp"
#include "eval/synthetic_input.hpp"
#include "eval/tracking_scene.hpp"
#include "eval/traffic_scene.hpp"
#include "video/video_decoder.hpp"

namespace roiflow::video {

// One kind of input. read() fills `image` with frame `index` (indices come in order, one
// after the other), and `gray` too when it has it at hand (else VideoSource converts `image`),
// and returns true; or returns false with `failure` empty at a normal end, or naming what went
// wrong.
class VideoSource::Reader {
 public:
  virtual ~Reader() = default;
  // Fills `frame`'s image (or deferred_image), timestamp and, optionally, gray.
  virtual bool read(long long index, Frame& frame, std::string& failure) = 0;
  virtual double fps() const = 0;
  virtual long long frame_count() const = 0;  // from index 0; -1 when unknown
  virtual std::string description() const = 0;
};

namespace {

namespace fs = std::filesystem;

std::string quoted(const std::string& text) {
  return "'" + text + "'";
}

std::string number_string(double value) {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%g", value);
  return buffer;
}

bool all_digits(std::string_view text) {
  return !text.empty() &&
         std::all_of(text.begin(), text.end(), [](unsigned char c) { return std::isdigit(c); });
}

std::optional<long long> parse_number(std::string_view digits) {
  long long value = 0;
  const auto [end, ec] = std::from_chars(digits.data(), digits.data() + digits.size(), value);
  if (ec != std::errc() || end != digits.data() + digits.size()) return std::nullopt;
  return value;
}

bool is_image_extension(std::string extension) {
  for (char& c : extension)
    c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  for (const char* known : {".jpg", ".jpeg", ".png", ".bmp", ".pgm", ".ppm", ".tif", ".tiff"})
    if (extension == known) return true;
  return false;
}

// The sorted entry names of `dir`; throws naming `dir` when it cannot be listed.
std::vector<std::string> file_names(const fs::path& dir) {
  std::vector<std::string> names;
  std::error_code ec;
  for (fs::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) {
    std::error_code type_ec;
    if (it->is_regular_file(type_ec)) names.push_back(it->path().filename().string());
  }
  if (ec) throw Error("cannot list directory " + quoted(dir.string()) + ": " + ec.message());
  std::sort(names.begin(), names.end());
  return names;
}

// The numbered files of one sequence: prefix + number + suffix.
struct Numbered {
  std::string prefix;
  std::string suffix;
  std::map<long long, std::string> files;  // number -> file name
};

// Splits "abc0012.jpg" into "abc", "0012", ".jpg"; false when there is no number before the
// extension.
bool split_numbered(const std::string& name, std::string& prefix, std::string& digits,
                    std::string& extension) {
  const auto dot = name.rfind('.');
  if (dot == std::string::npos || dot == 0) return false;
  auto first_digit = dot;
  while (first_digit > 0 && std::isdigit(static_cast<unsigned char>(name[first_digit - 1])))
    --first_digit;
  if (first_digit == dot) return false;
  prefix = name.substr(0, first_digit);
  digits = name.substr(first_digit, dot - first_digit);
  extension = name.substr(dot);
  return true;
}

// The largest group of numbered image files in `dir` (ties: the first prefix and extension in
// name order), or an empty group.
Numbered find_numbered_images(const fs::path& dir) {
  std::map<std::pair<std::string, std::string>, Numbered> groups;
  for (const auto& name : file_names(dir)) {
    std::string prefix, digits, extension;
    if (!split_numbered(name, prefix, digits, extension) || !is_image_extension(extension))
      continue;
    const auto number = parse_number(digits);
    if (!number) continue;
    auto& group = groups[{prefix, extension}];
    group.prefix = prefix;
    group.suffix = extension;
    group.files.emplace(*number, name);
  }
  Numbered best;
  for (auto& [key, group] : groups)
    if (group.files.size() > best.files.size()) best = std::move(group);
  return best;
}

// A printf pattern with one %d, %Nd or %0Nd in its file name.
struct Pattern {
  fs::path dir;
  std::string prefix;
  std::string suffix;
  std::string conversion;  // e.g. "%04d"
};

Pattern parse_pattern(const std::string& pattern) {
  const fs::path path(pattern);
  const std::string name = path.filename().string();
  const std::string dir = path.parent_path().string();
  const auto unsupported = [&] {
    return Error("unsupported image-sequence pattern " + quoted(pattern) +
                 ": expected one %d, %Nd or %0Nd in the file name, like img/%04d.jpg");
  };
  if (dir.find('%') != std::string::npos) throw unsupported();
  const auto percent = name.find('%');
  if (percent == std::string::npos) throw unsupported();
  auto end = percent + 1;
  while (end < name.size() && std::isdigit(static_cast<unsigned char>(name[end])))
    ++end;
  if (end >= name.size() || name[end] != 'd' || end - percent > 4) throw unsupported();
  if (name.find('%', end) != std::string::npos) throw unsupported();
  return {dir.empty() ? fs::path(".") : fs::path(dir), name.substr(0, percent),
          name.substr(end + 1), name.substr(percent, end + 1 - percent)};
}

Numbered find_pattern_files(const Pattern& pattern) {
  Numbered found{pattern.prefix, pattern.suffix, {}};
  std::error_code ec;
  if (!fs::is_directory(pattern.dir, ec)) return found;
  for (const auto& name : file_names(pattern.dir)) {
    if (name.size() <= pattern.prefix.size() + pattern.suffix.size() ||
        !name.starts_with(pattern.prefix) || !name.ends_with(pattern.suffix))
      continue;
    const std::string_view digits = std::string_view(name).substr(
        pattern.prefix.size(), name.size() - pattern.prefix.size() - pattern.suffix.size());
    if (!all_digits(digits)) continue;
    if (const auto number = parse_number(digits)) found.files.emplace(*number, name);
  }
  return found;
}

class SequenceReader : public VideoSource::Reader {
 public:
  // `label` names the sequence in messages (the folder or the pattern). `conversion`, when
  // given, formats a missing file's number; otherwise the file before the gap shows its width.
  SequenceReader(const fs::path& dir, const Numbered& numbered, std::string label,
                 const std::string& conversion, double fps)
      : label_(std::move(label)), fps_(fps) {
    const long long first_number = numbered.files.begin()->first;
    first_name_ = numbered.files.begin()->second;
    long long number = first_number;
    for (auto it = numbered.files.begin(); it != numbered.files.end() && it->first == number;
         ++it, ++number)
      paths_.push_back((dir / it->second).string());
    const long long after_gap = static_cast<long long>(numbered.files.size() - paths_.size());
    if (after_gap == 0) return;
    std::string format = conversion;
    if (format.empty()) {
      std::string prefix, digits, extension;
      split_numbered(fs::path(paths_.back()).filename().string(), prefix, digits, extension);
      format = "%0" + std::to_string(digits.size()) + "d";
    }
    format.insert(format.size() - 1, "ll");
    char buffer[64];
    std::snprintf(buffer, sizeof buffer, format.c_str(), number);
    gap_ = "missing file " + quoted((dir / (numbered.prefix + buffer + numbered.suffix)).string()) +
           " (a gap in the numbering: " + std::to_string(after_gap) + " later file" +
           (after_gap == 1 ? "" : "s") + " up to " + quoted(numbered.files.rbegin()->second) +
           " not read)";
  }

  bool read(long long index, Frame& frame, std::string& failure) override {
    if (index >= static_cast<long long>(paths_.size())) {
      failure = gap_;
      return false;
    }
    const std::string& path = paths_[static_cast<std::size_t>(index)];
    std::error_code ec;
    // Checked first: the file may have gone since the folder was listed.
    if (!fs::is_regular_file(path, ec)) {
      failure = "missing file " + quoted(path);
      return false;
    }
    try {
      frame.image = eval::read_image(path, cv::IMREAD_ANYCOLOR);
    } catch (const Error& e) {
      failure = e.what();
      return false;
    }
    frame.timestamp_s = static_cast<double>(index) / fps_;
    return true;
  }

  double fps() const override { return fps_; }
  long long frame_count() const override { return static_cast<long long>(paths_.size()); }
  std::string description() const override {
    return "image sequence " + quoted(label_) + " (" + quoted(first_name_) + ".." +
           quoted(fs::path(paths_.back()).filename().string()) + ", " +
           std::to_string(paths_.size()) + " frames, " + number_string(fps_) + " fps)";
  }

 private:
  std::string label_;
  double fps_;
  std::vector<std::string> paths_;  // the consecutive run, in order
  std::string first_name_;
  std::string gap_;  // why the sequence stops after paths_; empty when it simply ends
};

class CameraReader : public VideoSource::Reader {
 public:
  CameraReader(int camera, double default_fps) : label_("camera " + std::to_string(camera)) {
    capture_.open(camera);
    if (!capture_.isOpened()) throw Error("cannot open " + label_);
    const double reported = capture_.get(cv::CAP_PROP_FPS);
    fps_ = std::isfinite(reported) && reported > 0 ? reported : default_fps;
    opened_at_ = std::chrono::steady_clock::now();
  }

  bool read(long long, Frame& frame, std::string& failure) override {
    if (!capture_.read(frame.image) || frame.image.empty()) {
      failure = label_ + " stopped delivering frames";
      return false;
    }
    frame.timestamp_s =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - opened_at_).count();
    return true;
  }

  double fps() const override { return fps_; }
  long long frame_count() const override { return -1; }
  std::string description() const override {
    return label_ + " (" + number_string(fps_) + " fps, " + capture_.getBackendName() + ")";
  }

 private:
  std::string label_;
  cv::VideoCapture capture_;
  double fps_ = 0;
  std::chrono::steady_clock::time_point opened_at_;
};

class VideoFileReader : public VideoSource::Reader {
 public:
  VideoFileReader(const std::string& path, double default_fps, int threads, bool defer_colour)
      : label_("video " + quoted(path)), decoder_(path, threads, defer_colour) {
    // Checked before the first frame is decoded: a huge frame would be allocated by then.
    const cv::Size announced = decoder_.size();
    if (announced.width > 0 && announced.height > 0) eval::check_frame_size(announced, label_);
    fps_ = decoder_.fps() > 0 ? decoder_.fps() : default_fps;
  }

  bool read(long long index, Frame& out, std::string& failure) override {
    DecodedFrame frame;
    std::string error;
    if (!decoder_.read(frame, error)) {
      failure = end_failure(index, error);
      return false;
    }
    out.image = frame.bgr;
    out.deferred_image = frame.deferred_bgr;
    out.gray = frame.gray;
    // Containers without timestamps give none (or repeat the last one): fall back to the
    // frame rate so timestamps always increase.
    const double pts = frame.timestamp_s;
    const bool usable = std::isfinite(pts) && (last_timestamp_ ? pts > *last_timestamp_ : pts >= 0);
    out.timestamp_s = usable            ? pts
                      : last_timestamp_ ? *last_timestamp_ + 1.0 / fps_
                                        : static_cast<double>(index) / fps_;
    last_timestamp_ = out.timestamp_s;
    return true;
  }

  double fps() const override { return fps_; }
  long long frame_count() const override { return decoder_.frame_count(); }
  std::string description() const override {
    const long long count = decoder_.frame_count();
    return label_ + " (" + number_string(fps_) + " fps" +
           (count > 0 ? ", " + std::to_string(count) + " frames" : "") + ", FFmpeg " +
           decoder_.codec_name() + ")";
  }

 private:
  std::string label_;
  VideoDecoder decoder_;
  double fps_ = 0;
  std::optional<double> last_timestamp_;

  // Why there is no frame `index`: empty at a normal end. `error`: the decoder's, if any.
  std::string end_failure(long long index, const std::string& error) const {
    if (!error.empty()) return label_ + ": " + error;
    // A count estimated from the duration may be a frame or two off: only a clear shortfall
    // is a truncated or corrupt file.
    const long long count = decoder_.frame_count();
    if (count > 0 && index < count - 1 - count / 100)
      return label_ + " ended after " + std::to_string(index) + " of the " + std::to_string(count) +
             " frames its container announces (truncated or corrupt file?)";
    return {};
  }
};

// "synthetic:N[:WxH]": the tracking scene played forwards and backwards, rendered on demand.
class SyntheticReader : public VideoSource::Reader {
 public:
  static constexpr int kSceneFrames = 300;

  SyntheticReader(long long frames, cv::Size size, double fps)
      : frames_(frames), fps_(fps), scene_(scene_params(size)) {}

  bool read(long long index, Frame& frame, std::string&) override {
    if (index >= frames_) return false;
    // Mirrored so that the vehicle turns back instead of leaping to the start: the only jumps
    // are the scene's own, which the tracker's global treatment has to catch.
    const long long period = 2 * (kSceneFrames - 1);
    const long long phase = index % period;
    frame.image = scene_.render(static_cast<int>(phase < kSceneFrames ? phase : period - phase));
    frame.timestamp_s = static_cast<double>(index) / fps_;
    return true;
  }

  double fps() const override { return fps_; }
  long long frame_count() const override { return frames_; }
  std::string description() const override {
    return "synthetic scene (" + std::to_string(frames_) + " frames, " + number_string(fps_) +
           " fps)";
  }

 private:
  long long frames_;
  double fps_;
  eval::TrackingScene scene_;

  static eval::TrackingSceneParams scene_params(cv::Size size) {
    eval::TrackingSceneParams params;
    params.size = size;
    params.frames = kSceneFrames;
    // The default vehicle and jump are drawn for 640 px: scaled so that any size keeps the
    // same picture (the vehicle at least 8 px, as the scene requires).
    const float scale = static_cast<float>(size.width) / 640.f;
    params.object = {std::max(8.f, params.object.width * scale),
                     std::max(8.f, params.object.height * scale)};
    params.jump *= scale;
    return params;
  }
};

// "synthetic:N[:WxH]:OBJECTS": eval::TrafficScene, N frames, its vehicles' boxes known exactly.
class TrafficReader : public VideoSource::Reader {
 public:
  TrafficReader(const eval::TrafficSceneParams& params, double fps) : fps_(fps), scene_(params) {}

  bool read(long long index, Frame& frame, std::string&) override {
    if (index >= scene_.frames()) return false;
    frame.image = scene_.render(index);
    frame.timestamp_s = static_cast<double>(index) / fps_;
    return true;
  }

  double fps() const override { return fps_; }
  long long frame_count() const override { return scene_.frames(); }
  std::string description() const override {
    return "synthetic traffic (" + std::to_string(scene_.frames()) + " frames, " +
           std::to_string(scene_.objects()) + " vehicles, " + number_string(fps_) + " fps)";
  }

 private:
  double fps_;
  eval::TrafficScene scene_;
};

std::unique_ptr<VideoSource::Reader> open_synthetic(const std::string& input, double fps) {
  const eval::SyntheticInput spec = eval::parse_synthetic_input(input);
  if (spec.objects > 0) return std::make_unique<TrafficReader>(eval::traffic_params(spec), fps);
  return std::make_unique<SyntheticReader>(spec.frames, spec.size, fps);
}

// The camera index that `input` names, or -1 when it is not one.
int camera_index(const std::string& input) {
  if (!all_digits(input)) return -1;
  const auto number = parse_number(input);
  if (!number || *number > 1'000'000) throw Error("camera index out of range: " + input);
  return static_cast<int>(*number);
}

std::unique_ptr<VideoSource::Reader> open_reader(const std::string& input, double fps,
                                                 int decode_threads, bool defer_colour) {
  if (input.empty()) throw Error("no input given: expected a video file, a folder or a camera");
  if (const int camera = camera_index(input); camera >= 0)
    return std::make_unique<CameraReader>(camera, fps);
  std::error_code ec;
  const fs::file_status status = fs::status(input, ec);
  if (fs::is_directory(status)) {
    for (const fs::path& dir : {fs::path(input) / "img", fs::path(input)}) {
      if (!fs::is_directory(dir, ec)) continue;
      const Numbered numbered = find_numbered_images(dir);
      if (!numbered.files.empty())
        return std::make_unique<SequenceReader>(dir, numbered, dir.string(), "", fps);
    }
    throw Error("no image sequence in " + quoted(input) +
                " or its img/ folder: expected numbered images like 0001.jpg");
  }
  if (fs::exists(status))
    return std::make_unique<VideoFileReader>(input, fps, decode_threads, defer_colour);
  if (eval::is_synthetic_input(input)) return open_synthetic(input, fps);
  if (input.find('%') != std::string::npos) {
    const Pattern pattern = parse_pattern(input);
    const Numbered numbered = find_pattern_files(pattern);
    if (numbered.files.empty()) throw Error("no file matches the pattern " + quoted(input));
    return std::make_unique<SequenceReader>(pattern.dir, numbered, input, pattern.conversion, fps);
  }
  throw Error("no such file or directory: " + quoted(input));
}

}  // namespace

VideoSource::VideoSource(const std::string& input, const VideoSourceParams& params)
    : params_(params) {
  if (!std::isfinite(params.fps) || params.fps <= 0)
    throw Error("fps must be > 0, got " + number_string(params.fps));
  if (params.start < 0) throw Error("start must be >= 0, got " + std::to_string(params.start));
  if (params.max_frames < 0)
    throw Error("max_frames must be >= 0, got " + std::to_string(params.max_frames));
  if (params.decode_threads < 0)
    throw Error("decode_threads must be >= 0, got " + std::to_string(params.decode_threads));
  reader_ = open_reader(input, params.fps, params.decode_threads, params.defer_colour);

  std::string failure;
  for (long long index = 0; index < params.start; ++index) {
    // Reading (rather than seeking) keeps the frame exact whatever the codec's key frames.
    Frame skipped;
    if (!reader_->read(index, skipped, failure))
      throw Error("start " + std::to_string(params.start) + " is past the end of " + quoted(input) +
                  ": no frame " + std::to_string(index) +
                  (failure.empty() ? "" : " (" + failure + ")"));
  }
  pending_ = read_frame(params.start, failure);
  if (!pending_ && params.start > 0 && failure.empty())
    throw Error("start " + std::to_string(params.start) + " is past the end of " + quoted(input));
  if (!pending_)
    throw Error("cannot read the first frame of " + quoted(input) + ": " +
                (failure.empty() ? "no frame in it" : failure));
  size_ = pending_->gray.size();
}

VideoSource::~VideoSource() = default;
VideoSource::VideoSource(VideoSource&&) noexcept = default;
VideoSource& VideoSource::operator=(VideoSource&&) noexcept = default;

std::optional<Frame> VideoSource::next() {
  if (pending_) {
    ++delivered_;
    return std::exchange(pending_, std::nullopt);
  }
  if (status_.state != SourceStatus::State::kStreaming) return std::nullopt;
  if (params_.max_frames > 0 && delivered_ >= params_.max_frames) {
    status_ = {SourceStatus::State::kEnded, "end of stream"};
    return std::nullopt;
  }
  const long long index = params_.start + delivered_;
  std::string failure;
  std::optional<Frame> frame = read_frame(index, failure);
  if (frame)
    ++delivered_;
  else if (failure.empty())
    status_ = {SourceStatus::State::kEnded, "end of stream"};
  else
    status_ = {SourceStatus::State::kStopped,
               "stopped at frame " + std::to_string(index) + ": " + failure};
  return frame;
}

std::optional<Frame> VideoSource::read_frame(long long index, std::string& failure) {
  Frame frame;
  frame.index = index;
  if (!reader_->read(index, frame, failure)) return std::nullopt;
  // A deferred picture is BGR of the gray frame's size (the decoder makes both).
  const bool deferred = frame.image.empty() && frame.deferred_image && !frame.gray.empty();
  const cv::Mat& checked = deferred ? frame.gray : frame.image;
  if (!deferred && (frame.image.depth() != CV_8U ||
                    (frame.image.channels() != 1 && frame.image.channels() != 3))) {
    failure = "unsupported pixel format (OpenCV type " + std::to_string(frame.image.type()) +
              "): expected 8-bit gray or BGR";
    return std::nullopt;
  }
  if (size_.empty()) {
    // The first frame: checked before a gray copy of a huge image is made.
    failure = eval::frame_size_problem(checked.size());
    if (!failure.empty()) {
      failure = "frame size " + failure;
      return std::nullopt;
    }
  } else if (checked.size() != size_) {
    failure = "frame size " + size_text(checked.size()) + " differs from the first frame's " +
              size_text(size_);
    return std::nullopt;
  }
  if (!deferred && frame.image.channels() == 1)
    frame.gray = frame.image;
  else if (frame.gray.empty())
    cv::cvtColor(frame.image, frame.gray, cv::COLOR_BGR2GRAY);
  return frame;
}

cv::Size VideoSource::size() const {
  return size_;
}
double VideoSource::fps() const {
  return reader_->fps();
}

long long VideoSource::frame_count_hint() const {
  long long count = reader_->frame_count();
  if (count >= 0) count = std::max(0LL, count - params_.start);
  if (params_.max_frames > 0)
    count = count < 0 ? params_.max_frames : std::min(count, params_.max_frames);
  return count;
}

std::string VideoSource::description() const {
  std::string text = reader_->description() + ", " + size_text(size_);
  if (params_.start > 0) text += ", from frame " + std::to_string(params_.start);
  if (params_.max_frames > 0) text += ", at most " + std::to_string(params_.max_frames) + " frames";
  return text;
}

const SourceStatus& VideoSource::status() const {
  return status_;
}

}  // namespace roiflow::video
