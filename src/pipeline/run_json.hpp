// The run summaries as JSON documents (what `roiflow track --summary` and `roiflow dense
// --summary` write): every field of the typed summary, in a fixed order, with the per-stage
// times as report::stages_json gives them; and a tracking run's two lines for people.
//
//   roiflow::video::VideoSource source("synthetic:10");
//   const auto s = roiflow::pipeline::run_track_video(source, {});
//   nlohmann::ordered_json doc = roiflow::pipeline::to_json(s);
//   doc["input"] = s.input;  // callers add what their document needs beyond the run's figures
//   std::cout << doc.dump(2) << "\n" << roiflow::pipeline::summary_text("track", s);
#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "pipeline/run.hpp"
#include "pipeline/signals.hpp"

namespace roiflow::pipeline {

// mode, frames, global_activations, lost_frames, fps, tracker_fps, tracker_ms_per_frame, wall_s,
// threads, roi, max_in_flight, peak_rss_mb, stages.
nlohmann::ordered_json to_json(const TrackSummary& s);
// `roiflow track --summary`'s document: to_json(s) with the input and the status (how the run
// ended when a signal or a broken input cut it short, else the source's).
nlohmann::ordered_json summary_json(const TrackSummary& s, const Ending& end);
// mode ("dense"), input, frames, pairs, fps, flow_ms_per_pair, wall_s, threads, preset, status,
// peak_rss_mb, stages.
nlohmann::ordered_json to_json(const DenseSummary& s, const std::string& preset);
// "<what>: N frames in S s, F fps overall, tracker T fps (M ms/frame, decode excluded), mode m"
// and "  global activations G, frames lost L, N threads", each ending in '\n'.
std::string summary_text(const std::string& what, const TrackSummary& s);
// "dense <input>: N pairs in S s, F pairs/s, T threads\n".
std::string summary_text(const DenseSummary& s);
// The end of a run command: writes `doc` to `summary` when one is named, and returns what the
// command prints, `text` then "  wrote FILES" (the non-empty paths of `written`, then the
// summary; no line for none).
std::string finish_run(const std::string& summary, const nlohmann::ordered_json& doc,
                       const std::string& text, std::vector<std::string> written);

}  // namespace roiflow::pipeline
