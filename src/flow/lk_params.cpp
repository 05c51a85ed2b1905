#include <string>
#include <string_view>
#include <vector>

#include "core/error.hpp"
#include "flow/dense_lk.hpp"
#include "flow/pyramid.hpp"

namespace roiflow::flow {

LkParams LkParams::paper() {
  return LkParams{};
}

// Measured on the 8 Middlebury sequences (mean EPE, see README): from `paper`, 5 levels
// reach the large motions, 8 iterations let the robust weights settle, Cauchy reweighting
// (scale 0.008) discounts occlusions and motion boundaries, and 5x5 medians between levels
// and at the end remove isolated outliers.
LkParams LkParams::accurate() {
  LkParams p;
  p.levels = 5;
  p.iterations = 8;
  p.robust_scale = 0.008;
  p.level_median = 5;
  p.final_median = 5;
  return p;
}

LkParams LkParams::preset(std::string_view name) {
  if (name == "paper") return paper();
  if (name == "accurate") return accurate();
  throw Error("unknown preset '" + std::string(name) + "' (expected paper or accurate)");
}

std::vector<std::string> LkParams::preset_names() {
  return {"paper", "accurate"};
}

void LkParams::validate() const {
  auto fail = [](const std::string& what) { throw Error(what); };
  if (patch < 3 || patch > 31) fail("patch must be in 3..31, got " + std::to_string(patch));
  if (levels < 1 || levels > kMaxLevels) {
    fail("levels must be in 1.." + std::to_string(kMaxLevels) + ", got " + std::to_string(levels));
  }
  if (iterations < 1 || iterations > 50) {
    fail("iterations must be in 1..50, got " + std::to_string(iterations));
  }
  if (!(sigma >= 0.0 && sigma <= 20.0))
    fail("sigma must be in [0, 20], got " + std::to_string(sigma));
  if (!(lambda > 0.0 && lambda <= 1.0)) {
    fail("lambda must be in (0, 1], got " + std::to_string(lambda));
  }
  if (!(robust_scale >= 0.0 && robust_scale <= 1.0)) {
    fail("robust scale must be in [0, 1] (0 = off), got " + std::to_string(robust_scale));
  }
  for (int m : {level_median, final_median}) {
    if (m != 0 && m != 3 && m != 5) {
      fail("median filter size must be 0, 3 or 5, got " + std::to_string(m));
    }
  }
}

const char* to_string(Derivative d) {
  switch (d) {
    case Derivative::HornSchunck:
      return "hs";
    case Derivative::Scharr:
      return "scharr";
    case Derivative::Central:
      return "central";
  }
  return "?";
}

Derivative derivative_from_string(std::string_view name) {
  if (name == "hs" || name == "horn-schunck") return Derivative::HornSchunck;
  if (name == "scharr") return Derivative::Scharr;
  if (name == "central") return Derivative::Central;
  throw Error("unknown derivative '" + std::string(name) + "' (expected hs, scharr or central)");
}

}  // namespace roiflow::flow
