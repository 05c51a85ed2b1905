#include "pipeline/compare.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <csignal>
#include <filesystem>
#include <iostream>

#include "core/atomic_write.hpp"
#include "core/error.hpp"
#include "core/text.hpp"
#include "pipeline/run_json.hpp"
#include "report/plot.hpp"
#include "report/progress.hpp"

namespace roiflow::pipeline {
namespace {

namespace fs = std::filesystem;

// Linear interpolation between order statistics; `sorted` is not empty.
double percentile(const std::vector<double>& sorted, double p) {
  const double at = p * static_cast<double>(sorted.size() - 1);
  const std::size_t i = static_cast<std::size_t>(at);
  if (i + 1 >= sorted.size()) return sorted.back();
  return sorted[i] + (at - static_cast<double>(i)) * (sorted[i + 1] - sorted[i]);
}

// One run; its log and summary go to `stem`.csv/.json in out_dir unless `stem` is empty.
CompareRun compare_run(const CompareOptions& o, const char* mode, int patch,
                       const std::string& stem) {
  if (report::Progress::stderr_is_terminal() && o.run.progress) {
    std::cerr << "compare: " << mode << " mode, patch " << patch << " ..." << std::endl;
  }
  TrackRunOptions run = o.run;
  run.tracker.mode = tracking::track_mode_from_string(mode);
  run.tracker.lk.patch = patch;
  run.tracker.validate();
  run.log = stem.empty() ? "" : (fs::path(o.out_dir) / (stem + ".csv")).string();
  run.video.clear();
  run.progress = false;
  run.keep_records = true;
  video::VideoSource source(o.input, source_params(o.source));
  CompareRun r;
  r.mode = mode;
  r.patch = patch;
  r.summary = run_track_video(source, run);
  if (r.summary.end == RunEnd::InputStopped) {
    throw Error(fmt::format("--compare: the {} run (patch {}) failed: input {}", mode, patch,
                            r.summary.status));
  }
  if (r.summary.end == RunEnd::Cancelled) return r;
  if (!stem.empty()) {
    nlohmann::ordered_json doc = to_json(r.summary);
    doc["input"] = r.summary.input;
    doc["status"] = r.summary.status;
    write_text_atomically((fs::path(o.out_dir) / (stem + ".json")).string(), doc.dump(2) + "\n");
  }
  for (const eval::TrackRecord& record : r.summary.records)
    r.ms.push_back(record.ms);
  if (r.ms.empty()) throw Error(fmt::format("--compare: the {} run tracked no frame", mode));
  std::vector<double> sorted = r.ms;
  std::sort(sorted.begin(), sorted.end());
  r.ms_median = percentile(sorted, 0.5);
  r.ms_p95 = percentile(sorted, 0.95);
  for (double v : sorted)
    r.ms_mean += v;
  r.ms_mean /= static_cast<double>(sorted.size());
  return r;
}

nlohmann::ordered_json run_json(const CompareRun& r) {
  return {{"mode", r.mode},
          {"patch", r.patch},
          {"frames", r.summary.frames},
          {"fps", r.summary.fps},
          {"tracker_fps", r.summary.tracker_fps},
          {"ms_median", r.ms_median},
          {"ms_p95", r.ms_p95},
          {"ms_mean", r.ms_mean},
          {"global_activations", r.summary.global_activations},
          {"peak_rss_mb", r.summary.peak_rss_mb}};
}

std::string csv_row(const CompareRun& r) {
  return fmt::format("{},{},{},{:.2f},{:.2f},{:.3f},{:.3f},{:.3f},{},{:.1f}\n", r.patch, r.mode,
                     r.summary.frames, r.summary.fps, r.summary.tracker_fps, r.ms_median, r.ms_p95,
                     r.ms_mean, r.summary.global_activations, r.summary.peak_rss_mb);
}

double fps_speedup(const CompareResult& r) {
  return r.global.summary.tracker_fps > 0
             ? r.local.summary.tracker_fps / r.global.summary.tracker_fps
             : 0.0;
}

std::string input_name(const CompareOptions& o) {
  return fs::path(o.input).filename().string();
}

report::Plot frames_plot(const CompareResult& r, const CompareOptions& o) {
  report::Plot plot;
  plot.title = fmt::format("Tracker time per frame, local vs global ({}, patch {})", input_name(o),
                           r.local.patch);
  plot.x_label = "frame index";
  report::PlotPanel& panel = plot.panels.emplace_back();
  panel.y_label = "tracker time (ms per frame)";
  panel.y_from_zero = true;
  for (const CompareRun* run : {&r.local, &r.global}) {
    report::PlotSeries s;
    s.name = run->mode + " (median " + fixed(run->ms_median, 2) + " ms)";
    for (std::size_t i = 0; i < run->ms.size(); ++i) {
      s.x.push_back(static_cast<double>(o.source.start + static_cast<long long>(i) + 1));
      s.y.push_back(run->ms[i]);
    }
    s.markers = run->ms.size() <= 60;
    panel.series.push_back(std::move(s));
  }
  return plot;
}

report::Plot patches_plot(const CompareResult& r, const CompareOptions& o) {
  report::Plot plot;
  plot.title = "Tracker time vs patch size, local vs global (" + input_name(o) + ")";
  plot.x_label = "patch size (px)";
  plot.panels.resize(2);  // references taken after the last resize stay valid
  report::PlotPanel& time = plot.panels[0];
  time.y_label = "tracker time (ms per frame, median)";
  time.y_from_zero = true;
  report::PlotPanel& ratio = plot.panels[1];
  ratio.y_label = "global / local time (x)";
  ratio.y_from_zero = true;
  report::PlotSeries l{"local", {}, {}}, g{"global", {}, {}}, s{"speed-up of local", {}, {}};
  for (const auto& [lr, gr] : r.patches) {
    l.x.push_back(lr.patch);
    l.y.push_back(lr.ms_median);
    g.x.push_back(gr.patch);
    g.y.push_back(gr.ms_median);
    s.x.push_back(lr.patch);
    s.y.push_back(speedup(lr, gr));
  }
  time.series = {l, g};
  ratio.series = {s};
  return plot;
}

}  // namespace

double speedup(const CompareRun& local, const CompareRun& global) {
  return local.ms_median > 0 ? global.ms_median / local.ms_median : 0.0;
}

CompareResult run_compare(const CompareOptions& o) {
  if (std::all_of(o.input.begin(), o.input.end(),
                  [](unsigned char c) { return std::isdigit(c); })) {
    throw UsageError("--compare needs a video file or an image folder: a camera (" + o.input +
                     ") would show each mode different frames");
  }
  // Opened here only to check the input and the init box before any run starts.
  check_init_inside(o.run.tracker.init, video::VideoSource(o.input, source_params(o.source)).size(),
                    0.f);
  std::error_code ec;
  if (fs::exists(o.out_dir, ec) && !fs::is_directory(o.out_dir, ec)) {
    throw Error("--compare-out: '" + o.out_dir + "' exists and is not a directory");
  }
  fs::create_directories(o.out_dir, ec);
  if (ec) throw Error("--compare-out: cannot create '" + o.out_dir + "': " + ec.message());
  const int patch = o.run.tracker.lk.patch;
  CompareResult r;
  const auto cancelled = [&](const CompareRun& run) {
    r.cancelled = run.summary.end == RunEnd::Cancelled;
    return r.cancelled;
  };
  r.local = compare_run(o, "local", patch, "local");
  if (cancelled(r.local)) return r;
  r.global = compare_run(o, "global", patch, "global");
  if (cancelled(r.global)) return r;
  for (int p : o.patches) {
    if (p == patch) {
      r.patches.emplace_back(r.local, r.global);
      continue;
    }
    CompareRun local = compare_run(o, "local", p, "");
    if (cancelled(local)) return r;
    CompareRun global = compare_run(o, "global", p, "");
    if (cancelled(global)) return r;
    r.patches.emplace_back(std::move(local), std::move(global));
  }
  return r;
}

std::vector<std::string> write_compare_files(const CompareResult& r, const CompareOptions& o) {
  std::string csv =
      "patch,mode,frames,fps,tracker_fps,ms_median,ms_p95,ms_mean,global_activations,"
      "peak_rss_mb\n";
  nlohmann::ordered_json doc;
  doc["input"] = o.input;
  doc["threads"] = o.run.threads;
  doc["preset"] = o.preset;
  doc["patch"] = r.local.patch;
  doc["local"] = run_json(r.local);
  doc["global"] = run_json(r.global);
  doc["speedup_median_ms"] = speedup(r.local, r.global);
  doc["speedup_tracker_fps"] = fps_speedup(r);
  csv += csv_row(r.local) + csv_row(r.global);
  doc["patches"] = nlohmann::ordered_json::array();
  for (const auto& [l, g] : r.patches) {
    doc["patches"].push_back({{"patch", l.patch},
                              {"local", run_json(l)},
                              {"global", run_json(g)},
                              {"speedup_median_ms", speedup(l, g)}});
    csv += csv_row(l) + csv_row(g);
  }
  std::vector<std::string> written;
  const auto path = [&](const char* name) {
    written.push_back((fs::path(o.out_dir) / name).string());
    return written.back();
  };
  write_text_atomically(path("compare.csv"), csv);
  write_text_atomically(path("compare.json"), doc.dump(2) + "\n");
  report::write_plot_svg(path("ms_per_frame.svg"), frames_plot(r, o));
  if (!r.patches.empty()) report::write_plot_svg(path("patches.svg"), patches_plot(r, o));
  return written;
}

std::string compare_table(const CompareResult& r, const CompareOptions& o) {
  std::string text = fmt::format(
      "compare {}: local vs global, patch {}, {} threads, one mode "
      "after the other\n",
      o.input, r.local.patch, o.run.threads);
  text += fmt::format("{:<7} {:>7} {:>8} {:>12} {:>10} {:>8} {:>8} {:>12} {:>9}\n", "mode",
                      "frames", "fps", "tracker fps", "ms median", "ms p95", "ms mean",
                      "global act.", "peak MiB");
  for (const CompareRun* run : {&r.local, &r.global}) {
    const TrackSummary& s = run->summary;
    text +=
        fmt::format("{:<7} {:>7} {:>8.1f} {:>12.1f} {:>10.3f} {:>8.3f} {:>8.3f} {:>12} {:>9.1f}\n",
                    run->mode, s.frames, s.fps, s.tracker_fps, run->ms_median, run->ms_p95,
                    run->ms_mean, s.global_activations, s.peak_rss_mb);
  }
  text += fmt::format(
      "local mode is {:.1f}x faster than global (median ms per frame), {:.1f}x (tracker fps)\n",
      speedup(r.local, r.global), fps_speedup(r));
  if (r.patches.empty()) return text;
  text += fmt::format("{:>6} {:>16} {:>16} {:>9}\n", "patch", "local ms median", "global ms median",
                      "speed-up");
  for (const auto& [l, g] : r.patches) {
    text += fmt::format("{:>6} {:>16.3f} {:>16.3f} {:>8.1f}x\n", l.patch, l.ms_median, g.ms_median,
                        speedup(l, g));
  }
  return text;
}

std::string compare_text(const CompareResult& r, const CompareOptions& options,
                         const std::vector<std::string>& written) {
  return compare_table(r, options) + "  wrote " + joined(written) +
         "\n  per-mode logs and summaries: " +
         (std::filesystem::path(options.out_dir) / "{local,global}.{csv,json}").string() + "\n";
}

Ending compare_ending(const CompareResult& r) {
  if (!r.cancelled) return {};
  const int sig = caught_signal();
  return {128 + sig, std::string("interrupted by ") + (sig == SIGINT ? "SIGINT" : "SIGTERM") +
                         " during the compare runs; no comparison written"};
}

}  // namespace roiflow::pipeline
