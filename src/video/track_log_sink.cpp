#include "video/track_log_sink.hpp"

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <string>

#include "core/atomic_write.hpp"
#include "core/error.hpp"

namespace roiflow::video {
namespace {

std::string lowercase_extension(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return ext;
}

}  // namespace

void check_track_log_path(const std::string& path, const std::string& option) {
  check_output_path(path, option);
  const std::string ext = lowercase_extension(path);
  if (ext != ".csv" && ext != ".json") {
    throw UsageError(option + ": '" + path + "' must end in .csv or .json");
  }
}

TrackLogWriter::TrackLogWriter(const std::string& path) : path_(path) {
  const std::string ext = lowercase_extension(path);
  if (ext != ".csv" && ext != ".json") {
    throw Error("track log '" + path + "': unknown format '" + ext + "' (name it .csv or .json)");
  }
  json_ = ext == ".json";
  out_.open(path, std::ios::binary | std::ios::trunc);
  if (!out_) throw Error("cannot create track log '" + path + "'");
  if (json_) {
    out_ << "[";
    array_end_ = out_.tellp();
    out_ << "\n]\n";
  } else {
    out_ << eval::kTrackCsvHeader << "\n";
  }
  out_.flush();
  check_stream("write");
}

TrackLogWriter::~TrackLogWriter() {
  // A destructor may run while an exception unwinds; the log is already flushed and valid.
  try {
    close();
  } catch (const Error&) {
  }
}

void TrackLogWriter::write(const eval::TrackRecord& record) {
  if (!out_.is_open()) {
    throw Error("track log '" + path_ + "' is closed; frame " + std::to_string(record.frame) +
                " not written");
  }
  eval::check_track_record(record, path_);
  if (json_) {
    // One write per record, so a kill can tear at most the line being written.
    out_.seekp(array_end_);
    out_ << (records_ == 0 ? "\n" : ",\n") + eval::track_json_object(record);
    array_end_ = out_.tellp();
    out_ << "\n]\n";
  } else {
    out_ << eval::track_csv_row(record);
  }
  out_.flush();
  check_stream("write");
  ++records_;
}

void TrackLogWriter::close() {
  if (!out_.is_open()) return;
  out_.close();
  check_stream("close");
}

void TrackLogWriter::check_stream(const char* action) {
  if (out_.fail()) throw Error(std::string("cannot ") + action + " track log '" + path_ + "'");
}

}  // namespace roiflow::video
