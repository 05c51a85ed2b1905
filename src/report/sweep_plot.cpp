#include "report/sweep_plot.hpp"

#include <string>

#include "core/error.hpp"

namespace roiflow::report {

Plot sweep_plot(eval::SweepParam param, const std::vector<eval::SweepRow>& rows,
                const std::string& subtitle) {
  std::vector<double> x, aae, epe, ms;
  int pairs = 0;
  for (const eval::SweepRow& r : rows) {
    if (r.param != param) continue;
    x.push_back(r.value);
    aae.push_back(r.aae_deg);
    epe.push_back(r.epe);
    ms.push_back(r.ms_per_pair);
    pairs = r.pairs;
  }
  if (x.empty())
    throw Error("no sweep rows for " + std::string(eval::to_string(param)) + " to plot");

  Plot plot;
  const std::string suffix =
      subtitle.empty() ? "" : " (" + subtitle + ", mean of " + std::to_string(pairs) + " pairs)";
  switch (param) {
    case eval::SweepParam::Patch:
      plot.title = "Error and run time vs patch size" + suffix;
      plot.x_label = "patch size (px, side of the square window)";
      break;
    case eval::SweepParam::Iterations:
      plot.title = "Error and run time vs iterations" + suffix;
      plot.x_label = "iterations per pyramid level";
      break;
    case eval::SweepParam::Levels:
      plot.title = "Error and run time vs pyramid levels" + suffix;
      plot.x_label = "pyramid levels";
      break;
    case eval::SweepParam::Sigma:
      plot.title = "Error and run time vs pretreatment smoothing" + suffix;
      plot.x_label = "Gaussian sigma (px, 0 = no smoothing)";
      break;
    case eval::SweepParam::Lambda:
      plot.title = "Error and run time vs regularisation" + suffix;
      plot.x_label = "Tikhonov lambda ((intensity/px)^2, intensities in [0, 1]; log scale)";
      plot.x_log = true;
      break;
  }
  PlotPanel& error = plot.panels.emplace_back();
  error.y_label = "mean AAE (deg)";
  error.y2_label = "mean EPE (px)";
  error.series.push_back({"AAE (deg, left axis)", x, aae, PlotAxis::Left});
  error.series.push_back({"EPE (px, right axis)", x, epe, PlotAxis::Right});
  PlotPanel& time = plot.panels.emplace_back();
  time.y_label = "run time (ms per pair)";
  time.y_from_zero = true;
  time.series.push_back({"dense flow time per pair (ms)", x, ms, PlotAxis::Left});
  return plot;
}

}  // namespace roiflow::report
