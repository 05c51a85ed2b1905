#include "eval/track_log.hpp"

#include <charconv>
#include <cmath>
#include <limits>
#include <nlohmann/json.hpp>
#include <string_view>
#include <system_error>

#include "core/error.hpp"
#include "core/text.hpp"
#include "core/text_file.hpp"
#include "eval/line_error_impl.hpp"

namespace roiflow::eval {
namespace {

constexpr int kBoxDecimals = 2;
constexpr int kVelocityDecimals = 3;
constexpr int kMsDecimals = 3;

// Without the sign of a value that rounds to zero: "-0.00" would read back as a distinct value
// in some tools and looks like a sign error.
std::string log_fixed(double value, int decimals) {
  std::string text = fixed(value, decimals);
  if (text.front() == '-' && text.find_first_not_of("-0.") == std::string::npos) text.erase(0, 1);
  return text;
}

// The JSON log carries exactly the values of the CSV log, so both score identically.
double rounded(double value, int decimals) {
  return std::stod(log_fixed(value, decimals));
}

// --- reading ---------------------------------------------------------------------------------

using detail::LineError;

std::vector<std::string_view> split_commas(std::string_view line) {
  return split_view(line, ',');
}

// Boxes and velocities are floats: a larger value would become infinity (found by fuzzing).
float parse_float(std::string_view field, const char* name, const LineError& error) {
  const double value = error.number(field, name);
  if (std::abs(value) > std::numeric_limits<float>::max()) {
    error.fail(std::string(name) + " " + quoted_excerpt(field) + " is too large");
  }
  return static_cast<float>(value);
}

TrackRecord parse_log_row(std::string_view line, bool with_id, const LineError& error) {
  std::vector<std::string_view> f = split_commas(line);
  const std::size_t expected = with_id ? 11 : 10;
  if (f.size() != expected) {
    error.fail("expected " + std::to_string(expected) + " fields (" +
               std::string(with_id ? kTrackCsvHeader : kTrackCsvHeaderV1) + "), got " +
               std::to_string(f.size()));
  }
  TrackRecord r;
  const auto [end, ec] = std::from_chars(f[0].data(), f[0].data() + f[0].size(), r.frame);
  if (ec != std::errc() || end != f[0].data() + f[0].size() || r.frame < 1) {
    error.fail("frame " + quoted_excerpt(f[0]) + " is not a frame number (1, 2, ...)");
  }
  if (with_id) {
    const auto [id_end, id_ec] = std::from_chars(f[1].data(), f[1].data() + f[1].size(), r.id);
    if (id_ec != std::errc() || id_end != f[1].data() + f[1].size() || r.id < 1) {
      error.fail("id " + quoted_excerpt(f[1]) + " is not an object id (1, 2, ...)");
    }
    f.erase(f.begin() + 1);
  }
  r.box.x = parse_float(f[1], "x", error);
  r.box.y = parse_float(f[2], "y", error);
  r.box.width = parse_float(f[3], "w", error);
  r.box.height = parse_float(f[4], "h", error);
  if (r.box.width < 0 || r.box.height < 0) {
    error.fail("negative box size " + std::string(f[3]) + "x" + std::string(f[4]));
  }
  r.velocity.x = parse_float(f[5], "vx", error);
  r.velocity.y = parse_float(f[6], "vy", error);
  if (f[7] == "local") {
    r.mode = TrackRecord::Mode::Local;
  } else if (f[7] == "global") {
    r.mode = TrackRecord::Mode::Global;
  } else {
    error.fail("mode " + quoted_excerpt(f[7]) + " is neither local nor global");
  }
  if (f[8] != "0" && f[8] != "1")
    error.fail("lost " + quoted_excerpt(f[8]) + " is neither 0 nor 1");
  r.lost = f[8] == "1";
  r.ms = error.number(f[9], "ms");
  return r;
}

}  // namespace

const char* to_string(TrackRecord::Mode mode) {
  return mode == TrackRecord::Mode::Local ? "local" : "global";
}

void check_track_record(const TrackRecord& r, const std::string& path) {
  const std::string where = "track log '" + path + "', frame " + std::to_string(r.frame) + ": ";
  if (r.frame < 1) throw Error(where + "frames are numbered from 1");
  if (r.id < 1) throw Error(where + "object ids are numbered from 1");
  const double values[] = {r.box.x,      r.box.y,      r.box.width, r.box.height,
                           r.velocity.x, r.velocity.y, r.ms};
  const char* names[] = {"x", "y", "w", "h", "vx", "vy", "ms"};
  for (int i = 0; i < 7; ++i) {
    if (!std::isfinite(values[i])) {
      throw Error(where + names[i] + " is " + std::to_string(values[i]) + ", not a finite number");
    }
  }
  if (r.box.width < 0 || r.box.height < 0) {
    throw Error(where + "negative box size " + std::to_string(r.box.width) + "x" +
                std::to_string(r.box.height));
  }
}

std::string track_csv_row(const TrackRecord& r) {
  return std::to_string(r.frame) + "," + std::to_string(r.id) + "," +
         log_fixed(r.box.x, kBoxDecimals) + "," + log_fixed(r.box.y, kBoxDecimals) + "," +
         log_fixed(r.box.width, kBoxDecimals) + "," + log_fixed(r.box.height, kBoxDecimals) + "," +
         log_fixed(r.velocity.x, kVelocityDecimals) + "," +
         log_fixed(r.velocity.y, kVelocityDecimals) + "," + to_string(r.mode) + "," +
         (r.lost ? "1" : "0") + "," + log_fixed(r.ms, kMsDecimals) + "\n";
}

std::string track_json_object(const TrackRecord& r) {
  const nlohmann::ordered_json object = {{"frame", r.frame},
                                         {"id", r.id},
                                         {"x", rounded(r.box.x, kBoxDecimals)},
                                         {"y", rounded(r.box.y, kBoxDecimals)},
                                         {"w", rounded(r.box.width, kBoxDecimals)},
                                         {"h", rounded(r.box.height, kBoxDecimals)},
                                         {"vx", rounded(r.velocity.x, kVelocityDecimals)},
                                         {"vy", rounded(r.velocity.y, kVelocityDecimals)},
                                         {"mode", to_string(r.mode)},
                                         {"lost", r.lost},
                                         {"ms", rounded(r.ms, kMsDecimals)}};
  return object.dump();
}

std::vector<TrackRecord> parse_track_csv(std::string_view text, const std::string& name) {
  std::vector<TrackRecord> records;
  bool with_id = true;
  const long long lines = for_each_line(text, [&](long long number, std::string_view line) {
    const LineError error(name, number);
    if (number == 1) {
      if (line != kTrackCsvHeader && line != kTrackCsvHeaderV1) {
        error.fail("header " + quoted_excerpt(line) + " is not '" + std::string(kTrackCsvHeader) +
                   "' (or, before the id column, '" + std::string(kTrackCsvHeaderV1) + "')");
      }
      with_id = line == kTrackCsvHeader;
      return;
    }
    records.push_back(parse_log_row(line, with_id, error));
  });
  if (lines == 0)
    LineError(name, 1).fail("empty file, expected '" + std::string(kTrackCsvHeader) + "'");
  return records;
}

std::vector<TrackRecord> read_track_csv(const std::string& path) {
  return parse_track_csv(read_text_file(path, "track log"), path);
}

}  // namespace roiflow::eval
