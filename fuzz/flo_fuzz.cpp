// libFuzzer target: the Middlebury .flo reader (eval::parse_flo, which read_flo uses).
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "fuzz_checks.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  roiflow::fuzz::check_flo(std::string_view(reinterpret_cast<const char*>(data), size));
  return 0;
}
