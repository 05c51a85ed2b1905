// The coarse search, the level count and dense_flow's hook (large_motion.hpp).
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <opencv2/imgproc.hpp>
#include <string>
#include <vector>

#include "core/error.hpp"
#include "flow/large_motion.hpp"
#include "flow/pyramid.hpp"
#include "flow/window_cost.hpp"

namespace roiflow::flow {

namespace {

struct Displacement {
  int dx, dy;
};

// Every displacement of the square of `radius`, nearest first: scanned in this order with a
// strict "better than", a tie keeps the displacement nearest to the prior.
std::vector<Displacement> spiral(int radius) {
  std::vector<Displacement> out;
  for (int dy = -radius; dy <= radius; ++dy)
    for (int dx = -radius; dx <= radius; ++dx)
      out.push_back({dx, dy});
  std::stable_sort(out.begin(), out.end(), [](const Displacement& a, const Displacement& b) {
    return a.dx * a.dx + a.dy * a.dy < b.dx * b.dx + b.dy * b.dy;
  });
  return out;
}

// One direction of the search: every pixel of `a` matched in `b` at prior + displacement.
struct Matches {
  std::vector<std::int32_t> du, dv;  // best displacement, absolute (prior included)
  std::vector<float> cost;           // its window cost
  std::vector<float> prior_cost;     // the window cost of the prior itself
  // The backward search from frame t+1's pixels: the window pair of pixel x and x + s is the
  // window pair of pixel t = x + s and t - s, so each forward cost is also the backward cost
  // of its target, and one pass gives both directions.
  std::vector<std::int32_t> back_du, back_dv;
  std::vector<float> back_cost;
};

// `b` with `pad` replicated pixels on every side, so that every displacement reads in bounds.
cv::Mat padded(const cv::Mat& b, int pad) {
  cv::Mat out;
  cv::copyMakeBorder(b, out, pad, pad, pad, pad, cv::BORDER_REPLICATE);
  return out;
}

// Every pixel of `a` matched in `b` at the displacements order[first, last) (around `prior`):
// the window costs of one displacement stream through a StreamingZssd row by row, and each row
// updates the running best forward and, at the targets, backward.
Matches match_range(const cv::Mat& a, const cv::Mat& b_padded, int pad, cv::Point prior,
                    const std::vector<Displacement>& order, int first, int last, int window) {
  const int w = a.cols, h = a.rows;
  const std::size_t n = static_cast<std::size_t>(w) * h;
  Matches m;
  m.du.assign(n, prior.x);
  m.dv.assign(n, prior.y);
  m.cost.assign(n, std::numeric_limits<float>::infinity());
  m.prior_cost.assign(n, 0.f);
  m.back_du.assign(n, -prior.x);
  m.back_dv.assign(n, -prior.y);
  m.back_cost.assign(n, std::numeric_limits<float>::infinity());
  detail::StreamingZssd z(w, h, window);
  std::vector<float> cost_row;
  for (int i = first; i < last; ++i) {
    const Displacement& s = order[static_cast<std::size_t>(i)];
    const int du = prior.x + s.dx, dv = prior.y + s.dy;
    const bool at_prior = s.dx == 0 && s.dy == 0;
    const auto fill = [&](int y, float* __restrict d) {
      const float* __restrict pa = a.ptr<float>(y);
      const float* __restrict pb = b_padded.ptr<float>(y + pad + dv) + pad + du;
      for (int x = 0; x < w; ++x)
        d[x] = pb[x] - pa[x];
    };
    const auto use = [&](int y, const float* __restrict c) {
      const std::size_t row = static_cast<std::size_t>(y) * w;
      if (at_prior) std::copy_n(c, w, m.prior_cost.data() + row);
      float* __restrict best = m.cost.data() + row;
      std::int32_t* __restrict bu = m.du.data() + row;
      std::int32_t* __restrict bv = m.dv.data() + row;
      for (int x = 0; x < w; ++x) {
        const bool better = c[x] < best[x];
        best[x] = better ? c[x] : best[x];
        bu[x] = better ? du : bu[x];
        bv[x] = better ? dv : bv[x];
      }
      // The same costs are the backward search's at the targets t = x + (du, dv).
      const int ty = y + dv;
      if (ty < 0 || ty >= h) return;
      const int x0 = std::max(0, -du), x1 = std::min(w, w - du);
      const std::ptrdiff_t target = static_cast<std::ptrdiff_t>(ty) * w + du;  // + x
      float* __restrict tb = m.back_cost.data() + target;
      std::int32_t* __restrict tu = m.back_du.data() + target;
      std::int32_t* __restrict tv = m.back_dv.data() + target;
      for (int x = x0; x < x1; ++x) {
        const bool better = c[x] < tb[x];
        tb[x] = better ? c[x] : tb[x];
        tu[x] = better ? -du : tu[x];
        tv[x] = better ? -dv : tv[x];
      }
    };
    detail::for_each_cost_row(z, fill, use, cost_row);
  }
  return m;
}

// match_range over all of `order`. With an executor of two threads or more, contiguous parts
// of `order` side by side, then merged in order: a later part's best replaces the earlier one's
// only where it is strictly better, which is what one running best over the whole order keeps
// (the first displacement of the smallest cost), so the result is the one-thread result.
Matches match(const cv::Mat& a, const cv::Mat& b_padded, int pad, cv::Point prior,
              const std::vector<Displacement>& order, int window, const Executor* executor) {
  const int count = static_cast<int>(order.size());
  if (!executor || executor->concurrency() < 2 || count < 2) {
    return match_range(a, b_padded, pad, prior, order, 0, count, window);
  }
  const int parts = std::min(count, 2 * executor->concurrency());
  std::vector<Matches> part(static_cast<std::size_t>(parts));
  executor->for_range(0, parts, 1, [&](int p0, int p1) {
    for (int p = p0; p < p1; ++p) {
      part[static_cast<std::size_t>(p)] = match_range(
          a, b_padded, pad, prior, order, count * p / parts, count * (p + 1) / parts, window);
    }
  });
  Matches m = std::move(part[0]);  // holds order[0], the prior itself, and so its costs
  const std::size_t n = m.cost.size();
  for (int p = 1; p < parts; ++p) {
    const Matches& q = part[static_cast<std::size_t>(p)];
    for (std::size_t i = 0; i < n; ++i) {
      if (q.cost[i] < m.cost[i]) {
        m.cost[i] = q.cost[i];
        m.du[i] = q.du[i];
        m.dv[i] = q.dv[i];
      }
      if (q.back_cost[i] < m.back_cost[i]) {
        m.back_cost[i] = q.back_cost[i];
        m.back_du[i] = q.back_du[i];
        m.back_dv[i] = q.back_dv[i];
      }
    }
  }
  return m;
}

// Index of the reliable pixel nearest to each pixel (itself when reliable); -1 when none is.
std::vector<int> nearest_reliable(const std::vector<std::uint8_t>& reliable, int w, int h) {
  const std::size_t n = reliable.size();
  std::vector<int> where;
  cv::Mat zeros(h, w, CV_8U);
  for (std::size_t i = 0; i < n; ++i) {
    zeros.data[i] = reliable[i] ? 0 : 255;
    if (reliable[i]) where.push_back(static_cast<int>(i));
  }
  std::vector<int> out(n, -1);
  if (where.empty()) return out;
  cv::Mat dist, labels;
  // Labels number the zero pixels (the reliable ones) in row-major order, from 1.
  cv::distanceTransform(zeros, dist, labels, cv::DIST_L2, cv::DIST_MASK_5, cv::DIST_LABEL_PIXEL);
  for (std::size_t i = 0; i < n; ++i)
    out[i] = reliable[i] ? static_cast<int>(i) : where[labels.at<int>(static_cast<int>(i)) - 1];
  return out;
}

void check_search(const cv::Mat& i0, const cv::Mat& i1, const SearchParams& p, const cv::Mat& u,
                  const cv::Mat& v) {
  if (i0.empty() || i0.type() != CV_32FC1 || i1.type() != CV_32FC1 || i1.size() != i0.size() ||
      u.type() != CV_32FC1 || v.type() != CV_32FC1 || u.size() != i0.size() ||
      v.size() != i0.size()) {
    throw Error("coarse search: images and flow must be non-empty CV_32FC1 of one size");
  }
  if (p.radius < 1 || p.radius > kMaxSearchRadius || p.window < 3 || p.window > 15 ||
      p.window % 2 == 0 || !(p.fb_tolerance >= 0.f) || !(p.prior_margin >= 0.f) ||
      !(p.prior_margin < 1.f)) {
    throw Error("coarse search: radius must be in 1.." + std::to_string(kMaxSearchRadius) +
                ", the window odd in 3..15, the tolerance >= 0 and the margin in [0, 1); got "
                "radius " +
                std::to_string(p.radius) + ", window " + std::to_string(p.window) + ", tolerance " +
                std::to_string(p.fb_tolerance) + ", margin " + std::to_string(p.prior_margin));
  }
}

}  // namespace

int auto_levels(cv::Size size, double expected_motion, int coarsest_side) {
  if (size.empty()) throw Error("auto levels: the frame size is empty");
  int levels = 1;
  while (levels < kMaxLevels) {
    const cv::Size next = level_size(size, levels);
    if (std::min(next.width, next.height) < std::max(coarsest_side, kMinLevelSide)) break;
    // A small expected motion is seen as two pixels or less one level before: enough.
    if (expected_motion > 0 && expected_motion / static_cast<double>(1 << (levels - 1)) <= 2.0)
      break;
    ++levels;
  }
  return levels;
}

int search_radius_for(cv::Size size, int level, double expected_motion, int max_radius) {
  const double motion =
      expected_motion > 0 ? expected_motion : 0.25 * std::max(size.width, size.height);
  const int radius = static_cast<int>(std::ceil(motion / static_cast<double>(1 << level)));
  return std::clamp(radius, 1, max_radius);
}

void search_flow(const cv::Mat& i0, const cv::Mat& i1, cv::Point2f prior,
                 const SearchParams& params, cv::Mat& u, cv::Mat& v, const Executor* executor) {
  check_search(i0, i1, params, u, v);
  const int w = i0.cols, h = i0.rows;
  const std::size_t n = static_cast<std::size_t>(w) * h;
  // A prior beyond the frame would only read replicated borders.
  const cv::Point p(std::clamp(static_cast<int>(std::lround(prior.x)), -w, w),
                    std::clamp(static_cast<int>(std::lround(prior.y)), -h, h));
  const int pad = params.radius + std::max(std::abs(p.x), std::abs(p.y));
  const std::vector<Displacement> order = spiral(params.radius);
  const Matches fwd = match(i0, padded(i1, pad), pad, p, order, params.window, executor);

  std::vector<std::uint8_t> reliable(n);
  const float tol2 = params.fb_tolerance * params.fb_tolerance;
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      const std::size_t i = static_cast<std::size_t>(y) * w + x;
      const int tx = std::clamp(x + fwd.du[i], 0, w - 1), ty = std::clamp(y + fwd.dv[i], 0, h - 1);
      const std::size_t j = static_cast<std::size_t>(ty) * w + tx;
      const float ex = static_cast<float>(fwd.du[i] + fwd.back_du[j]);
      const float ey = static_cast<float>(fwd.dv[i] + fwd.back_dv[j]);
      const bool at_prior = fwd.du[i] == p.x && fwd.dv[i] == p.y;
      const bool saves = fwd.prior_cost[i] - fwd.cost[i] >= params.prior_margin * fwd.prior_cost[i];
      reliable[i] = ex * ex + ey * ey <= tol2 && (at_prior || saves) ? 1 : 0;
    }
  }
  // Unreliable pixels: the prior, or the flow of their nearest reliable pixel, whichever field
  // fits their window better (the prior on a tie).
  const std::vector<int> nearest = nearest_reliable(reliable, w, h);
  cv::Mat prior_u(h, w, CV_32F), prior_v(h, w, CV_32F), near_u(h, w, CV_32F), near_v(h, w, CV_32F);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      const std::size_t i = static_cast<std::size_t>(y) * w + x;
      const std::size_t k = nearest[i] >= 0 ? static_cast<std::size_t>(nearest[i]) : i;
      const bool own = reliable[i] != 0, near = nearest[i] >= 0;
      prior_u.at<float>(y, x) = own ? fwd.du[i] : static_cast<float>(p.x);
      prior_v.at<float>(y, x) = own ? fwd.dv[i] : static_cast<float>(p.y);
      near_u.at<float>(y, x) = near ? fwd.du[k] : static_cast<float>(p.x);
      near_v.at<float>(y, x) = near ? fwd.dv[k] : static_cast<float>(p.y);
    }
  }
  std::vector<float> prior_cost, near_cost;
  detail::field_costs(i0, i1, prior_u, prior_v, params.window, prior_cost);
  detail::field_costs(i0, i1, near_u, near_v, params.window, near_cost);
  for (int y = 0; y < h; ++y) {
    float* pu = u.ptr<float>(y);
    float* pv = v.ptr<float>(y);
    for (int x = 0; x < w; ++x) {
      const std::size_t i = static_cast<std::size_t>(y) * w + x;
      const bool near = near_cost[i] < prior_cost[i];
      pu[x] = near ? near_u.at<float>(y, x) : prior_u.at<float>(y, x);
      pv[x] = near ? near_v.at<float>(y, x) : prior_v.at<float>(y, x);
    }
  }
}

namespace detail {

int requested_levels(cv::Size size, const LkParams& params) {
  return params.levels > 0 ? params.levels
                           : auto_levels(size, params.expected_motion, params.coarsest_side);
}

bool seeds_level(const LkParams& params, int level, int levels, const FlowOptions& options) {
  return (level == levels - 1 && params.search_radius > 0 && options.initial_flow.empty()) ||
         (params.fuse_far_step > 0 && level >= params.fuse_far_finest_level) ||
         (params.fuse_step > 0 && level >= params.fuse_finest_level);
}

void seed_level(const LkParams& params, const cv::Mat& i0, const cv::Mat& i1, const cv::Rect& c,
                int level, int levels, const FlowOptions& options, cv::Mat& u, cv::Mat& v,
                const Executor* executor, std::vector<float>* scratch) {
  // A region works on its own rectangle, read as if the frame ended there.
  const cv::Mat a = i0(c), b = i1(c);
  if (level == levels - 1 && params.search_radius > 0 && options.initial_flow.empty()) {
    SearchParams search;
    search.radius = search_radius_for(i0.size() * (1 << level), level, params.expected_motion,
                                      params.search_radius);
    const float scale = 1.f / static_cast<float>(1 << level);
    search_flow(a, b, options.initial_motion * scale, search, u, v, executor);
  }
  // Far candidates first: they carry a motion over a distance the near ones then refine.
  if (params.fuse_far_step > 0 && level >= params.fuse_far_finest_level)
    fuse_candidates(a, b, params.fuse_far_step, kFuseWindow, u, v, executor, scratch);
  if (params.fuse_step > 0 && level >= params.fuse_finest_level)
    fuse_candidates(a, b, params.fuse_step, kFuseWindow, u, v, executor, scratch);
}

}  // namespace detail

}  // namespace roiflow::flow
