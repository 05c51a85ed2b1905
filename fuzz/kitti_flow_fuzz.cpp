// libFuzzer target: the KITTI 16-bit PNG flow reader (src/eval/kitti_flow.cpp) behind
// cv::imdecode, checked by re-encoding (see fuzz_checks.hpp).
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "fuzz_checks.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  roiflow::fuzz::check_kitti_flow(std::string_view(reinterpret_cast<const char*>(data), size));
  return 0;
}
