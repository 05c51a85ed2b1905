// A self-contained HTML report of a flow evaluation: one file, images embedded, for a browser.
//
//   using namespace roiflow;
//   report::HtmlReport report("roiflow eval data/middlebury", "paper", params);
//   for (const eval::EvalPair& pair : pairs) {
//     eval::EvalImages images;
//     const eval::EvalRow row = eval::evaluate_pair(pair, params, nullptr, &images);
//     report.add(row, images);      // encodes the images now; keeps only the compressed bytes
//   }
//   report.write("report.html");   // atomically
//
// At the top: the LK parameters, a summary table (one row per pair, linked to its section, and
// the mean) and the colour-wheel legend. Per pair: frame t, frame t+1, the ground-truth and the
// estimated flow colour-coded with the same maximum magnitude (the ground truth's), the
// endpoint-error heat map with its colour bar and scale (grey: pixels not scored), and the
// metrics over all and over non-occluded pixels. Images wider than `display_width` are
// downscaled and embedded as base64 JPEG data URIs (about 0.2 MB a pair at 480 px).
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
