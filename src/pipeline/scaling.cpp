#include "pipeline/scaling.hpp"

#include <tbb/global_control.h>

#include <fmt/format.h>
#include <algorithm>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <set>

#include "core/atomic_write.hpp"
#include "core/error.hpp"
#include "core/text.hpp"
#include "pipeline/frame_graph.hpp"
#include "pipeline/mot_run.hpp"
#include "pipeline/tbb_executor.hpp"
#include "report/run_stats.hpp"
#include "tracking/tracker.hpp"
#include "video/video_source.hpp"

namespace roiflow::pipeline {
namespace {

struct Measured {
  long long frames = 0;
  double wall_s = 0;
  double tracker_ms = 0;
  bool cancelled = false;
  std::string input;
};

Measured run_once(const ScalingOptions& o, int threads) {
  // Caps every oneTBB parallel region of this run (the arena below, and anything the stages
  // start) at `threads`.
  const tbb::global_control cap(tbb::global_control::max_allowed_parallelism,
                                static_cast<std::size_t>(threads));
  video::VideoSourceParams source_params;
  source_params.max_frames = o.max_frames;
  source_params.defer_colour = true;
  video::VideoSource source(o.input, source_params);
  const FrameSource frames = [&] { return source.next(); };

  report::RunStats stats;
  GraphOptions graph;
  graph.threads = threads;
  graph.cancel = o.cancel;
  graph.stats = &stats;
  Measured m;
  m.input = source.description();
  RunReport report;
  if (o.mode == ScalingMode::Dense) {
    report = run_dense(frames, o.lk, {}, graph);
    const nlohmann::ordered_json s = stats.to_json(report.wall_s);
    m.tracker_ms = report::stage_ms_total(s, "flow");
    m.frames = std::max<long long>(0, report.frames - 1);  // pairs
  } else if (o.mode == ScalingMode::Local) {
    MotRunOptions mot;
    mot.params.lk = o.lk;
    mot.threads = threads;
    mot.cancel = o.cancel;
    const MotRun run = track_objects(frames, source.size(), source.fps(), mot);
    report = run.report;
    m.tracker_ms =
        run.summary.at("tracker_ms_per_frame").get<double>() * static_cast<double>(report.frames);
    m.frames = report.frames;
  } else {
    tracking::TrackerParams params;
    params.lk = o.lk;
    params.mode =
        o.mode == ScalingMode::Global ? tracking::TrackMode::Global : tracking::TrackMode::Local;
    TbbExecutor tiles;
    tracking::Tracker tracker(params, &tiles);
    report = run_tracking(frames, tracker, {}, graph);
    const nlohmann::ordered_json s = stats.to_json(report.wall_s);
    m.tracker_ms = report::stage_ms_total(s, "pyramid") + report::stage_ms_total(s, "track");
    m.frames = report.frames;
  }
  m.wall_s = report.wall_s;
  m.cancelled = report.cancelled;
  return m;
}

}  // namespace

const char* to_string(ScalingMode mode) {
  switch (mode) {
    case ScalingMode::Local:
      return "local";
    case ScalingMode::Global:
      return "global";
    case ScalingMode::Dense:
      return "dense";
  }
  return "?";
}

ScalingMode scaling_mode_from_string(const std::string& text) {
  for (ScalingMode m : {ScalingMode::Local, ScalingMode::Global, ScalingMode::Dense}) {
    if (text == to_string(m)) return m;
  }
  throw Error("scaling mode must be local, global or dense, got '" + text + "'");
}

void ScalingOptions::validate() const {
  if (threads.empty()) throw Error("scaling: no thread count given");
  std::set<int> seen;
  for (int t : threads) {
    if (t < 1 || t > kMaxThreads) {
      throw Error("scaling: thread counts must be in 1.." + std::to_string(kMaxThreads) + ", got " +
                  std::to_string(t));
    }
    if (!seen.insert(t).second) {
      throw Error("scaling: thread count " + std::to_string(t) + " given twice");
    }
  }
  if (repeats < 1 || repeats > 100) {
    throw Error("scaling: repeats must be in 1..100, got " + std::to_string(repeats));
  }
  if (max_frames < 0) {
    throw Error("scaling: max_frames must be >= 0, got " + std::to_string(max_frames));
  }
  lk.validate();
}

void fill_speedup(std::vector<ScalingRow>& rows) {
  if (rows.empty()) return;
  const ScalingRow base = rows.front();
  for (ScalingRow& r : rows) {
    r.speedup = base.fps > 0 ? r.fps / base.fps : 0.0;
    r.efficiency = r.threads > 0 ? r.speedup * base.threads / r.threads : 0.0;
  }
}

ScalingResult run_scaling(const ScalingOptions& options) {
  options.validate();
  ScalingResult result;
  result.mode = options.mode;
  for (int threads : options.threads) {
    ScalingRow row;
    row.threads = threads;
    bool have = false;
    for (int k = 0; k < options.repeats; ++k) {
      const Measured m = run_once(options, threads);
      result.input = m.input;
      if (m.cancelled) {
        result.cancelled = true;
        fill_speedup(result.rows);
        return result;
      }
      if (m.frames <= 0 || m.wall_s <= 0) {
        throw Error("scaling: '" + options.input + "' gave no frame to time (" +
                    std::to_string(m.frames) + " frames)");
      }
      if (have && m.wall_s >= row.wall_s) continue;
      have = true;
      row.frames = m.frames;
      row.wall_s = m.wall_s;
      row.fps = static_cast<double>(m.frames) / m.wall_s;
      row.tracker_fps = m.tracker_ms > 0 ? m.frames / (m.tracker_ms / 1000.0) : 0.0;
    }
    result.rows.push_back(row);
  }
  fill_speedup(result.rows);
  return result;
}

std::string scaling_csv(const ScalingResult& result) {
  std::string text = "threads,fps,tracker_fps,speedup,efficiency\n";
  for (const ScalingRow& r : result.rows) {
    text += std::to_string(r.threads) + "," + fixed(r.fps, 2) + "," + fixed(r.tracker_fps, 2) +
            "," + fixed(r.speedup, 3) + "," + fixed(r.efficiency, 3) + "\n";
  }
  return text;
}

report::Plot scaling_plot(const ScalingResult& result) {
  report::Plot plot;
  plot.title = std::string("Thread scaling, ") + to_string(result.mode) + " mode: " + result.input;
  plot.x_label = "threads";
  std::vector<double> threads, fps, tracker_fps, speedup, ideal;
  for (const ScalingRow& r : result.rows) {
    threads.push_back(r.threads);
    fps.push_back(r.fps);
    tracker_fps.push_back(r.tracker_fps);
    speedup.push_back(r.speedup);
    ideal.push_back(result.rows.empty() ? 0.0
                                        : static_cast<double>(r.threads) / result.rows[0].threads);
  }
  report::PlotPanel& rates = plot.panels.emplace_back();
  rates.y_label = result.mode == ScalingMode::Dense ? "pairs per second" : "frames per second";
  rates.y_from_zero = true;
  rates.series.push_back({"fps (wall time)", threads, fps});
  rates.series.push_back({"tracker fps (inside the tracker)", threads, tracker_fps});
  report::PlotPanel& gain = plot.panels.emplace_back();
  gain.y_label = "speedup";
  gain.y_from_zero = true;
  gain.series.push_back({"speedup", threads, speedup});
  gain.series.push_back({"ideal", threads, ideal, report::PlotAxis::Left, false});
  return plot;
}

std::vector<std::string> write_scaling(const ScalingResult& result, const std::string& dir) {
  const std::string csv = (std::filesystem::path(dir) / "scaling.csv").string();
  const std::string svg = (std::filesystem::path(dir) / "scaling.svg").string();
  write_text_atomically(csv, scaling_csv(result));
  report::write_plot_svg(svg, scaling_plot(result));
  return {csv, svg};
}

std::string scaling_text(const ScalingResult& result) {
  std::string text = fmt::format("scaling {} mode, {}\n", to_string(result.mode), result.input) +
                     "threads      fps  tracker_fps  speedup  efficiency\n";
  for (const ScalingRow& row : result.rows) {
    text += fmt::format("{:7d} {:8.1f} {:12.1f} {:8.2f} {:11.2f}\n", row.threads, row.fps,
                        row.tracker_fps, row.speedup, row.efficiency);
  }
  return text;
}

}  // namespace roiflow::pipeline
