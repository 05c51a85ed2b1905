// libFuzzer target: the track-log CSV parser (eval::parse_track_csv, which read_track_csv
// uses), eval::track_boxes and the scoring of the boxes.
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "fuzz_checks.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  roiflow::fuzz::check_track_csv(std::string_view(reinterpret_cast<const char*>(data), size));
  return 0;
}
