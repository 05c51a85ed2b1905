#include "eval/synthetic_input.hpp"

#include <charconv>
#include <optional>
#include <system_error>

#include "core/error.hpp"
#include "core/text.hpp"
#include "eval/image_io.hpp"

namespace roiflow::eval {
namespace {

// Digits only (no sign, no spaces), within long long.
std::optional<long long> number(std::string_view text) {
  if (text.empty() || text.size() > 12) return std::nullopt;
  long long value = 0;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (ec != std::errc() || end != text.data() + text.size()) return std::nullopt;
  for (char c : text)
    if (c < '0' || c > '9') return std::nullopt;
  return value;
}

}  // namespace

bool is_synthetic_input(std::string_view input) {
  return input.substr(0, kSyntheticInputPrefix.size()) == kSyntheticInputPrefix;
}

SyntheticInput parse_synthetic_input(const std::string& input) {
  const auto bad = [&](const std::string& why) {
    return Error("bad synthetic input '" + input + "': " + why +
                 " (expected synthetic:N[:WxH][:OBJECTS], like synthetic:300:640x480:16)");
  };
  if (!is_synthetic_input(input)) throw bad("it does not start with synthetic:");
  std::string_view spec = std::string_view(input).substr(kSyntheticInputPrefix.size());
  const std::vector<std::string_view> fields = split_view(spec, ':');
  if (fields.size() > 3) throw bad("too many fields");
  SyntheticInput out;
  const auto frames = number(fields[0]);
  if (!frames || *frames < 1 || *frames > 1'000'000'000)
    throw bad("the frame count must be in 1..1000000000");
  out.frames = *frames;
  std::size_t next = 1;
  if (next < fields.size() &&
      (fields[next].find('x') != std::string_view::npos || fields.size() == 3)) {
    const std::string_view size_text = fields[next++];
    const auto x = size_text.find('x');
    const std::string_view w = size_text.substr(0, x);
    const std::string_view h = x == std::string_view::npos ? "" : size_text.substr(x + 1);
    const auto width = number(w);
    const auto height = number(h);
    if (!width || !height || *width < 64 || *height < 64 || *width > kMaxFrameSide ||
        *height > kMaxFrameSide)
      throw bad("the size must be WxH with each side in 64.." + std::to_string(kMaxFrameSide));
    out.size = {static_cast<int>(*width), static_cast<int>(*height)};
    check_frame_size(out.size, "synthetic input '" + input + "'");
  }
  if (next < fields.size()) {
    const auto objects = number(fields[next]);
    if (!objects || *objects < 1 || *objects > kMaxTrafficObjects)
      throw bad("the object count must be in 1.." + std::to_string(kMaxTrafficObjects));
    out.objects = static_cast<int>(*objects);
  }
  return out;
}

TrafficSceneParams traffic_params(const SyntheticInput& spec) {
  TrafficSceneParams p;
  p.size = spec.size;
  p.frames = spec.frames;
  p.objects = spec.objects;
  return p;
}

}  // namespace roiflow::eval
