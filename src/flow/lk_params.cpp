#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "core/error.hpp"
#include "flow/dense_lk.hpp"
#include "flow/large_motion.hpp"
#include "flow/pyramid.hpp"

namespace roiflow::flow {

LkParams LkParams::paper() {
  return LkParams{};
}

// Chosen on Middlebury, KITTI, Sintel and FlyingChairs together (docs/ACCURACY.md): 8
// iterations let the robust weights settle, Cauchy reweighting (scale 0.008) discounts
// occlusions and motion boundaries, 5x5 medians between levels and at the end remove isolated
// outliers; the coarse search and the candidate fusion follow motions larger than a patch, and
// an 8x8 patch keeps motion boundaries sharper than the paper's 10x10.
LkParams LkParams::accurate() {
  LkParams p;
  p.patch = 8;
  p.levels = 0;
  p.iterations = 8;
  p.robust_scale = 0.008;
  p.level_median = 5;
  p.final_median = 5;
  p.search_radius = 14;
  p.fuse_far_step = 16;
  p.fuse_step = 6;
  p.fuse_finest_level = 1;
  p.mask_outside = true;
  return p;
}

// The realtime choice for large motions, set as DIS ULTRAFAST is: the search on a coarser level
// (shorter side 20 px), LK from there down to level 2 (a quarter of the resolution) and the
// flow upsampled. No candidate fusion: at these levels it traded KITTI against Sintel and cost
// a sixth of the time (docs/ACCURACY.md).
LkParams LkParams::fast() {
  LkParams p;
  p.levels = 0;
  p.coarsest_side = 20;
  p.iterations = 5;
  p.robust_scale = 0.008;
  p.final_median = 3;
  p.search_radius = 8;
  p.mask_outside = true;
  p.finest_level = 2;
  return p;
}

LkParams LkParams::preset(std::string_view name) {
  if (name == "paper") return paper();
  if (name == "accurate") return accurate();
  if (name == "fast") return fast();
  throw Error("unknown preset '" + std::string(name) + "' (expected paper, accurate or fast)");
}

std::vector<std::string> LkParams::preset_names() {
  return {"paper", "accurate", "fast"};
}

void LkParams::validate() const {
  auto fail = [](const std::string& what) { throw Error(what); };
  if (patch < 3 || patch > 31) fail("patch must be in 3..31, got " + std::to_string(patch));
  if (levels < 0 || levels > kMaxLevels) {
    fail("levels must be in 1.." + std::to_string(kMaxLevels) + " or 0 (auto), got " +
         std::to_string(levels));
  }
  if (iterations < 1 || iterations > 50) {
    fail("iterations must be in 1..50, got " + std::to_string(iterations));
  }
  if (finest_iterations < 0 || finest_iterations > 50) {
    fail("finest iterations must be in 0..50 (0 = iterations), got " +
         std::to_string(finest_iterations));
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
  if (!(expected_motion >= 0.0 && expected_motion <= 1e5)) {
    fail("expected motion must be in [0, 100000] pixels (0 = from the frame size), got " +
         std::to_string(expected_motion));
  }
  if (search_radius < 0 || search_radius > kMaxSearchRadius) {
    fail("search radius must be in 0.." + std::to_string(kMaxSearchRadius) + " (0 = off), got " +
         std::to_string(search_radius));
  }
  if (coarsest_side < kMinLevelSide || coarsest_side > 480) {
    fail("coarsest side must be in " + std::to_string(kMinLevelSide) + "..480 pixels, got " +
         std::to_string(coarsest_side));
  }
  for (const auto& [name, step] :
       {std::pair{"fuse step", fuse_step}, std::pair{"fuse far step", fuse_far_step}}) {
    if (step < 0 || step > 32) {
      fail(std::string(name) + " must be in 0..32 (0 = off), got " + std::to_string(step));
    }
  }
  for (const auto& [name, level] : {std::pair{"fuse finest level", fuse_finest_level},
                                    std::pair{"fuse far finest level", fuse_far_finest_level},
                                    std::pair{"finest level", finest_level}}) {
    if (level < 0 || level >= kMaxLevels) {
      fail(std::string(name) + " must be in 0.." + std::to_string(kMaxLevels - 1) + ", got " +
           std::to_string(level));
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
