// libFuzzer target: the OTB ground-truth parser (eval::parse_ground_truth, which
// read_ground_truth uses) and the scoring of what it returns.
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "fuzz_checks.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  roiflow::fuzz::check_ground_truth(std::string_view(reinterpret_cast<const char*>(data), size));
  return 0;
}
