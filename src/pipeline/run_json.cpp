#include "pipeline/run_json.hpp"

#include <fmt/format.h>

#include <algorithm>

#include "core/atomic_write.hpp"
#include "core/text.hpp"

namespace roiflow::pipeline {

nlohmann::ordered_json to_json(const TrackSummary& s) {
  return {{"mode", s.mode},
          {"frames", s.frames},
          {"global_activations", s.global_activations},
          {"lost_frames", s.lost_frames},
          {"fps", s.fps},
          {"tracker_fps", s.tracker_fps},
          {"tracker_ms_per_frame", s.tracker_ms_per_frame},
          {"wall_s", s.wall_s},
          {"threads", s.threads},
          {"roi", s.roi},
          {"max_in_flight", s.max_in_flight},
          {"peak_rss_mb", s.peak_rss_mb},
          {"stages", report::stages_json(s.stages)}};
}

nlohmann::ordered_json to_json(const DenseSummary& s, const std::string& preset) {
  return {{"mode", "dense"},
          {"input", s.input},
          {"frames", s.frames},
          {"pairs", s.pairs},
          {"fps", s.fps},
          {"flow_ms_per_pair", s.flow_ms_per_pair},
          {"wall_s", s.wall_s},
          {"threads", s.threads},
          {"preset", preset},
          {"status", s.status},
          {"peak_rss_mb", s.peak_rss_mb},
          {"stages", report::stages_json(s.stages)}};
}

nlohmann::ordered_json summary_json(const TrackSummary& s, const Ending& end) {
  nlohmann::ordered_json doc = to_json(s);
  doc["input"] = s.input;
  doc["status"] = end.message.empty() ? s.status : end.message;
  return doc;
}

std::string summary_text(const std::string& what, const TrackSummary& s) {
  return fmt::format(
      "{}: {} frames in {:.2f} s, {:.1f} fps overall, tracker {:.1f} fps ({:.3f} ms/frame, decode "
      "excluded), mode {}\n  global activations {}, frames lost {}, {} threads\n",
      what, s.frames, s.wall_s, s.fps, s.tracker_fps, s.tracker_ms_per_frame, s.mode,
      s.global_activations, s.lost_frames, s.threads);
}

std::string summary_text(const DenseSummary& s) {
  return fmt::format("dense {}: {} pairs in {:.2f} s, {:.1f} pairs/s, {} threads\n", s.input,
                     s.pairs, s.wall_s, s.fps, s.threads);
}

std::string finish_run(const std::string& summary, const nlohmann::ordered_json& doc,
                       const std::string& text, std::vector<std::string> written) {
  if (!summary.empty()) {
    write_text_atomically(summary, doc.dump(2) + "\n");
    written.push_back(summary);
  }
  written.erase(std::remove(written.begin(), written.end(), std::string()), written.end());
  return text + (written.empty() ? "" : "  wrote " + joined(written) + "\n");
}

}  // namespace roiflow::pipeline
