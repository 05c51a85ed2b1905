// TrackLogWriter: the track log written while a run goes, one record per frame, as CSV or JSON
// (the format: eval/track_log.hpp).
//
//   roiflow::stages::TrackLogWriter log("run/track.csv");   // or .json; opened (and checked) now
//   log.write({.frame = 1, .box = {70, 51, 107, 87}});      // written and flushed at once
//   log.close();                                            // or let the destructor do it
//
// Every record is flushed as it is written, so a run that dies leaves a log complete up to its
// last frame. The JSON array is re-closed after every record (the `]` is overwritten by the
// next one), so the file is valid JSON at every moment except during the write of one line:
// even SIGKILL leaves a parseable log. (That rewrite needs a seekable file: not a pipe.) Write
// errors and values a reader could not take back (NaN, infinity, a frame below 1, a negative
// size) throw roiflow::Error.
#pragma once

#include <fstream>
#include <string>

#include "eval/track_log.hpp"

namespace roiflow::stages {

class TrackLogWriter {
 public:
  // The format follows the extension, `.csv` or `.json` (any case); anything else, or a file
  // that cannot be created, throws roiflow::Error naming the path.
  explicit TrackLogWriter(const std::string& path);
  ~TrackLogWriter();
  TrackLogWriter(const TrackLogWriter&) = delete;
  TrackLogWriter& operator=(const TrackLogWriter&) = delete;

  void write(const eval::TrackRecord& record);
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

// Before a run: check_output_path(path, option), and UsageError "<option>: 'p' must end in .csv
// or .json" for a name TrackLogWriter would refuse.
void check_track_log_path(const std::string& path, const std::string& option);

}  // namespace roiflow::stages
