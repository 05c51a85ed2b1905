// The figure of a parameter sweep (the paper's Fig. 7 and 8): error and run time against the
// value of one LK parameter.
//
//   using namespace roiflow;
//   const std::vector<eval::SweepRow> rows = {{eval::SweepParam::Patch, 10, 3.9, 0.28, 12, 8}};
//   report::Plot plot = report::sweep_plot(eval::SweepParam::Patch, rows, "middlebury");
//
// The rows of `param`: error (AAE left, EPE right axis) vs the value above, time (ms per pair)
// below; lambda on a log axis. `subtitle` (e.g. the data set) goes into the title. Throws
// roiflow::Error when no row is of `param`.
#pragma once

#include <string>
#include <vector>

#include "eval/sweep.hpp"
#include "report/plot.hpp"

namespace roiflow::report {

Plot sweep_plot(eval::SweepParam param, const std::vector<eval::SweepRow>& rows,
                const std::string& subtitle = "");

}  // namespace roiflow::report
