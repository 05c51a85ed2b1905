#include "pipeline/frame_graph.hpp"
#include "tracking/motion_split.hpp"

#include <oneapi/tbb/flow_graph.h>
#include <oneapi/tbb/info.h>

#include <chrono>
#include <memory>
#include <mutex>
#include <opencv2/imgproc.hpp>
#include <string>
#include <tuple>
#include <unordered_map>
#include <vector>

#include "core/error.hpp"
#include "pipeline/frame_graph_impl.hpp"
#include "pipeline/tbb_executor.hpp"

namespace roiflow::pipeline {
namespace {

using namespace frame_graph_impl;

namespace tf = oneapi::tbb::flow;
// A frame or pair done with by `votes` consumers; retired when all of them have voted.
struct RetireMsg {
  long long seq = 0;
  int votes = 1;
};

// What every graph shares: options, counters, timing.
class Run {
 public:
  explicit Run(const GraphOptions& options) : options_(options) {}

  void enter(Stage stage, long long seq) const {
    if (options_.on_stage) options_.on_stage(stage, seq);
  }
  void time(const char* stage, Clock::time_point start) const {
    if (options_.stats != nullptr) options_.stats->add(stage, ms_since(start));
  }
  void time(const std::string& stage, Clock::time_point start) const {
    if (options_.stats != nullptr) options_.stats->add(stage, ms_since(start));
  }
  bool cancel_requested() const {
    return options_.cancel != nullptr && options_.cancel->load(std::memory_order_relaxed);
  }

  // A frame passed the limiter.
  void admitted() {
    const long long now = alive_.fetch_add(1) + 1;
    long long seen = max_alive_.load();
    while (now > seen && !max_alive_.compare_exchange_weak(seen, now)) {
    }
  }
  // Called by the (serial) retire node: true when the frame is done and the limiter may let
  // another one in.
  bool vote(const RetireMsg& msg, int needed) {
    int& count = votes_[msg.seq];
    count += msg.votes;
    if (count < needed) return false;
    votes_.erase(msg.seq);
    alive_.fetch_sub(1);
    ++retired_;
    if (options_.stats != nullptr) options_.stats->add_frames(1);
    return true;
  }

  RunReport report(double wall_s, bool cancelled) const {
    RunReport r;
    r.frames = retired_;
    r.max_in_flight = max_alive_.load();
    r.cancelled = cancelled;
    r.wall_s = wall_s;
    return r;
  }

  const GraphOptions& options() const { return options_; }

 private:
  const GraphOptions& options_;
  std::atomic<long long> alive_{0};
  std::atomic<long long> max_alive_{0};
  std::unordered_map<long long, int> votes_;  // touched by the serial retire node only
  long long retired_ = 0;
};

int thread_count(const GraphOptions& options) {
  if (options.threads < 0 || options.threads > kMaxThreads) {
    throw Error("threads must be in 0.." + std::to_string(kMaxThreads) + " (0 = all), got " +
                std::to_string(options.threads));
  }
  return options.threads == 0 ? oneapi::tbb::info::default_concurrency() : options.threads;
}

int in_flight_limit(const GraphOptions& options, int threads) {
  if (options.max_in_flight < 0) {
    throw Error("frames in flight must be >= 1 (0 = automatic), got " +
                std::to_string(options.max_in_flight));
  }
  return options.max_in_flight == 0 ? 2 * threads + 2 : options.max_in_flight;
}

// Pyramids are recycled: a frame's pyramid goes back to the pool when its last user lets go,
// and the next frame is built into its buffers (build_pyramid and pyrDown reuse buffers of the
// right size), unless a level is still shared. The pool never holds more than the pyramids that
// were alive at once, which the limiter bounds; no per-frame allocation means no page faults and a
// flat memory profile. The pool lives as long as any pyramid (the tracker keeps the last one after
// the run).
class PyramidPool : public std::enable_shared_from_this<PyramidPool> {
 public:
  std::shared_ptr<flow::Pyramid> get() {
    std::unique_ptr<flow::Pyramid> p;
    {
      const std::lock_guard<std::mutex> lock(mutex_);
      if (!free_.empty()) {
        p = std::move(free_.back());
        free_.pop_back();
      }
    }
    if (!p) p = std::make_unique<flow::Pyramid>();
    return {p.release(), [self = shared_from_this()](flow::Pyramid* q) { self->put(q); }};
  }

 private:
  void put(flow::Pyramid* p) {
    std::unique_ptr<flow::Pyramid> owned(p);
    // A level whose buffer someone still shares (a cv::Mat copy of it outlived the pyramid)
    // is let go, not overwritten: the next build allocates that one afresh.
    for (cv::Mat& level : owned->levels) {
      if (level.u != nullptr && level.u->refcount > 1) level.release();
    }
    const std::lock_guard<std::mutex> lock(mutex_);
    free_.push_back(std::move(owned));
  }

  std::mutex mutex_;
  std::vector<std::unique_ptr<flow::Pyramid>> free_;
};

// source -> limiter -> level 0 -> level 1 -> ... -> sequencer: the part both modes share.
class FrontEnd {
 public:
  // `wanted` (may be empty: always) says whether the consumer wants whole-frame pyramids now;
  // frames it does not want them for go on without one.
  FrontEnd(tf::graph& g, Run& run, const FrameSource& source, int limit, int levels, double sigma,
           std::function<bool()> wanted = {})
      : run_(run),
        wanted_(std::move(wanted)),
        source_(source),
        input_(g, [this](oneapi::tbb::flow_control& fc) { return next(fc); }),
        limiter_(g, static_cast<std::size_t>(limit)),
        sequencer_(g, [](const FrameMsg& m) { return static_cast<std::size_t>(m.seq); }) {
    level_nodes_.reserve(static_cast<std::size_t>(levels));
    for (int level = 0; level < levels; ++level) {
      level_nodes_.emplace_back(g, tf::unlimited, [this, level, levels, sigma](FrameMsg m) {
        if (level == 0) {
          run_.admitted();
          run_.enter(Stage::Pyramid, m.seq);
          if (wanted_ && !wanted_()) m.pyramid.reset();  // back to the pool
        }
        if (!m.pyramid) return m;
        const auto start = Clock::now();
        flow::Pyramid& pyr = *m.pyramid;
        if (level == 0) {
          flow::build_base_level(m.frame->gray, levels, sigma, pyr);
        } else if (level < pyr.num_levels()) {
          flow::build_level(pyr, level);
        }
        run_.time("pyramid", start);
        return m;
      });
    }
    tf::make_edge(input_, limiter_);
    tf::make_edge(limiter_, level_nodes_.front());
    for (std::size_t i = 1; i < level_nodes_.size(); ++i)
      tf::make_edge(level_nodes_[i - 1], level_nodes_[i]);
    tf::make_edge(level_nodes_.back(), sequencer_);
  }

  tf::sequencer_node<FrameMsg>& output() { return sequencer_; }
  tf::receiver<tf::continue_msg>& retire_port() { return limiter_.decrementer(); }
  void start() { input_.activate(); }
  bool cancelled() const { return cancelled_; }

 private:
  FrameMsg next(oneapi::tbb::flow_control& fc) {
    if (run_.cancel_requested()) {
      cancelled_ = true;
      fc.stop();
      return {};
    }
    run_.enter(Stage::Source, seq_);
    const auto start = Clock::now();
    std::optional<video::Frame> frame = source_();
    if (!frame) {
      fc.stop();
      return {};
    }
    run_.time("decode", start);
    FrameMsg m;
    m.seq = seq_++;
    m.frame = std::make_shared<const video::Frame>(std::move(*frame));
    m.pyramid = pool_->get();
    return m;
  }

  Run& run_;
  std::function<bool()> wanted_;
  const FrameSource& source_;
  long long seq_ = 0;  // the input node's body runs serially
  bool cancelled_ = false;
  std::shared_ptr<PyramidPool> pool_ = std::make_shared<PyramidPool>();
  tf::input_node<FrameMsg> input_;
  tf::limiter_node<FrameMsg> limiter_;
  std::vector<tf::function_node<FrameMsg, FrameMsg>> level_nodes_;
  tf::sequencer_node<FrameMsg> sequencer_;
};

using RetireNode = tf::multifunction_node<RetireMsg, std::tuple<tf::continue_msg>>;

RetireNode make_retire_node(tf::graph& g, Run& run, int votes_needed) {
  return RetireNode(g, tf::serial, [&run, votes_needed](const RetireMsg& m, auto& ports) {
    if (run.vote(m, votes_needed)) std::get<0>(ports).try_put(tf::continue_msg());
  });
}

// One serial node per sink, so that each sees the messages in order while different sinks
// work on different ones at once; each votes for frame seq + `retire_offset`. With no sink, a
// pass-through retires the frames.
template <class Msg, class Sink>
std::vector<tf::function_node<Msg, RetireMsg>> make_sink_nodes(tf::graph& g, Run& run,
                                                               const std::vector<Sink>& sinks,
                                                               long long retire_offset) {
  std::vector<tf::function_node<Msg, RetireMsg>> nodes;
  nodes.reserve(std::max<std::size_t>(1, sinks.size()));
  for (const Sink& sink : sinks) {
    nodes.emplace_back(g, tf::serial, [&run, &sink, retire_offset](const Msg& m) {
      run.enter(Stage::Sink, m.seq);
      const auto t0 = Clock::now();
      sink.consume(m);
      run.time(sink.name, t0);
      return RetireMsg{m.seq + retire_offset, 1};
    });
  }
  if (sinks.empty()) {
    nodes.emplace_back(g, tf::serial, [retire_offset](const Msg& m) {
      return RetireMsg{m.seq + retire_offset, 1};
    });
  }
  return nodes;
}

// Starts the source, waits for the graph (rethrowing what a node threw) and reports.
RunReport finish(tf::graph& g, Run& run, FrontEnd& front, Clock::time_point start) {
  front.start();
  g.wait_for_all();
  return run.report(std::chrono::duration<double>(Clock::now() - start).count(), front.cancelled());
}

// Runs `body` (which builds the graph, starts it and waits) in an arena of the options'
// thread count, and times it.
template <class Body>
RunReport run_in_arena(const GraphOptions& options, Body&& body) {
  const int threads = thread_count(options);
  const int limit = in_flight_limit(options, threads);
  ThreadScope scope(threads);
  const auto start = Clock::now();
  return scope.run([&] { return body(limit, start); });
}

}  // namespace

const char* to_string(Stage stage) {
  switch (stage) {
    case Stage::Source:
      return "source";
    case Stage::Pyramid:
      return "pyramid";
    case Stage::Track:
      return "track";
    case Stage::Flow:
      return "flow";
    case Stage::Sink:
      return "sink";
  }
  return "?";
}

RunReport run_tracking(const FrameSource& source, tracking::Tracker& tracker,
                       const std::vector<TrackSink>& sinks, const GraphOptions& options) {
  TrackStep step;
  step.levels = tracker.pyramid_levels();
  step.sigma = tracker.pyramid_sigma();
  step.process = [&tracker](const tracking::TrackerInput& in) { return tracker.process(in); };
  step.wants_pyramid = [&tracker] { return tracker.wants_pyramid(); };
  step.drain = [&tracker] { tracker.finish_background_work(); };
  return run_tracking(source, step, sinks, options);
}

RunReport run_tracking(const FrameSource& source, const TrackStep& step,
                       const std::vector<TrackSink>& sinks, const GraphOptions& options) {
  if (!step.process) throw Error("tracking step without a process function");
  return run_in_arena(options, [&](int limit, Clock::time_point start) {
    Run run(options);
    tf::graph g;
    FrontEnd front(g, run, source, limit, step.levels, step.sigma, step.wants_pyramid);

    tf::function_node<FrameMsg, TrackedFrame> track(g, tf::serial, [&](const FrameMsg& m) {
      run.enter(Stage::Track, m.seq);
      const auto t0 = Clock::now();
      TrackedFrame out;
      out.seq = m.seq;
      out.frame = m.frame;
      out.output = std::make_shared<const tracking::TrackerOutput>(step.process(
          {m.frame->index, m.frame->image, m.frame->gray,
           std::const_pointer_cast<const flow::Pyramid>(m.pyramid), m.frame->deferred_image}));
      run.time("track", t0);
      return out;
    });

    // The tracker is serial, but oneTBB does not keep the order of what one serial node puts
    // to the next when consecutive messages leave from different threads (about one in ten
    // thousand; oneTBB issue 289): a sequencer restores it before the sinks.
    tf::sequencer_node<TrackedFrame> track_order(
        g, [](const TrackedFrame& f) { return static_cast<std::size_t>(f.seq); });
    tf::broadcast_node<TrackedFrame> to_sinks(g);  // a sequencer feeds one successor only
    auto sink_nodes = make_sink_nodes<TrackedFrame>(g, run, sinks, 0);
    RetireNode retire = make_retire_node(g, run, static_cast<int>(sink_nodes.size()));

    tf::make_edge(front.output(), track);
    tf::make_edge(track, track_order);
    tf::make_edge(track_order, to_sinks);
    for (auto& node : sink_nodes) {
      tf::make_edge(to_sinks, node);
      tf::make_edge(node, retire);
    }
    tf::make_edge(tf::output_port<0>(retire), front.retire_port());

    if (!step.drain) return finish(g, run, front, start);
    RunReport report;
    try {
      report = finish(g, run, front, start);
    } catch (...) {
      try {
        step.drain();
      } catch (...) {  // NOLINT(bugprone-empty-catch): the first error is the one reported
      }
      throw;
    }
    step.drain();
    return report;
  });
}

RunReport run_dense(const FrameSource& source, const flow::LkParams& params,
                    const std::vector<FlowSink>& sinks, const GraphOptions& options) {
  params.validate();
  return run_in_arena(options, [&](int limit, Clock::time_point start) {
    Run run(options);
    tf::graph g;
    // The frame size comes with the first frame: build the levels the largest frame would need
    // (a pyramid stops where its frame is too small, and dense_flow uses what it asks for).
    const int pyramid_levels = flow::flow_pyramid_levels({1 << 16, 1 << 16}, params, {});
    FrontEnd front(g, run, source, limit, pyramid_levels, params.sigma);

    struct PairJob {
      long long seq = 0;
      FrameMsg t, t1;
    };
    // Pairs each frame with the previous one. Frame 0 is retired at once (this node keeps it
    // as `previous`); frame t+1 is retired when the sinks are done with pair (t, t+1).
    using PairNode = tf::multifunction_node<FrameMsg, std::tuple<PairJob, RetireMsg>>;
    std::optional<FrameMsg> previous;
    PairNode pair(g, tf::serial, [&](const FrameMsg& m, PairNode::output_ports_type& ports) {
      if (previous) {
        std::get<0>(ports).try_put(PairJob{previous->seq, *previous, m});
      } else {
        std::get<1>(ports).try_put(
            RetireMsg{m.seq, static_cast<int>(std::max<std::size_t>(1, sinks.size()))});
      }
      previous = m;
    });

    LkPool lk_pool(params);
    tf::function_node<PairJob, FlowPair> flow_node(g, tf::unlimited, [&](const PairJob& job) {
      run.enter(Stage::Flow, job.seq);
      const auto t0 = Clock::now();
      auto result = std::make_shared<flow::FlowResult>();
      // One thread per pair: the limiter keeps more pairs in flight than there are threads,
      // and splitting each pair in row tiles as well cost ~15 % of the throughput (measured
      // with pipeline_bench BM_Dense at 2 threads: 171 -> 200 pairs/s without tiles).
      std::unique_ptr<flow::DenseLK> lk = lk_pool.take();
      lk->calc(*job.t.pyramid, *job.t1.pyramid, *result);
      lk_pool.give_back(std::move(lk));
      run.time("flow", t0);
      return FlowPair{job.seq, job.t.frame, job.t1.frame, std::move(result)};
    });
    // The sinks' parallel parts, one vector entry per sink (empty for a sink without one).
    struct PreparedPair {
      FlowPair pair;
      std::vector<cv::Mat> prepared;
    };
    std::vector<std::string> prepare_stage(sinks.size());
    for (std::size_t i = 0; i < sinks.size(); ++i)
      prepare_stage[i] = sinks[i].name + ".prepare";
    tf::function_node<FlowPair, PreparedPair> prepare_node(
        g, tf::unlimited, [&](const FlowPair& p) {
          PreparedPair out{p, std::vector<cv::Mat>(sinks.size())};
          for (std::size_t i = 0; i < sinks.size(); ++i) {
            if (!sinks[i].prepare) continue;
            run.enter(Stage::Sink, p.seq);
            const auto t0 = Clock::now();
            out.prepared[i] = sinks[i].prepare(p);
            run.time(prepare_stage[i], t0);
          }
          return out;
        });
    tf::sequencer_node<PreparedPair> pair_order(
        g, [](const PreparedPair& p) { return static_cast<std::size_t>(p.pair.seq); });
    tf::broadcast_node<PreparedPair> to_sinks(g);  // a sequencer feeds one successor only

    // Each sink gets the pair with its own prepared part; sinks vote for frame t+1, the newer
    // frame of their pair.
    std::vector<tf::function_node<PreparedPair, RetireMsg>> sink_nodes;
    sink_nodes.reserve(std::max<std::size_t>(1, sinks.size()));
    for (std::size_t i = 0; i < sinks.size(); ++i) {
      sink_nodes.emplace_back(g, tf::serial, [&run, &sinks, i](const PreparedPair& m) {
        run.enter(Stage::Sink, m.pair.seq);
        const auto t0 = Clock::now();
        FlowPair p = m.pair;
        p.prepared = m.prepared[i];
        sinks[i].consume(p);
        run.time(sinks[i].name, t0);
        return RetireMsg{m.pair.seq + 1, 1};
      });
    }
    if (sinks.empty()) {
      sink_nodes.emplace_back(g, tf::serial, [](const PreparedPair& m) {
        return RetireMsg{m.pair.seq + 1, 1};
      });
    }
    RetireNode retire = make_retire_node(g, run, static_cast<int>(sink_nodes.size()));

    tf::make_edge(front.output(), pair);
    tf::make_edge(tf::output_port<0>(pair), flow_node);
    tf::make_edge(tf::output_port<1>(pair), retire);
    tf::make_edge(flow_node, prepare_node);
    tf::make_edge(prepare_node, pair_order);
    tf::make_edge(pair_order, to_sinks);
    for (auto& node : sink_nodes) {
      tf::make_edge(to_sinks, node);
      tf::make_edge(node, retire);
    }
    tf::make_edge(tf::output_port<0>(retire), front.retire_port());

    return finish(g, run, front, start);
  });
}

namespace {

// The scene start's flow: dense LK from each frame back to the previous one while the detector
// wants the frames' motion (tracking::wants_flow: its first frames), serial and in frame order,
// ahead of the background refresh. It holds the previous frame's pyramid only while the next
// frame wants it.
class StartFlowNode {
 public:
  StartFlowNode(tf::graph& g, Run& run, const tracking::MultiTrackerParams& params)
      : params_(params),
        lk_(params.lk, &stripes_),
        node_(g, tf::serial, [this, &run](const FrameMsg& m) { return step(run, m); }) {}
  tf::function_node<FrameMsg, StartMsg>& node() { return node_; }

 private:
  StartMsg step(Run& run, const FrameMsg& m) {
    StartMsg out{m.seq, m, nullptr};
    if (tracking::wants_flow(params_.detector, m.seq) && previous_ && m.pyramid) {
      run.enter(Stage::Flow, m.seq);
      const auto t0 = Clock::now();
      auto back = std::make_shared<flow::FlowResult>();
      lk_.calc(*m.pyramid, *previous_, *back);
      out.back = std::move(back);
      run.time("start_flow", t0);
    }
    const bool more = tracking::wants_flow(params_.detector, m.seq + 1);
    if (!more && previous_) lk_.collectGarbage();  // the scene start is over
    previous_ = more ? m.pyramid : nullptr;
    return out;
  }

  const tracking::MultiTrackerParams& params_;
  const TbbExecutor stripes_;  // the LK's row stripes on the arena's threads (same result)
  flow::DenseLK lk_;
  std::shared_ptr<flow::Pyramid> previous_;
  tf::function_node<FrameMsg, StartMsg> node_;
};

// The background refresh: the motion detector's model learns each frame, serial and in frame
// order (the model learns the frames in order); its bands of rows run at once on the arena's
// threads (the same masks).
class BackgroundNode {
 public:
  BackgroundNode(tf::graph& g, Run& run, const tracking::MultiTrackerParams& params)
      : detector_(params.detector),
        node_(g, tf::serial, [this, &run](const StartMsg& m) { return step(run, m); }) {}
  tf::function_node<StartMsg, SeenMsg>& node() { return node_; }

 private:
  SeenMsg step(Run& run, const StartMsg& m) {
    run.enter(Stage::Track, m.seq);
    const auto t0 = Clock::now();
    SeenMsg out{m.seq, m.frame, nullptr, nullptr};
    out.fg = std::make_shared<const tracking::Foreground>(
        detector_.observe(m.frame.frame->picture(), m.back.get(), &bands_));
    run.time("background", t0);
    return out;
  }

  tracking::MotionDetector detector_;
  const TbbExecutor bands_;
  tf::function_node<StartMsg, SeenMsg> node_;
};

// The motion split (after the scene start) of the detections the objects at t say are wrong
// (tracking::split_candidates): dense LK over each one's box, serial (frames meet their
// decisions one at a time), between the meeting of frame t+1 with the decisions at t and the plan.
class SplitNode {
 public:
  using Met = std::tuple<SeenMsg, DecidedMsg>;
  SplitNode(tf::graph& g, Run& run, const tracking::MultiTrackerParams& params)
      : params_(params),
        lk_(params.lk, &stripes_),
        node_(g, tf::serial, [this, &run](Met in) { return step(run, std::move(in)); }) {}
  tf::function_node<Met, Met>& node() { return node_; }

 private:
  Met step(Run& run, Met in) {
    SeenMsg& now = std::get<0>(in);
    const DecidedMsg& before = std::get<1>(in);
    if (!before.pyramid || !before.state || !now.detections || !now.fg) return in;
    const std::vector<std::size_t> which =
        tracking::split_candidates(*before.state, *now.detections, *now.fg, params_);
    if (which.empty()) return in;
    run.enter(Stage::Flow, now.seq);
    const auto t0 = Clock::now();
    std::vector<std::vector<cv::Rect2f>> parts;
    for (std::size_t j : which)
      parts.push_back(tracking::split_by_flow((*now.detections)[j].box, *before.pyramid,
                                              *now.frame.pyramid, *now.fg, lk_, params_));
    now.detections = std::make_shared<const std::vector<tracking::Detection>>(
        tracking::apply_splits(*now.detections, which, parts));
    run.time("split", t0);
    return in;
  }

  const tracking::MultiTrackerParams& params_;
  const TbbExecutor stripes_;  // the LK's row stripes on the arena's threads (same result)
  flow::DenseLK lk_;
  tf::function_node<Met, Met> node_;
};

}  // namespace

RunReport run_mot(const FrameSource& source, const tracking::MultiTrackerParams& params,
                  const std::vector<MotSink>& sinks, const GraphOptions& options) {
  params.validate();
  return run_in_arena(options, [&](int limit, Clock::time_point start) {
    Run run(options);
    tf::graph g;
    FrontEnd front(g, run, source, limit, params.lk.levels, params.lk.sigma);

    StartFlowNode start_flow(g, run, params);   // the scene start's flow, then
    BackgroundNode background(g, run, params);  // the background refresh
    // Global treatment: the moving objects of each frame, several frames at once.
    tf::function_node<SeenMsg, SeenMsg> global(g, tf::unlimited, [&](SeenMsg m) {
      const auto t0 = Clock::now();
      m.detections = std::make_shared<const std::vector<tracking::Detection>>(
          tracking::detect_objects(*m.fg, params.detector));
      run.time("global", t0);
      return m;
    });
    tf::sequencer_node<SeenMsg> seen_order(
        g, [](const SeenMsg& m) { return static_cast<std::size_t>(m.seq); });
    // Frame t+1 meets the decisions at t (the feedback edge), then the motion split.
    tf::join_node<std::tuple<SeenMsg, DecidedMsg>, tf::queueing> meet(g);
    SplitNode split(g, run, params);
    using PlanNode =
        tf::multifunction_node<std::tuple<SeenMsg, DecidedMsg>, std::tuple<TileMsg, CollectMsg>>;
    PlanNode plan(g, tf::serial, [&](const std::tuple<SeenMsg, DecidedMsg>& in, auto& ports) {
      const SeenMsg& now = std::get<0>(in);
      run.enter(Stage::Track, now.seq);
      const auto t0 = Clock::now();
      auto work = std::make_shared<FrameWork>();
      work->now = now;
      work->before = std::get<1>(in);
      work->planned = t0;
      if (work->before.pyramid) {
        work->tiles = tracking::plan_tiles(*work->before.state, *work->before.fg, params);
      }
      std::shared_ptr<const FrameWork> shared = work;
      run.time("plan", t0);
      // A frame without tiles goes to the collector as a header (it completes at once).
      if (shared->tiles.empty()) std::get<1>(ports).try_put(CollectMsg{shared, -1, {}});
      for (std::size_t i = 0; i < shared->tiles.size(); ++i)
        std::get<0>(ports).try_put(TileMsg{shared, i});
    });

    // LK refinement over ROI tiles: one task per tile, a frame's tiles at once.
    LkPool lk_pool(params.lk);
    tf::function_node<TileMsg, CollectMsg> lk_tiles(g, tf::unlimited, [&](const TileMsg& m) {
      run.enter(Stage::Flow, m.work->now.seq);
      const auto t0 = Clock::now();
      std::unique_ptr<flow::DenseLK> lk = lk_pool.take();
      CollectMsg out{m.work, static_cast<long long>(m.tile), {}};
      out.motion =
          tracking::measure_tile(m.work->tiles[m.tile], *m.work->before.pyramid,
                                 *m.work->now.frame.pyramid, *m.work->before.fg, *lk, params);
      lk_pool.give_back(std::move(lk));
      run.time("lk", t0);
      return out;
    });

    TileCollector collector;  // joins a frame's tiles (they finish in any order)
    using CollectNode = tf::multifunction_node<CollectMsg, std::tuple<CollectedMsg>>;
    CollectNode collect(g, tf::serial, [&](const CollectMsg& m, auto& ports) {
      if (std::optional<CollectedMsg> done = collector.add(m)) std::get<0>(ports).try_put(*done);
    });

    using DecideNode =
        tf::multifunction_node<CollectedMsg, std::tuple<DecidedMsg, MotTrackedFrame>>;
    DecideNode decision(g, tf::serial, [&](const CollectedMsg& m, auto& ports) {
      const SeenMsg& now = m.work->now;
      run.enter(Stage::Track, now.seq);
      const auto t0 = Clock::now();
      auto [state, out] = decide_frame(m, params);
      run.time("decide", t0);
      out->ms = ms_since(m.work->planned);
      std::get<0>(ports).try_put(DecidedMsg{now.seq, state, now.frame.pyramid, now.fg});
      std::get<1>(ports).try_put(MotTrackedFrame{now.seq, now.frame.frame, std::move(out)});
    });

    tf::sequencer_node<MotTrackedFrame> out_order(
        g, [](const MotTrackedFrame& f) { return static_cast<std::size_t>(f.seq); });
    tf::broadcast_node<MotTrackedFrame> to_sinks(g);
    auto sink_nodes = make_sink_nodes<MotTrackedFrame>(g, run, sinks, 0);
    RetireNode retire = make_retire_node(g, run, static_cast<int>(sink_nodes.size()));

    tf::make_edge(front.output(), start_flow.node());
    tf::make_edge(start_flow.node(), background.node());
    tf::make_edge(background.node(), global);
    tf::make_edge(global, seen_order);
    tf::make_edge(seen_order, tf::input_port<0>(meet));
    tf::make_edge(meet, split.node());
    tf::make_edge(split.node(), plan);
    tf::make_edge(tf::output_port<0>(plan), lk_tiles);
    tf::make_edge(tf::output_port<1>(plan), collect);
    tf::make_edge(lk_tiles, collect);
    tf::make_edge(tf::output_port<0>(collect), decision);
    tf::make_edge(tf::output_port<0>(decision), tf::input_port<1>(meet));
    tf::make_edge(tf::output_port<1>(decision), out_order);
    tf::make_edge(out_order, to_sinks);
    for (auto& node : sink_nodes) {
      tf::make_edge(to_sinks, node);
      tf::make_edge(node, retire);
    }
    tf::make_edge(tf::output_port<0>(retire), front.retire_port());

    DecidedMsg seed;
    seed.state = std::make_shared<const tracking::TrackSet>(tracking::initial_tracks(params));
    tf::input_port<1>(meet).try_put(seed);
    return finish(g, run, front, start);
  });
}

}  // namespace roiflow::pipeline
