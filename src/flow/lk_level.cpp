#include "flow/lk_level.hpp"

#include <algorithm>
#include <cstddef>
#include <vector>

#include "flow/large_motion.hpp"

namespace roiflow::flow::detail {

Window make_window(int patch, bool half_pixel_grid) {
  const int h = patch / 2;
  const bool odd = (patch % 2) != 0;
  if (!half_pixel_grid) return odd ? Window{-h, h, false} : Window{-h, h, true};
  return odd ? Window{-h - 1, h, true} : Window{-h, h - 1, false};
}

// Sum of the window's weights at index i of an axis of n samples (the clipped window).
float window_weight(const Window& win, int i, int n) {
  const int a = std::max(0, i + win.lo), b = std::min(n - 1, i + win.hi);
  float w = static_cast<float>(b - a + 1);
  if (win.half) {
    if (i + win.lo >= 0) w -= 0.5f;
    if (i + win.hi <= n - 1) w -= 0.5f;
  }
  return w;
}

std::size_t RowScratch::bytes() const {
  std::size_t n = ring.capacity() + colsum.capacity() + col.capacity() + prefix.capacity();
  for (const WarpedRow& r : warp_cache)
    n += r.m.capacity() + r.d.capacity();
  return n * sizeof(float);
}

RowScratch& LevelScratch::wavefront(int iteration) {
  while (static_cast<int>(wavefront_.size()) <= iteration)
    wavefront_.push_back(std::make_unique<RowScratch>());
  return *wavefront_[iteration];
}

void LevelScratch::reserve_stripes(int n) {
  while (static_cast<int>(stripes_.size()) < n)
    stripes_.push_back(std::make_unique<RowScratch>());
  if (busy_size_ < n) {
    busy_ = std::make_unique<std::atomic<bool>[]>(n);
    busy_size_ = n;
  }
  for (int i = 0; i < busy_size_; ++i)
    busy_[i].store(false, std::memory_order_relaxed);
}

std::size_t LevelScratch::bytes() const {
  std::size_t n = 0;
  for (const auto* pool : {&wavefront_, &stripes_}) {
    for (const auto& s : *pool)
      n += s->bytes();
  }
  return n;
}

LevelScratch::Lease::Lease(LevelScratch& owner) : owner_(owner) {
  const int n = std::min(owner.busy_size_, static_cast<int>(owner.stripes_.size()));
  for (int i = 0; i < n; ++i) {
    if (!owner.busy_[i].exchange(true, std::memory_order_acquire)) {
      slot_ = i;
      scratch_ = owner.stripes_[i].get();
      return;
    }
  }
  // More bodies at once than the executor's concurrency promised: a private scratch.
  own_ = std::make_unique<RowScratch>();
  scratch_ = own_.get();
}

LevelScratch::Lease::~Lease() {
  if (slot_ >= 0) owner_.busy_[slot_].store(false, std::memory_order_release);
}

namespace {

// boundary, so stripes much shorter than the window would waste work.
constexpr int kStripeRows = 32;

// One refinement iteration for rows [yb, ye) of the computed rectangle. Reads the previous
// flow (planar, comp-sized), writes the new one. Everything a row needs is produced by
// streaming: warped rows -> derivative-product rows -> vertical running sums -> horizontal
// running sums -> 2x2 solve, so the working set stays a few rows wide.
class RowIterator {
 public:
  RowIterator(const LevelProblem& p, const float* u_old, const float* v_old, RowScratch& scratch)
      : p_(p),
        u_old_(u_old),
        v_old_(v_old),
        w_(p.comp.width),
        h_(p.comp.height),
        ring_rows_(p.win.hi - p.win.lo + 1),
        scratch_(scratch) {
    for (int i = 0; i < 4; ++i) {
      WarpedRow& e = warp_cache_[i];
      e.row = -1;
      e.m.resize(w_ + 2);  // one replicated column on each side
      e.d.resize(w_ + 2);
    }
    // Rows of these buffers are always written before they are read: no clearing needed.
    ring_.resize(static_cast<size_t>(ring_rows_) * kChannels * w_);
    colsum_.assign(static_cast<size_t>(kChannels) * w_, 0.f);
    hpad_lo_ = -p.win.lo;
    const int hpad = hpad_lo_ + w_ + p.win.hi + 1;
    col_.assign(static_cast<size_t>(kChannels) * hpad, 0.f);
    col_stride_ = hpad;
    // Prefix sums per channel: 1 - lo zeros before column 0 and hi copies of the total after
    // the last, so every window is prefix[x + hi] - prefix[x + lo - 1] without a clamp.
    prefix_pad_ = 1 - p.win.lo;
    prefix_stride_ = static_cast<size_t>(prefix_pad_ + w_ + p.win.hi);
    prefix_.assign(kChannels * prefix_stride_, 0.f);
  }

  // Rows [yb, ye) of the new flow. yb must be a multiple of kStripeRows (or 0).
  void run(int yb, int ye, float* u_new, float* v_new, float* confidence) {
    start(yb);
    for (int y = yb; y < ye; ++y)
      next_row(u_new, v_new, confidence);
  }

  // Row by row: start(yb), then each next_row() writes the next row of the new flow. Row y
  // reads rows y .. y + lookahead() of the previous flow.
  void start(int yb) {
    for (int s = yb + p_.win.lo; s < yb + p_.win.hi; ++s)
      advance(s, false);
    first_ = next_ = yb;
  }
  int lookahead() const { return p_.win.hi + 1; }

  void next_row(float* u_new, float* v_new, float* confidence) {
    const Window& win = p_.win;
    const int y = next_++;
    advance(y + win.hi, y > first_);
    // A running sum's rounding depends on where it started. Summing the window afresh at
    // every stripe boundary makes the result independent of how rows are split among
    // threads: bit-identical for any thread count.
    if (y % kStripeRows == 0) resum_window(y);
    const float* columns = colsum_.data();
    int stride = w_;
    if (win.half) {
      half_weight_ends(y);
      columns = col_.data() + hpad_lo_;
      stride = col_stride_;
    }
    const size_t pstride = prefix_stride_;
    float* prefix = prefix_.data() + prefix_pad_;
    prefix_scan(columns, stride, w_, prefix, pstride);
    for (int c = 0; c < kChannels; ++c) {
      float* pc = prefix + c * pstride;
      std::fill(pc + w_, pc + w_ + win.hi, pc[w_ - 1]);
    }
    const size_t off = static_cast<size_t>(y) * w_;
    WindowSolve ws{w_,
                   prefix,
                   pstride,
                   win.half ? columns : nullptr,
                   stride,
                   win.lo,
                   win.hi,
                   p_.inv_cx.data(),
                   1.f / p_.cy[y],
                   p_.lambda};
    solve_pixels(ws, u_old_ + off, v_old_ + off, u_new + off, v_new + off,
                 confidence ? confidence + off : nullptr);
  }

 private:
  // Mean image (I0 + warped I1) / 2, difference warped I1 - I0, and flow of row r of comp.
  const WarpedRow& warped(int r) {
    r = std::clamp(r, 0, h_ - 1);
    WarpedRow& e = warp_cache_[static_cast<size_t>(r) & 3u];
    if (e.row == r) return e;
    e.row = r;
    const int gy = p_.comp.y + r;
    warp_row(*p_.i1, p_.i0->ptr<float>(gy) + p_.comp.x, p_.comp.x, gy, w_,
             u_old_ + static_cast<size_t>(r) * w_, v_old_ + static_cast<size_t>(r) * w_,
             e.m.data() + 1, e.d.data() + 1);
    if (p_.mask_outside) {
      mask_outside_row(*p_.i1, p_.i0->ptr<float>(gy) + p_.comp.x, p_.comp.x, gy, w_,
                       u_old_ + static_cast<size_t>(r) * w_, v_old_ + static_cast<size_t>(r) * w_,
                       e.m.data() + 1, e.d.data() + 1);
    }
    e.u = u_old_ + static_cast<size_t>(r) * w_;
    e.v = v_old_ + static_cast<size_t>(r) * w_;
    for (auto* vec : {&e.m, &e.d}) {
      (*vec)[0] = (*vec)[1];
      (*vec)[w_ + 1] = (*vec)[w_];
    }
    return e;
  }

  void resum_window(int y) {
    std::fill(colsum_.begin(), colsum_.end(), 0.f);
    const size_t n = static_cast<size_t>(kChannels) * w_;
    float* __restrict acc = colsum_.data();
    for (int s = y + p_.win.lo; s <= y + p_.win.hi; ++s) {
      const float* __restrict row = ring_row(s);
      for (size_t i = 0; i < n; ++i)
        acc[i] += row[i];
    }
  }

  // The ring holds the products of the derivative-grid rows in the vertical window.
  float* ring_row(int s) {
    const int slot = ((s % ring_rows_) + ring_rows_) % ring_rows_;
    return ring_.data() + static_cast<size_t>(slot) * kChannels * w_;
  }

  // Brings derivative-grid row s (zero outside the rectangle) into the vertical window;
  // with `leaving`, row s - ring_rows_ leaves it.
  void advance(int s, bool leaving) {
    float* row = ring_row(s);
    float* acc = colsum_.data();
    const float inv_s2 = p_.robust_inv_scale2;
    if (s < 0 || s >= h_) {
      const size_t n = static_cast<size_t>(kChannels) * w_;
      for (size_t i = 0; i < n; ++i) {
        if (leaving) acc[i] -= row[i];
        row[i] = 0.f;
      }
      return;
    }
    // Horn–Schunck reads rows s, s + 1; the grid stencils s - 1, s, s + 1 (clamped).
    const WarpedRow& up = warped(p_.derivative == Derivative::HornSchunck ? s : s - 1);
    const WarpedRow& centre = warped(s);
    const WarpedRow& down = warped(s + 1);
    row_window_terms(p_.derivative, up, centre, down, w_, inv_s2, leaving, row, acc);
  }

  // Column sums of output row y with the two end rows at weight 1/2, into the zero-padded
  // col_ (the padding gives the horizontal half-weight correction its zeros off the edge).
  void half_weight_ends(int y) {
    const Window& win = p_.win;
    const float* top = ring_row(y + win.lo);
    const float* bot = ring_row(y + win.hi);
    for (int c = 0; c < kChannels; ++c) {
      const size_t o = static_cast<size_t>(c) * w_;
      const float* __restrict src = colsum_.data() + o;
      const float* __restrict t = top + o;
      const float* __restrict b = bot + o;
      float* __restrict dst = col_.data() + static_cast<size_t>(c) * col_stride_ + hpad_lo_;
      for (int x = 0; x < w_; ++x)
        dst[x] = src[x] - 0.5f * (t[x] + b[x]);
    }
  }

  const LevelProblem& p_;
  const float* u_old_;
  const float* v_old_;
  int w_, h_;
  int ring_rows_;
  RowScratch& scratch_;
  int first_ = 0, next_ = 0;
  WarpedRow* warp_cache_ = scratch_.warp_cache;
  std::vector<float>& ring_ = scratch_.ring;
  std::vector<float>& colsum_ = scratch_.colsum;
  std::vector<float>& col_ = scratch_.col;
  int col_stride_ = 0;
  int hpad_lo_ = 0;
  std::vector<float>& prefix_ = scratch_.prefix;
  size_t prefix_stride_ = 0;
  int prefix_pad_ = 0;
};

}  // namespace

void iterate_level(const LevelProblem& p, cv::Mat& u, cv::Mat& v, cv::Mat& u_next, cv::Mat& v_next,
                   cv::Mat* confidence, int iterations, const Executor& executor,
                   LevelScratch& scratch) {
  u_next.create(u.size(), CV_32F);
  v_next.create(v.size(), CV_32F);
  const int h = p.comp.height;
  // Iteration k reads the flow of iteration k - 1 (ping-pong between the two buffers) and
  // writes its own; the last one also the confidence.
  auto input = [&](int k, int plane) -> cv::Mat& {
    return (k % 2 == 0) ? (plane == 0 ? u : v) : (plane == 0 ? u_next : v_next);
  };
  auto output = [&](int k, int plane) -> cv::Mat& { return input(k + 1, plane); };
  auto conf_of = [&](int k) {
    return (k + 1 == iterations && confidence) ? confidence->ptr<float>() : nullptr;
  };
  // Stripes pay only when every thread gets a few of them: each costs a task, a fresh window
  // sum and a pass over the level per iteration instead of the wavefront's one. A tracker's
  // region of ~100 rows split over two threads (one of them busy decoding) ran slower than the
  // serial schedule.
  const int stripes = (h + kStripeRows - 1) / kStripeRows;
  if (executor.concurrency() == 1 || stripes < 2 * executor.concurrency()) {
    // Serial: all iterations advance together as a wavefront, iteration k a fixed lag
    // behind k - 1, so each row is read again while it is still in cache instead of once per
    // pass over the level. Iteration k + 1 overwrites a row of k - 1's buffer only after
    // iteration k, the last reader of that row, has moved past it.
    std::vector<RowIterator> rows;
    rows.reserve(iterations);
    for (int k = 0; k < iterations; ++k) {
      rows.emplace_back(p, input(k, 0).ptr<float>(), input(k, 1).ptr<float>(),
                        scratch.wavefront(k));
    }
    const int lag = rows[0].lookahead() + 1;
    for (int t = 0; t < h + (iterations - 1) * lag; ++t) {
      for (int k = 0; k < iterations; ++k) {
        const int y = t - k * lag;
        if (y == 0) rows[k].start(0);  // reads rows 0 .. lookahead() - 1 of its input
        if (y >= 0 && y < h) {
          rows[k].next_row(output(k, 0).ptr<float>(), output(k, 1).ptr<float>(), conf_of(k));
        }
      }
    }
  } else {
    scratch.reserve_stripes(executor.concurrency());
    for (int k = 0; k < iterations; ++k) {
      const float* uo = input(k, 0).ptr<float>();
      const float* vo = input(k, 1).ptr<float>();
      float* un = output(k, 0).ptr<float>();
      float* vn = output(k, 1).ptr<float>();
      float* conf = conf_of(k);
      executor.for_range(0, stripes, 1, [&](int sb, int se) {
        const LevelScratch::Lease lease(scratch);
        RowIterator stripe(p, uo, vo, *lease);
        stripe.run(sb * kStripeRows, std::min(h, se * kStripeRows), un, vn, conf);
      });
    }
  }
  if (iterations % 2 == 1) {
    std::swap(u, u_next);
    std::swap(v, v_next);
  }
}

// Flow component of the coarser level (origin `src_origin` in its level) resampled onto
// rectangle `dst` of the finer level and doubled. Pixel x of the finer level sits at x / 2 of
// the coarser one, so along each axis the finer pixels alternate between copies of a coarse
// pixel and means of two neighbours; borders replicate.
void upsample_flow(const cv::Mat& src, cv::Point src_origin, const cv::Rect& dst, cv::Mat& out) {
  const int n = src.cols;
  // Coarse index of finer pixel 0 (floor of half of `twice`) and whether it falls between
  // two coarse pixels. dst lies inside the coarse rectangle, so the index is >= 0.
  const int twice_x = dst.x - 2 * src_origin.x;
  const int k0 = twice_x >> 1;
  const bool x_between = (twice_x & 1) != 0;
  std::vector<float> copy(n + 2), mean(n + 2);
  out.create(dst.size(), CV_32F);
  for (int y = 0; y < dst.height; ++y) {
    const int twice_y = dst.y + y - 2 * src_origin.y;
    const int y0 = std::clamp(twice_y >> 1, 0, src.rows - 1);
    const int y1 = std::min(y0 + 1, src.rows - 1);
    const float fy = (twice_y & 1) ? 0.5f : 0.f;
    const float* a = src.ptr<float>(y0);
    const float* b = src.ptr<float>(y1);
    for (int x = 0; x < n; ++x)
      copy[x] = 2.f * (a[x] + fy * (b[x] - a[x]));
    copy[n] = copy[n + 1] = copy[n - 1];
    for (int x = 0; x <= n; ++x)
      mean[x] = 0.5f * (copy[x] + copy[x + 1]);
    // Finer pixels alternate: even ones take `first`, odd ones `second`.
    const float* first = x_between ? mean.data() + k0 : copy.data() + k0;
    const float* second = x_between ? copy.data() + k0 + 1 : mean.data() + k0;
    float* o = out.ptr<float>(y);
    const int pairs = dst.width / 2;
    for (int i = 0; i < pairs; ++i) {
      o[2 * i] = first[i];
      o[2 * i + 1] = second[i];
    }
    if (dst.width & 1) o[dst.width - 1] = first[pairs];
  }
}

}  // namespace roiflow::flow::detail
