// Track log: one record per frame of a tracking run, written as CSV or JSON while the run goes.
//
//   using namespace roiflow;
//   stages::TrackLogWriter log("run/track.csv");        // or .json; opened (and checked) now
//   log.write({.frame = 1, .box = {70, 51, 107, 87}});  // written and flushed at once
//   log.close();                                        // or let the destructor do it
//   for (const stages::TrackRecord& r : stages::read_track_csv("run/track.csv")) ...
//
// CSV: the header `frame,x,y,w,h,vx,vy,mode,lost,ms`, then one line per record with the box to
// 2 decimals, the velocity and ms to 3, mode `local` or `global`, lost `0` or `1`.
// JSON: an array of objects with the same keys and the same rounding (lost is a boolean), one
// record per line: `[\n{"frame":1,...},\n{"frame":2,...}\n]\n`.
//
// Every record is flushed as it is written, so a run that dies leaves a log complete up to its
// last frame. The JSON array is re-closed after every record (the `]` is overwritten by the
// next one), so the file is valid JSON at every moment except during the write of one line:
// even SIGKILL leaves a parseable log. (That rewrite needs a seekable file: not a pipe.) Write
// errors and values a reader could not take back (NaN, infinity, a frame below 1, a negative size)
// throw roiflow::Error.
#pragma once

#include <fstream>
#include <opencv2/core.hpp>
#include <string>
#include <string_view>
#include <vector>

namespace roiflow::stages {

struct TrackRecord {
  enum class Mode { Local, Global };

  long long frame = 1;      // 1-based, like OTB's ground-truth lines
  cv::Rect2f box;           // top-left corner and size, pixels
  cv::Point2f velocity;     // pixels per frame
  Mode mode = Mode::Local;  // which treatment produced the box
  bool lost = false;
  double ms = 0;  // tracker time spent on this frame, milliseconds
};

class TrackLogWriter {
 public:
  // The format follows the extension, `.csv` or `.json` (any case); anything else, or a file
  // that cannot be created, throws roiflow::Error naming the path.
  explicit TrackLogWriter(const std::string& path);
  ~TrackLogWriter();
  TrackLogWriter(const TrackLogWriter&) = delete;
  TrackLogWriter& operator=(const TrackLogWriter&) = delete;

  void write(const TrackRecord& record);
  // Idempotent; writing after close throws.
  void close();

 private:
  void check_stream(const char* action);

  std::string path_;
  bool json_ = false;
  std::ofstream out_;
  long long records_ = 0;
  std::streampos array_end_;  // JSON: where the closing bracket starts, overwritten next
};

// Reads a CSV written by TrackLogWriter. Strict, because scores are computed from it: the header
// must match exactly, every row holds 10 fields, numbers parse completely and are finite (box and
// velocity within the float range), mode is local|global and lost 0|1. Windows line ends are
// accepted. Anything else throws roiflow::Error as `path:line: what was wrong`.
std::vector<TrackRecord> read_track_csv(const std::string& path);
// The same from a file's text held in memory; `name` stands for the path in error messages.
std::vector<TrackRecord> parse_track_csv(std::string_view text, const std::string& name);

}  // namespace roiflow::stages
