// libFuzzer target: the command-line parsing of the shared Lucas-Kanade options
// (apps/cli_common.cpp: add_lk_options, lk_params). The input is an argument list, one argument
// per line. CLI11's parse errors and roiflow's UsageError are clean refusals; anything else, a
// crash, undefined behaviour, or accepted parameters that are out of range, is a bug.
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "cli_common.hpp"
#include "pipeline/tbb_executor.hpp"

namespace {

void require(bool ok, const char* what) {
  if (!ok) throw std::logic_error(what);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace roiflow;
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  std::vector<std::string> args;  // CLI11 takes them last first
  for (std::size_t start = 0; start <= text.size() && args.size() < 32;) {
    const std::size_t newline = std::min(text.find('\n', start), text.size());
    args.emplace_back(text.substr(start, newline - start));
    start = newline + 1;
  }
  std::reverse(args.begin(), args.end());

  CLI::App app{"fuzz"};
  cli::LkOptions lk;
  cli::add_lk_options(app, lk);
  try {
    app.parse(args);
  } catch (const CLI::Error&) {
    return 0;
  }
  flow::LkParams params;
  try {
    params = cli::lk_params(lk);
  } catch (const cli::UsageError&) {
    return 0;
  }
  params.validate();  // must not throw: lk_params promised valid parameters
  require(lk.threads >= 1 && lk.threads <= pipeline::kMaxThreads, "threads out of range");
  require(!lk.patch || params.patch == *lk.patch, "--patch not applied");
  require(!lk.levels || params.levels == *lk.levels, "--levels not applied");
  require(!lk.iterations || params.iterations == *lk.iterations, "--iterations not applied");
  require(!lk.sigma || params.sigma == *lk.sigma, "--sigma not applied");
  require(!lk.lambda || params.lambda == *lk.lambda, "--lambda not applied");
  require(!lk.robust_scale || params.robust_scale == *lk.robust_scale,
          "--robust-scale not applied");
  require(!lk.level_median || params.level_median == *lk.level_median,
          "--level-median not applied");
  require(!lk.final_median || params.final_median == *lk.final_median,
          "--final-median not applied");
  return 0;
}
