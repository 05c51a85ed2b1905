// Known targets (--init-file): `id,x,y,w,h` lines, declared in tracking/multi_tracker.hpp.
#include <charconv>
#include <cmath>
#include <string>

#include "core/error.hpp"
#include "core/text.hpp"
#include "core/text_file.hpp"
#include "tracking/multi_tracker.hpp"

namespace roiflow::tracking {

std::vector<KnownTarget> parse_known_targets(std::string_view text, const std::string& name) {
  std::vector<KnownTarget> out;
  for_each_line(text, [&](long long number, std::string_view line) {
    const std::string where = name + ":" + std::to_string(number) + ": ";
    if (line.empty() || line.front() == '#') return;
    const std::vector<std::string_view> f = split_view(line, ',');
    if (f.size() != 5) {
      throw Error(where + "expected 5 fields id,x,y,w,h, got " + std::to_string(f.size()));
    }
    KnownTarget k;
    const auto [id_end, id_ec] = std::from_chars(f[0].data(), f[0].data() + f[0].size(), k.id);
    if (id_ec != std::errc() || id_end != f[0].data() + f[0].size() || k.id < 1)
      throw Error(where + "id " + quoted_excerpt(f[0]) + " is not an id (1, 2, ...)");
    double v[4];
    const char* names[] = {"x", "y", "w", "h"};
    for (int i = 0; i < 4; ++i) {
      const std::string_view s = f[static_cast<std::size_t>(i) + 1];
      const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), v[i]);
      if (ec != std::errc() || end != s.data() + s.size() || !std::isfinite(v[i]) ||
          std::abs(v[i]) > 1e7)
        throw Error(where + names[i] + " " + quoted_excerpt(s) + " is not a finite number");
    }
    if (!(v[2] > 0 && v[3] > 0)) throw Error(where + "the box needs a positive width and height");
    for (const KnownTarget& other : out)
      if (other.id == k.id) throw Error(where + "id " + std::to_string(k.id) + " given twice");
    k.box = cv::Rect2f(static_cast<float>(v[0]), static_cast<float>(v[1]), static_cast<float>(v[2]),
                       static_cast<float>(v[3]));
    out.push_back(k);
  });
  if (out.empty()) throw Error(name + ": no target (expected id,x,y,w,h lines)");
  return out;
}

std::vector<KnownTarget> read_known_targets(const std::string& path) {
  return parse_known_targets(read_text_file(path, "targets file"), path);
}

}  // namespace roiflow::tracking
