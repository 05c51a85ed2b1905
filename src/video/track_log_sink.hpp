// The track log written while a run goes, one record per frame, as CSV or JSON (the format:
// eval/track_log.hpp), each record flushed at once and a JSON array kept valid after every
// record, so a run that dies leaves a complete, parseable log up to its last frame.
//
//   roiflow::video::check_track_log_path("run/track.csv", "--log");  // before the run
//   roiflow::video::TrackLogWriter log("run/track.csv");  // or .json; opened (and checked) now
//   roiflow::eval::TrackRecord r;
//   r.box = {70, 51, 107, 87};
//   log.write(r);  // written and flushed at once
//   log.close();                                          // or let the destructor do it
#pragma once

#include <fstream>
#include <string>

#include "eval/track_log.hpp"

namespace roiflow::video {

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

}  // namespace roiflow::video
