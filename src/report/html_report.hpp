// A self-contained HTML report of a flow evaluation, one file with its images embedded: the LK
// parameters, a summary table and the colour-wheel legend, then per pair the frames, the true
// and estimated flow colour-coded alike, the endpoint-error map and the metrics
// (docs/REPORTS.md).
//
//   const roiflow::flow::LkParams params = roiflow::flow::LkParams::paper();
//   roiflow::report::HtmlReport report("roiflow eval data/middlebury", "paper", params);
//   for (const auto& pair : roiflow::eval::find_middlebury("data/middlebury")) {
//     roiflow::eval::EvalImages images;
//     report.add(roiflow::eval::evaluate_pair(pair, params, nullptr, &images), images);
//   }
//   report.write("report.html");  // atomically
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "eval/flow_eval.hpp"
#include "flow/dense_lk.hpp"

namespace roiflow::report {

class HtmlReport {
 public:
  // Throws roiflow::Error when display_width < 16.
  HtmlReport(std::string title, std::string preset, const flow::LkParams& params,
             int display_width = 480);

  // Throws roiflow::Error when the images are missing or of the wrong type or size.
  void add(const eval::EvalRow& row, const eval::EvalImages& images);
  std::size_t size() const { return sections_.size(); }

  std::string html() const;
  void write(const std::string& path) const;

 private:
  struct Figure {
    std::string caption;
    std::string data_uri;
  };
  struct Section {
    eval::EvalRow row;
    std::vector<Figure> figures;  // frame t, frame t+1, ground truth, estimate, error
    double error_scale = 1;       // px at the top of the heat map's colour bar
  };

  std::string title_;
  std::string preset_;
  flow::LkParams params_;
  int display_width_;
  std::vector<Section> sections_;
};

}  // namespace roiflow::report
