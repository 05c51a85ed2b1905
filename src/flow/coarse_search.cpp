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

// The zero-mean SSD of every window of `a` at one displacement, fused in one pass over the rows
// (the search runs this for every displacement, so it must not allocate or call out): running
// column sums of d and d^2 over the window's rows (rows enter and leave; zero columns outside
// `a` make the window clipped, as the counts in inv_n), a direct sum of the window's columns,
// the cost, and the running best.
class DisplacementPass {
 public:
  DisplacementPass(const cv::Mat& a, int window) : a_(a), r_(window / 2) {
    const int w = a.cols, h = a.rows;
    c1_.assign(w + 2 * r_, 0.f);
    c2_.assign(w + 2 * r_, 0.f);
    s1_.resize(w);
    s2_.resize(w);
    ring1_.resize(static_cast<std::size_t>(2 * r_ + 1) * w);
    ring2_.resize(ring1_.size());
    inv_nx_.resize(w);
    inv_ny_.resize(h);
    for (int x = 0; x < w; ++x)
      inv_nx_[x] = 1.f / static_cast<float>(std::min(w - 1, x + r_) - std::max(0, x - r_) + 1);
    for (int y = 0; y < h; ++y)
      inv_ny_[y] = 1.f / static_cast<float>(std::min(h - 1, y + r_) - std::max(0, y - r_) + 1);
  }

  // Displacement (du, dv) into `b_padded` (pad pixels each side): updates m where it is better;
  // the costs into `costs` when it is not null.
  void run(const cv::Mat& b_padded, int pad, int du, int dv, Matches& m, float* costs) {
    const int w = a_.cols, h = a_.rows, r = r_;
    std::fill(c1_.begin(), c1_.end(), 0.f);
    std::fill(c2_.begin(), c2_.end(), 0.f);
    for (int y = 0; y < std::min(r, h); ++y)
      enter(b_padded, pad, du, dv, y);
    const auto iu = static_cast<std::int32_t>(du), iv = static_cast<std::int32_t>(dv);
    for (int y = 0; y < h; ++y) {
      // The leaving row's ring slot is the entering row's: leave first.
      if (y - r - 1 >= 0) leave(y - r - 1);
      if (y + r < h) enter(b_padded, pad, du, dv, y + r);
      const std::size_t row = static_cast<std::size_t>(y) * w;
      float* cost = costs ? costs + row : s1_.data();
      if (r == 3) {
        select_row<3>(row, inv_ny_[y], iu, iv, m, cost);
      } else {
        select_row<-1>(row, inv_ny_[y], iu, iv, m, cost);
      }
    }
  }

 private:
  // The window sums of one row from the column sums, the cost, and the running best: one loop
  // along x. With the radius known at compile time (kR >= 0) the taps unroll and the loop
  // vectorises along x.
  template <int kR>
  void select_row(std::size_t row, float iny, std::int32_t iu, std::int32_t iv, Matches& m,
                  float* __restrict cost) {
    const int w = a_.cols, r = kR >= 0 ? kR : r_;
    const float* __restrict c1 = c1_.data();
    const float* __restrict c2 = c2_.data();
    const float* __restrict inx = inv_nx_.data();
    float* __restrict best = m.cost.data() + row;
    std::int32_t* __restrict bu = m.du.data() + row;
    std::int32_t* __restrict bv = m.dv.data() + row;
    for (int x = 0; x < w; ++x) {
      float s1 = 0.f, s2 = 0.f;
#pragma GCC unroll 16
      for (int k = 0; k <= 2 * r; ++k) {
        s1 += c1[x + k];
        s2 += c2[x + k];
      }
      const float c = s2 - s1 * s1 * (inx[x] * iny);
      cost[x] = c;
      const bool better = c < best[x];
      best[x] = better ? c : best[x];
      bu[x] = better ? iu : bu[x];
      bv[x] = better ? iv : bv[x];
    }
    // The same costs as the backward search's at the targets t = x + (iu, iv) in the frame.
    const int y = static_cast<int>(row / static_cast<std::size_t>(w)), ty = y + iv;
    if (ty < 0 || ty >= a_.rows) return;
    const int x0 = std::max(0, -iu), x1 = std::min(w, w - iu);
    const std::size_t trow = static_cast<std::size_t>(ty) * w + iu;  // + x: the target
    float* __restrict tb = m.back_cost.data() + trow;
    std::int32_t* __restrict tu = m.back_du.data() + trow;
    std::int32_t* __restrict tv = m.back_dv.data() + trow;
    for (int x = x0; x < x1; ++x) {
      const bool better = cost[x] < tb[x];
      tb[x] = better ? cost[x] : tb[x];
      tu[x] = better ? -iu : tu[x];
      tv[x] = better ? -iv : tv[x];
    }
  }

  std::size_t slot(int y) const {
    return static_cast<std::size_t>(y % (2 * r_ + 1)) * static_cast<std::size_t>(a_.cols);
  }

  // Row y of d = b(x + (du, dv)) - a(x) and d^2 into the ring and the column sums.
  void enter(const cv::Mat& b_padded, int pad, int du, int dv, int y) {
    const int w = a_.cols;
    const float* __restrict pa = a_.ptr<float>(y);
    const float* __restrict pb = b_padded.ptr<float>(y + pad + dv) + pad + du;
    float* __restrict d1 = ring1_.data() + slot(y);
    float* __restrict d2 = ring2_.data() + slot(y);
    float* __restrict c1 = c1_.data() + r_;
    float* __restrict c2 = c2_.data() + r_;
    for (int x = 0; x < w; ++x) {
      const float d = pb[x] - pa[x];
      d1[x] = d;
      d2[x] = d * d;
      c1[x] += d;
      c2[x] += d * d;
    }
  }

  void leave(int y) {
    const int w = a_.cols;
    const float* __restrict d1 = ring1_.data() + slot(y);
    const float* __restrict d2 = ring2_.data() + slot(y);
    float* __restrict c1 = c1_.data() + r_;
    float* __restrict c2 = c2_.data() + r_;
    for (int x = 0; x < w; ++x) {
      c1[x] -= d1[x];
      c2[x] -= d2[x];
    }
  }

  const cv::Mat& a_;
  int r_;
  std::vector<float> c1_, c2_, s1_, s2_, ring1_, ring2_, inv_nx_, inv_ny_;
};

Matches match(const cv::Mat& a, const cv::Mat& b_padded, int pad, cv::Point prior,
              const std::vector<Displacement>& order, int window) {
  const std::size_t n = static_cast<std::size_t>(a.cols) * a.rows;
  Matches m;
  m.du.assign(n, prior.x);
  m.dv.assign(n, prior.y);
  m.cost.assign(n, std::numeric_limits<float>::infinity());
  m.prior_cost.assign(n, 0.f);
  m.back_du.assign(n, -prior.x);
  m.back_dv.assign(n, -prior.y);
  m.back_cost.assign(n, std::numeric_limits<float>::infinity());
  DisplacementPass pass(a, window);
  for (const Displacement& s : order) {
    const bool at_prior = s.dx == 0 && s.dy == 0;
    pass.run(b_padded, pad, prior.x + s.dx, prior.y + s.dy, m,
             at_prior ? m.prior_cost.data() : nullptr);
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
                 const SearchParams& params, cv::Mat& u, cv::Mat& v) {
  check_search(i0, i1, params, u, v);
  const int w = i0.cols, h = i0.rows;
  const std::size_t n = static_cast<std::size_t>(w) * h;
  // A prior beyond the frame would only read replicated borders.
  const cv::Point p(std::clamp(static_cast<int>(std::lround(prior.x)), -w, w),
                    std::clamp(static_cast<int>(std::lround(prior.y)), -h, h));
  const int pad = params.radius + std::max(std::abs(p.x), std::abs(p.y));
  const std::vector<Displacement> order = spiral(params.radius);
  const Matches fwd = match(i0, padded(i1, pad), pad, p, order, params.window);

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
  detail::FieldCost field_cost(w, h, params.window);
  std::vector<float> prior_cost, near_cost;
  field_cost(i0, i1, prior_u, prior_v, prior_cost);
  field_cost(i0, i1, near_u, near_v, near_cost);
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
                int level, int levels, const FlowOptions& options, cv::Mat& u, cv::Mat& v) {
  // A region works on its own rectangle, read as if the frame ended there.
  const cv::Mat a = i0(c), b = i1(c);
  if (level == levels - 1 && params.search_radius > 0 && options.initial_flow.empty()) {
    SearchParams search;
    search.radius = search_radius_for(i0.size() * (1 << level), level, params.expected_motion,
                                      params.search_radius);
    const float scale = 1.f / static_cast<float>(1 << level);
    search_flow(a, b, options.initial_motion * scale, search, u, v);
  }
  // Far candidates first: they carry a motion over a distance the near ones then refine.
  if (params.fuse_far_step > 0 && level >= params.fuse_far_finest_level)
    fuse_candidates(a, b, params.fuse_far_step, kFuseWindow, u, v);
  if (params.fuse_step > 0 && level >= params.fuse_finest_level)
    fuse_candidates(a, b, params.fuse_step, kFuseWindow, u, v);
}

}  // namespace detail

}  // namespace roiflow::flow
