// The track-log format: one record per object and frame of a tracking run, as CSV or JSON, and
// its strict CSV reader. CSV: the header `frame,id,x,y,w,h,vx,vy,mode,lost,ms`, then one line per
// record with the object's id, the box to 2 decimals, the velocity and ms to 3, mode `local` or
// `global`, lost `0` or `1`. The reader also takes the logs written before the id column
// (`frame,x,y,w,h,vx,vy,mode,lost,ms`: every record gets id 1). JSON: an array of objects with the
// same keys and rounding, one per line. The writer that keeps a file valid while a run goes is
// video::TrackLogWriter.
//
//   roiflow::eval::TrackRecord r;
//   r.box = {70, 51, 107, 87};  // frame 1, id 1
//   const std::string csv =
//       std::string(roiflow::eval::kTrackCsvHeader) + "\n" + roiflow::eval::track_csv_row(r);
//   const auto records = roiflow::eval::parse_track_csv(csv, "memory");  // r, rounded
#pragma once

#include <opencv2/core.hpp>
#include <string>
#include <string_view>
#include <vector>

namespace roiflow::eval {

struct TrackRecord {
  enum class Mode { Local, Global };

  long long frame = 1;      // 1-based, like OTB's ground-truth lines
  cv::Rect2f box;           // top-left corner and size, pixels
  cv::Point2f velocity;     // pixels per frame
  Mode mode = Mode::Local;  // which treatment produced the box
  bool lost = false;
  double ms = 0;     // tracker time spent on this frame, milliseconds
  long long id = 1;  // the object's id (>= 1); single-object runs use 1
};

inline constexpr std::string_view kTrackCsvHeader = "frame,id,x,y,w,h,vx,vy,mode,lost,ms";
// The header of logs written before the id column; still read.
inline constexpr std::string_view kTrackCsvHeaderV1 = "frame,x,y,w,h,vx,vy,mode,lost,ms";

const char* to_string(TrackRecord::Mode mode);  // "local" | "global"

// Throws roiflow::Error, naming `path` and the frame, for a value a reader could not take back:
// NaN, infinity, a frame below 1, a negative size.
void check_track_record(const TrackRecord& record, const std::string& path);
// One CSV line, '\n' included.
std::string track_csv_row(const TrackRecord& record);
// One JSON object on one line, without separators; the same values as the CSV line.
std::string track_json_object(const TrackRecord& record);

// Reads a track-log CSV. Strict, because scores are computed from it: the header must match
// exactly (either header), every row holds its 11 (10 without id) fields, numbers parse completely
// and are finite (box and velocity within the float range), mode is local|global and lost 0|1.
// Windows line ends are accepted. Anything else throws roiflow::Error as `path:line: what was
// wrong`.
std::vector<TrackRecord> read_track_csv(const std::string& path);
// The same from a file's text held in memory; `name` stands for the path in error messages.
std::vector<TrackRecord> parse_track_csv(std::string_view text, const std::string& name);

}  // namespace roiflow::eval
