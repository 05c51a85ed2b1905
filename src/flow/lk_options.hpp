// The Lucas-Kanade parameters a user may set by name, declared once: each one's name, meaning,
// accepted values and how it changes an LkParams. The command line makes its --patch, --levels,
// ... options from this table, on top of a preset; bindings can do the same.
//
//   roiflow::flow::LkParams p = roiflow::flow::LkParams::preset("accurate");
//   for (const roiflow::flow::LkOption& o : roiflow::flow::lk_options()) {
//     if (std::string(o.name) == "patch") o.set(p, 15, "");
//   }
//   p.validate();
#pragma once

#include <string>
#include <vector>

#include "flow/dense_lk.hpp"

namespace roiflow::flow {

struct LkOption {
  enum class Type { Int, Real, Text };
  const char* name;  // "patch" (the CLI's --patch)
  const char* help;
  Type type;
  double min = 0, max = 0;           // min < max: the accepted range (Text: a number in it)
  std::vector<double> int_choices;   // Int: the accepted values, when not a range
  std::vector<std::string> choices;  // Text: the accepted words (besides the range, if any)
  const char* type_name = nullptr;   // shown for the value instead of the type's
  // Sets the parameter to `number` (Int, Real, Text holding a number) or `word` (Text).
  void (*set)(LkParams& params, double number, const std::string& word);
};

const std::vector<LkOption>& lk_options();

}  // namespace roiflow::flow
