// The figure of a parameter sweep (the paper's Fig. 7 and 8): error (AAE left, EPE right axis)
// above and time per pair below, against the value of one LK parameter (lambda on a log axis).
//
//   const std::vector<roiflow::eval::SweepRow> rows = {
//       {roiflow::eval::SweepParam::Patch, 10, 3.9, 0.28, 12, 8}};
//   const roiflow::report::Plot plot =
//       roiflow::report::sweep_plot(roiflow::eval::SweepParam::Patch, rows, "middlebury");
#pragma once

#include <string>
#include <vector>

#include "eval/sweep.hpp"
#include "report/plot.hpp"

namespace roiflow::report {

Plot sweep_plot(eval::SweepParam param, const std::vector<eval::SweepRow>& rows,
                const std::string& subtitle = "");

}  // namespace roiflow::report
