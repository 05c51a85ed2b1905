#include "flow/dense_lk.hpp"

#include <algorithm>
#include <memory>
#include <opencv2/imgproc.hpp>
#include <string>
#include <vector>

#include "core/error.hpp"
#include "flow/large_motion.hpp"
#include "flow/lk_level.hpp"

namespace roiflow::flow {

using detail::iterate_level;
using detail::LevelInput;
using detail::LevelProblem;
using detail::make_window;
using detail::upsample_flow;

// Everything a DenseLK keeps between calls.
struct DenseLK::Workspace {
  Pyramid pyr_t, pyr_t1;
  std::vector<cv::Mat> u, v;  // per level
  cv::Mat init_u, init_v;     // options.initial_flow, split
  cv::Mat seed_u, seed_v;     // a level's starting flow, when large_motion.hpp seeds it
  cv::Mat confidence;         // the finest level's
  detail::LevelScratch scratch;
  std::vector<float> fusion;  // the candidate fusion's costs, with threads

  std::size_t bytes() const {
    std::size_t n = scratch.bytes() + fusion.capacity() * sizeof(float);
    for (const cv::Mat* m : {&init_u, &init_v, &seed_u, &seed_v, &confidence})
      n += m->total() * m->elemSize();
    for (const std::vector<cv::Mat>* mats : {&pyr_t.levels, &pyr_t1.levels, &u, &v}) {
      for (const cv::Mat& m : *mats)
        n += m.total() * m.elemSize();
    }
    return n;
  }
};

namespace {

cv::Rect expand(const cv::Rect& r, int by) {
  return {r.x - by, r.y - by, r.width + 2 * by, r.height + 2 * by};
}

void median_filter(cv::Mat& u, cv::Mat& v, int ksize, const Executor& exec) {
  if (ksize <= 1) return;
  // The two components side by side.
  exec.for_range(0, 2, 1, [&](int b0, int b1) {
    for (int b = b0; b < b1; ++b) {
      cv::Mat& m = b == 0 ? u : v;
      cv::medianBlur(m, m, ksize);
    }
  });
}

// Which levels LK runs on and the rectangle each level computes (coarsest last).
struct LevelPlan {
  int finest = 0;  // LK runs on levels finest .. top - 1
  int top = 1;
  // Levels >= finest: the finer level's rectangle halved (the region itself at the finest
  // level, in its pixels), plus the margin the iterations read, clipped to the level. Levels
  // below finest: where the finest level's flow is upsampled to, down to the region at level 0.
  std::vector<cv::Rect> comp;
};

LevelPlan plan_levels(cv::Size size, const LkParams& params, const FlowOptions& options,
                      const cv::Rect& region) {
  if (options.context < -1 || options.context > 1000) {
    throw Error("flow context must be in -1..1000 pixels, got " + std::to_string(options.context));
  }
  if (options.finest_level < 0 || options.finest_level >= kMaxLevels) {
    throw Error("flow finest level must be in 0.." + std::to_string(kMaxLevels - 1) + ", got " +
                std::to_string(options.finest_level));
  }
  LevelPlan plan;
  plan.top = flow_pyramid_levels(size, params, options);
  plan.finest = std::min(std::max(options.finest_level, params.finest_level), plan.top - 1);
  const detail::Window win =
      make_window(params.patch, params.derivative == Derivative::HornSchunck);
  // Flow at a pixel after one iteration depends on the previous flow within the window plus
  // the derivative stencil: computing on a margin of this many pixels per iteration makes a
  // region's flow equal the whole frame's flow inside the region (up to rounding).
  const int reach = win.reach() + 2;
  const int margin = options.context >= 0
                         ? options.context
                         : std::max(params.iterations, params.finest_iterations) * reach +
                               std::max(params.level_median, params.final_median) / 2;
  plan.comp.resize(plan.top);
  cv::Rect need = region;
  for (int l = 0; l < plan.top; ++l) {
    const cv::Rect level(cv::Point(), level_size(size, l));
    plan.comp[l] = (l < plan.finest ? need : expand(need, margin)) & level;
    const cv::Rect& c = plan.comp[l];
    need = cv::Rect(cv::Point(c.x / 2, c.y / 2),
                    cv::Point((c.x + c.width - 1) / 2 + 2, (c.y + c.height - 1) / 2 + 2));
  }
  return plan;
}

// `src` (the finest level's confidence over rectangle `from` of level `level`) sampled at the
// nearest level pixel for the level-0 pixels of `region` in rows [y0, y1) of `out` (region-sized,
// made by the caller).
void confidence_to_level0(const cv::Mat& src, const cv::Rect& from, int level,
                          const cv::Rect& region, cv::Mat& out, int y0, int y1) {
  const int half = level > 0 ? 1 << (level - 1) : 0;
  std::vector<int> column(region.width);
  for (int x = 0; x < region.width; ++x)
    column[x] = std::clamp(((region.x + x + half) >> level) - from.x, 0, src.cols - 1);
  int last = -1;  // the level row that row y - 1 was sampled from
  for (int y = y0; y < y1; ++y) {
    const int sy = std::clamp(((region.y + y + half) >> level) - from.y, 0, src.rows - 1);
    float* o = out.ptr<float>(y);
    if (sy == last) {  // 2^level rows in a row read the same level row
      std::copy_n(out.ptr<float>(y - 1), region.width, o);
      continue;
    }
    last = sy;
    const float* in = src.ptr<float>(sy);
    for (int x = 0; x < region.width; ++x)
      o[x] = in[column[x]];
  }
}

// The flow the coarsest level `level` (of size `level_size`) starts from over its computed
// rectangle `c`: options.initial_flow there (split into u, v), or options.initial_motion in that
// level's pixels.
LevelInput coarsest_input(const FlowOptions& options, int level, cv::Size level_size,
                          const cv::Rect& c, cv::Mat& u, cv::Mat& v) {
  if (options.initial_flow.empty()) {
    const float scale = 1.f / static_cast<float>(1 << level);
    return LevelInput::constant(options.initial_motion.x * scale, options.initial_motion.y * scale);
  }
  const cv::Mat& init = options.initial_flow;
  if (init.type() != CV_32FC2 || init.size() != level_size) {
    throw Error("initial flow must be CV_32FC2 of the coarsest level's size " +
                std::to_string(level_size.width) + "x" + std::to_string(level_size.height) +
                " (level " + std::to_string(level) + "), got " + cv::typeToString(init.type()) +
                " " + std::to_string(init.cols) + "x" + std::to_string(init.rows));
  }
  u.create(c.size(), CV_32F);
  v.create(c.size(), CV_32F);
  cv::Mat planes[] = {u, v};
  cv::split(init(c), planes);
  return LevelInput::planes(u, v);
}

// `input` (over the computed rectangle `c`) as planes u, v of c's size.
void starting_planes(const LevelInput& input, const cv::Rect& c, cv::Mat& u, cv::Mat& v) {
  switch (input.kind) {
    case LevelInput::Kind::Constant:
      u.create(c.size(), CV_32F);
      v.create(c.size(), CV_32F);
      u.setTo(input.u);
      v.setTo(input.v);
      return;
    case LevelInput::Kind::Planes:
      input.pu->copyTo(u);
      input.pv->copyTo(v);
      return;
    case LevelInput::Kind::Coarser:
      upsample_flow(*input.pu, input.coarse_origin, c, u);
      upsample_flow(*input.pv, input.coarse_origin, c, v);
      return;
  }
}

// The problem of one level: its images, the computed rectangle `c` and the window.
LevelProblem level_problem(const cv::Mat& i0, const cv::Mat& i1, const cv::Rect& c,
                           const LkParams& params) {
  LevelProblem p;
  p.i0 = &i0;
  p.i1 = &i1;
  p.comp = c;
  p.derivative = params.derivative;
  p.win = make_window(params.patch, params.derivative == Derivative::HornSchunck);
  p.lambda = static_cast<float>(params.lambda);
  p.robust_inv_scale2 = params.robust_scale > 0
                            ? static_cast<float>(1.0 / (params.robust_scale * params.robust_scale))
                            : 0.f;
  p.mask_outside = params.mask_outside;
  return p;
}

// The first `size` pixels of a level plane (LK planes are padded, see iterate_level).
cv::Mat view(const cv::Mat& plane, cv::Size size) {
  return plane(cv::Rect(cv::Point(), size));
}

// The LK levels as two chains of row bands (detail::iterate_levels_chained) when `exec` has
// exactly two threads, LK ends at level 0 and every level only iterates (no coarse search, no
// fusion, no median between levels); false, computing nothing, otherwise.
bool chain_levels(const Pyramid& pyr_t, const Pyramid& pyr_t1, const LkParams& params,
                  const FlowOptions& options, const LevelPlan& plan, cv::Size size, bool direct,
                  FlowResult& result, const Executor& exec, DenseLK::Workspace& ws) {
  const int levels = plan.top;
  const std::vector<cv::Rect>& comp = plan.comp;
  bool chained = exec.concurrency() == 2 && plan.finest == 0 && levels >= 2;
  for (int l = 0; l < levels && chained; ++l) {
    chained = !detail::seeds_level(params, l, levels, options) &&
              (l == plan.finest || params.level_median <= 1);
  }
  if (!chained) return false;
  std::vector<detail::ChainLevel> chain(levels);
  for (int l = levels - 1; l >= 0; --l) {
    detail::ChainLevel& cl = chain[levels - 1 - l];
    cl.p = level_problem(pyr_t.levels[l], pyr_t1.levels[l], comp[l], params);
    cl.iterations = params.iterations_at(l, plan.finest);
    cl.u = &ws.u[l];
    cl.v = &ws.v[l];
    if (l == 0) {
      if (options.confidence) cl.confidence = direct ? &result.confidence : &ws.confidence;
      cl.flow = direct ? &result.flow : nullptr;
    }
  }
  const LevelInput input = coarsest_input(options, levels - 1, level_size(size, levels - 1),
                                          comp[levels - 1], ws.init_u, ws.init_v);
  return detail::iterate_levels_chained(chain, input, exec, ws.scratch);
}

// Dense flow from pyramids with `ws`'s buffers (params already validated).
void flow_from_pyramids(const Pyramid& pyr_t, const Pyramid& pyr_t1, const LkParams& params,
                        FlowResult& result, const FlowOptions& options, const Executor* executor,
                        DenseLK::Workspace& ws) {
  const cv::Size size = pyr_t.size();
  if (size.empty() || pyr_t1.size() != size) throw Error("pyramids are empty or differ in size");
  const cv::Rect full(cv::Point(), size);
  const cv::Rect region = options.region.empty() ? full : (options.region & full);
  if (region.empty()) throw Error("flow region lies outside the frame");
  const LevelPlan plan = plan_levels(size, params, options, region);
  const int levels = plan.top;
  if (pyr_t.num_levels() < levels || pyr_t1.num_levels() < levels) {
    throw Error("pyramid has " + std::to_string(std::min(pyr_t.num_levels(), pyr_t1.num_levels())) +
                " levels, " + std::to_string(levels) + " needed");
  }
  const std::vector<cv::Rect>& comp = plan.comp;
  if (!options.confidence) result.confidence.release();
  const SerialExecutor serial;
  const Executor& exec = executor ? *executor : serial;

  ws.u.resize(levels);
  ws.v.resize(levels);
  // The last iteration writes the result itself when it is level 0's whole computed rectangle
  // and no median follows.
  const bool direct =
      plan.finest == 0 && params.final_median == 0 && region.size() == comp[0].size();
  // With two threads, levels that only iterate run as two chains of bands (no barrier between
  // levels); the flow is the same.
  const bool chained =
      chain_levels(pyr_t, pyr_t1, params, options, plan, size, direct, result, exec, ws);
  if (chained && direct) {
    result.region = region;
    return;
  }
  if (chained) {
    cv::Mat u = view(ws.u[0], comp[0].size()), v = view(ws.v[0], comp[0].size());
    median_filter(u, v, params.final_median, exec);
  }
  for (int l = levels - 1; l >= 0 && !chained; --l) {
    const cv::Rect& c = comp[l];
    if (l == 0 && plan.finest > 0) break;  // level 0 is upsampled into the result below
    if (l < plan.finest) {                 // below the finest level the flow is only upsampled
      upsample_flow(view(ws.u[l + 1], comp[l + 1].size()), comp[l + 1].tl(), c, ws.u[l], &exec);
      upsample_flow(view(ws.v[l + 1], comp[l + 1].size()), comp[l + 1].tl(), c, ws.v[l], &exec);
      continue;
    }
    cv::Mat coarse_u, coarse_v;  // LevelInput points at these
    if (l < levels - 1) {
      coarse_u = view(ws.u[l + 1], comp[l + 1].size());
      coarse_v = view(ws.v[l + 1], comp[l + 1].size());
    }
    LevelInput input =
        l == levels - 1 ? coarsest_input(options, l, level_size(size, l), c, ws.init_u, ws.init_v)
                        : LevelInput::coarser(coarse_u, coarse_v, comp[l + 1].tl());
    if (detail::seeds_level(params, l, levels, options)) {
      // The coarse search and the candidate fusion work on the level's starting flow as planes.
      starting_planes(input, c, ws.seed_u, ws.seed_v);
      detail::seed_level(params, pyr_t.levels[l], pyr_t1.levels[l], c, l, levels, options,
                         ws.seed_u, ws.seed_v, &exec, &ws.fusion);
      input = LevelInput::planes(ws.seed_u, ws.seed_v);
    }
    const LevelProblem p = level_problem(pyr_t.levels[l], pyr_t1.levels[l], c, params);
    const bool finest = l == plan.finest;
    const int iterations = params.iterations_at(l, plan.finest);
    if (finest && direct) {
      iterate_level(p, input, ws.u[l], ws.v[l], options.confidence ? &result.confidence : nullptr,
                    iterations, exec, ws.scratch, &result.flow);
      result.region = region;
      return;
    }
    iterate_level(p, input, ws.u[l], ws.v[l],
                  finest && options.confidence ? &ws.confidence : nullptr, iterations, exec,
                  ws.scratch);
    cv::Mat u = view(ws.u[l], c.size()), v = view(ws.v[l], c.size());
    median_filter(u, v, finest ? params.final_median : params.level_median, exec);
  }

  const cv::Rect crop(region.tl() - comp[0].tl(), region.size());
  const bool conf = options.confidence;
  const cv::Mat confidence = conf ? view(ws.confidence, comp[plan.finest].size()) : cv::Mat();
  if (conf) result.confidence.create(crop.size(), CV_32F);
  if (plan.finest > 0) {
    // Level 1's flow upsampled straight onto the region, interleaved (each pixel's value depends
    // only on where it lies, so the region gives level 0's computed rectangle's values there).
    detail::upsample_flow_pair(view(ws.u[1], comp[1].size()), view(ws.v[1], comp[1].size()),
                               comp[1].tl(), region, result.flow, &exec);
    if (conf) {
      exec.for_range(0, crop.height, 64, [&](int y0, int y1) {
        confidence_to_level0(confidence, comp[plan.finest], plan.finest, region, result.confidence,
                             y0, y1);
      });
    }
    result.region = region;
    return;
  }
  const cv::Mat u = view(ws.u[0], comp[0].size())(crop), v = view(ws.v[0], comp[0].size())(crop);
  result.flow.create(crop.size(), CV_32FC2);
  // Row blocks on the executor: at VGA these copies are a few per cent of a pair.
  exec.for_range(0, crop.height, 64, [&](int y0, int y1) {
    const cv::Rect rows(0, y0, crop.width, y1 - y0);
    const cv::Mat planes[] = {u(rows), v(rows)};
    cv::Mat out = result.flow(rows);
    cv::merge(planes, 2, out);
    if (conf) confidence(crop)(rows).copyTo(result.confidence(rows));
  });
  result.region = region;
}

}  // namespace

cv::Rect flow_footprint(cv::Size size, const LkParams& params, const FlowOptions& options) {
  params.validate();
  const cv::Rect full(cv::Point(), size);
  const cv::Rect region = options.region.empty() ? full : (options.region & full);
  if (region.empty()) throw Error("flow region lies outside the frame");
  cv::Rect out = region;
  const LevelPlan plan = plan_levels(size, params, options, region);
  for (int l = plan.finest; l < plan.top; ++l) {
    const int f = 1 << l;
    const cv::Rect& c = plan.comp[l];
    out |= cv::Rect(c.x * f, c.y * f, c.width * f, c.height * f);
  }
  return out & full;
}

int flow_pyramid_levels(cv::Size size, const LkParams& params, const FlowOptions& options) {
  const int finest =
      std::clamp(std::max(options.finest_level, params.finest_level), 0, kMaxLevels - 1);
  const int levels = detail::requested_levels(size, params);
  const int top = std::max(levels, finest + std::min(levels, 2));
  return effective_levels(size, std::min(kMaxLevels, top));
}

DenseLK::DenseLK(const LkParams& params, const Executor* executor)
    : params_(params), executor_(executor) {
  params_.validate();
}

DenseLK::~DenseLK() = default;
DenseLK::DenseLK(DenseLK&&) noexcept = default;
DenseLK& DenseLK::operator=(DenseLK&&) noexcept = default;

void DenseLK::set_params(const LkParams& params) {
  params.validate();
  params_ = params;
}

void DenseLK::reserve(cv::Size size, const FlowOptions& options) {
  // A pair of black frames takes every buffer a pair of this size takes.
  const cv::Mat black = cv::Mat::zeros(size, CV_8UC1);
  FlowResult ignored;
  calc(black, black, ignored, options);
}

void DenseLK::collectGarbage() {
  ws_.reset();
}

std::size_t DenseLK::workspace_bytes() const {
  return ws_ ? ws_->bytes() : 0;
}

void DenseLK::calc(const cv::Mat& frame_t, const cv::Mat& frame_t1, FlowResult& result,
                   const FlowOptions& options) {
  if (frame_t.empty() || frame_t1.empty()) throw Error("input frame is empty");
  if (frame_t.size() != frame_t1.size()) {
    throw Error("frames differ in size: " + std::to_string(frame_t.cols) + "x" +
                std::to_string(frame_t.rows) + " vs " + std::to_string(frame_t1.cols) + "x" +
                std::to_string(frame_t1.rows));
  }
  if (!ws_) ws_ = std::make_unique<Workspace>();
  const int levels = flow_pyramid_levels(frame_t.size(), params_, options);
  // The two pyramids side by side when there are threads for it.
  const cv::Mat* frames[] = {&frame_t, &frame_t1};
  Pyramid* pyramids[] = {&ws_->pyr_t, &ws_->pyr_t1};
  auto build = [&](int b, int e) {
    for (int i = b; i < e; ++i)
      build_pyramid(*frames[i], levels, params_.sigma, *pyramids[i]);
  };
  if (executor_ && executor_->concurrency() > 1) {
    executor_->for_range(0, 2, 1, build);
  } else {
    build(0, 2);
  }
  flow_from_pyramids(ws_->pyr_t, ws_->pyr_t1, params_, result, options, executor_, *ws_);
}

void DenseLK::calc(const Pyramid& pyr_t, const Pyramid& pyr_t1, FlowResult& result,
                   const FlowOptions& options) {
  if (!ws_) ws_ = std::make_unique<Workspace>();
  flow_from_pyramids(pyr_t, pyr_t1, params_, result, options, executor_, *ws_);
}

FlowResult DenseLK::calc(const cv::Mat& frame_t, const cv::Mat& frame_t1,
                         const FlowOptions& options) {
  FlowResult result;
  calc(frame_t, frame_t1, result, options);
  return result;
}

FlowResult DenseLK::calc(const Pyramid& pyr_t, const Pyramid& pyr_t1, const FlowOptions& options) {
  FlowResult result;
  calc(pyr_t, pyr_t1, result, options);
  return result;
}

void dense_flow(const cv::Mat& frame_t, const cv::Mat& frame_t1, const LkParams& params,
                FlowResult& result, const FlowOptions& options, const Executor* executor) {
  DenseLK(params, executor).calc(frame_t, frame_t1, result, options);
}

void dense_flow(const Pyramid& pyr_t, const Pyramid& pyr_t1, const LkParams& params,
                FlowResult& result, const FlowOptions& options, const Executor* executor) {
  DenseLK(params, executor).calc(pyr_t, pyr_t1, result, options);
}

FlowResult dense_flow(const cv::Mat& frame_t, const cv::Mat& frame_t1, const LkParams& params,
                      const FlowOptions& options, const Executor* executor) {
  FlowResult result;
  dense_flow(frame_t, frame_t1, params, result, options, executor);
  return result;
}

FlowResult dense_flow(const Pyramid& pyr_t, const Pyramid& pyr_t1, const LkParams& params,
                      const FlowOptions& options, const Executor* executor) {
  FlowResult result;
  dense_flow(pyr_t, pyr_t1, params, result, options, executor);
  return result;
}

}  // namespace roiflow::flow
