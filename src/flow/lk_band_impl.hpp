// The band driver of dense LK's kernels (lk_kernels.hpp), compiled once per instruction set:
// lk_kernels_<isa>.cpp defines ROIFLOW_KERNEL_TABLE (the exported table's name) and includes
// this file. Everything here has internal linkage, and no standard-library template is used, so
// the copies built with different instruction sets share no symbol.
//
// One iteration streams over the rows of the computed rectangle: warp row -> the five window
// terms of one derivative-grid row, added into vertical running sums -> horizontal prefix sums
// -> the 2x2 solve of one output row, chunk by chunk along the row. The iterations of a level
// advance together as a wavefront (iteration k a fixed lag behind k - 1, reading its rows from
// a small ring), so each row is reused while it is in cache.
#include <cstddef>

#include "flow/lk_kernels.hpp"
#include "flow/lk_kernels_impl.hpp"
#include "flow/lk_pairs_impl.hpp"
#include "flow/lk_rows_impl.hpp"

#ifndef ROIFLOW_KERNEL_TABLE
#error "define ROIFLOW_KERNEL_TABLE before including lk_band_impl.hpp"
#endif

namespace roiflow::flow::detail {
namespace {

// ---------------------------------------------------------------------------------------------
// Scratch of one iteration: four warped rows (m, d and Horn–Schunck's pairs), the ring of window
// terms, the vertical sums, the half-weight columns and the prefix sums.
struct Layout {
  Idx wrow;       // floats per warped row (m or d), kPad on each side
  Idx slot;       // floats per cached warped row: m, d, pairs
  Idx ring_rows;  // rows in the vertical window
  Idx ring, acc;  // offsets
  Idx col, col_stride, col_pad;
  Idx prefix, prefix_stride, prefix_pad;
  Idx total;
};

Layout layout_of(const LevelJob& L) {
  Layout s;
  const Idx wp = L.wp;
  s.wrow = round_up(wp + 2 * kPad, 16);
  s.slot = 2 * s.wrow + kChannels * wp;
  s.ring_rows = L.hi - L.lo + 1;
  s.ring = 4 * s.slot;
  s.acc = s.ring + s.ring_rows * kFactors * wp;
  s.col = s.acc + kChannels * wp;
  s.col_pad = round_up(-L.lo, 16);
  s.col_stride = round_up(s.col_pad + wp + L.hi + 1, 16);
  s.prefix = s.col + kChannels * s.col_stride;
  // (Two vectors more: the windowed output stores vector x's windows at x - 2N.)
  s.prefix_pad = round_up(1 - L.lo, 16) + 2 * Native::N;
  s.prefix_stride = round_up(s.prefix_pad + wp + L.hi + Native::N, 16);
  s.total = s.prefix + kChannels * s.prefix_stride;
  return s;
}

std::size_t scratch_floats(const LevelJob& L) {
  return static_cast<std::size_t>(layout_of(L).total);
}

// Columns per step of a row pass: every stage (warp, pairs, window terms and sums, prefix sums,
// solve) runs over one chunk before the next. A chunk is a whole row up to 4096 columns: a
// stage then reads what the one before stored a row's length earlier, long out of the store
// queue (the solve's loads of the prefix sums just stored waited for them with shorter
// chunks), and each stage's set-up is paid once per row. A row's intermediate data stays in the
// second-level cache.
constexpr int kChunk = 4096;

// One iteration of one band: rows [first, end) of its output from its input.
class RowPass {
 public:
  void init(const LevelJob& L, const FlowRows& in, const FlowRows& out, float* conf,
            Idx conf_stride, float* flow, Idx flow_stride, float* scratch) {
    L_ = &L;
    in_ = in;
    out_ = out;
    conf_ = conf;
    conf_stride_ = conf_stride;
    flow_ = flow;
    flow_stride_ = flow_stride;
    s_ = layout_of(L);
    for (int i = 0; i < 4; ++i) {
      cache_row_[i] = -1 << 30;
      m_[i] = scratch + i * s_.slot + kPad;
      d_[i] = scratch + i * s_.slot + s_.wrow + kPad;
      pairs_[i] = scratch + i * s_.slot + 2 * s_.wrow;
    }
    ring_ = scratch + s_.ring;
    acc_ = scratch + s_.acc;
    col_ = scratch + s_.col + s_.col_pad;
    prefix_ = scratch + s_.prefix + s_.prefix_pad;
    win_ = Native::kPermute2 && !L.half ? window_width(L.lo, L.hi, Native::N) : 0;
    // The zeros before column 0 that windows clipped at the left border read (the scratch held
    // another level's layout before).
    for (int c = 0; c < kChannels; ++c) {
      for (Idx x = -s_.prefix_pad; x < 0; ++x)
        prefix_[c * s_.prefix_stride + x] = 0.f;
      for (Idx x = -s_.col_pad; x < 0; ++x)
        col_[c * s_.col_stride + x] = 0.f;
    }
  }

  // Fills the vertical window of output row yb, whose rows are computed by next_row() from then.
  void start(int yb) {
    for (int s = yb + L_->lo; s < yb + L_->hi; ++s)
      pass(s, false, -1);
    first_ = next_ = yb;
  }

  void next_row() {
    const int y = next_++;
    pass(y + L_->hi, y > first_, y, y >= solve_from_);
  }

  // Rows above `row` are computed only for the window sums they carry into the rows below (the
  // next iteration reads none of their flow): they enter the window, and are neither summed
  // horizontally nor solved.
  void solve_from(int row) { solve_from_ = row; }

 private:
  float* ring_row(int s) const {
    const int n = static_cast<int>(s_.ring_rows);
    return ring_ + static_cast<Idx>(((s % n) + n) % n) * kFactors * L_->wp;
  }

  // Columns [x0, x1) of warped row r (and its Horn–Schunck pairs up to the vector end xe).
  void warp_chunk(int r, int slot, int x0, int x1) {
    warp_row(*L_, L_->y0 + r, row_u(in_, r), row_v(in_, r), m_[slot], d_[slot], x0, x1);
  }
  void pairs_chunk(int r, int slot, int x0, int xe) {
    if (L_->derivative == kHornSchunck) {
      hs_pairs(x0, xe, m_[slot], d_[slot], row_u(in_, r), row_v(in_, r), pairs_[slot]);
    }
  }

  // Warped row r whole, and its Horn–Schunck pairs.
  void warp_whole(int r, int slot) {
    const int xe = static_cast<int>(round_up(L_->w, Native::N));
    if (L_->derivative == kHornSchunck) {
      return warp_pairs_row(*L_, L_->y0 + r, row_u(in_, r), row_v(in_, r), m_[slot], d_[slot],
                            pairs_[slot], xe);
    }
    warp_chunk(r, slot, 0, L_->w);
  }

  // Warped row r of the rectangle (clamped to it), whole, from the cache of the last four.
  int warped(int r) {
    r = imin(imax(r, 0), L_->h - 1);
    const int slot = r & 3;
    if (cache_row_[slot] != r) {
      cache_row_[slot] = r;
      warp_whole(r, slot);
    }
    return slot;
  }

  // Derivative-grid row s (zero outside the rectangle) enters the vertical window (the row a
  // window's height above leaves it when `leaving`); then output row y (>= 0) is solved. The
  // newest warped row is made chunk by chunk along with the rest.
  void pass(int s, bool leaving, int y, bool flow = true) {
    const LevelJob& L = *L_;
    constexpr int N = Native::N;
    const int w = L.w;
    const bool solve = y >= 0 && flow;
    const bool half = solve && L.half;
    TermRows t;
    t.w = w;
    t.lo = L.lo;
    int deriv = kOutside;
    int fresh = -1, fresh_slot = 0;  // the row warped chunk by chunk, if any
    if (s >= 0 && s < L.h) {
      deriv = L.derivative;
      const bool hs = deriv == kHornSchunck;
      const int newest = imin(s + 1, L.h - 1);
      if (cache_row_[newest & 3] != newest) {
        fresh = newest;
        fresh_slot = newest & 3;
        cache_row_[fresh_slot] = newest;
      }
      // (Every row read here is cached or is `fresh`, whose slot is filled along the chunks.)
      const int last = fresh >= 0 ? fresh_slot : warped(newest);
      if (hs) {
        t.pa = pairs_[warped(s)];
        t.pb = pairs_[last];
      } else {
        const int centre = warped(s);
        t.m0 = m_[warped(s - 1)];
        t.m1 = m_[centre];
        t.m2 = m_[last];
        t.d1 = d_[centre];
        t.u1 = row_u(in_, s);
        t.v1 = row_v(in_, s);
      }
    }
    // Fresh sums on every stripe row, solved or not: the running sums below depend on them.
    const bool resum = y >= 0 && y % L.stripe == 0;
    const EnterFn enter = pick_enter(deriv, L.inv_s2 > 0.f, leaving, solve && !resum, half, win_);
    const float* top = half ? ring_row(y + L.lo) : nullptr;
    float* ring = ring_row(s);
    const float* resum_rows[64];
    int resum_count = 0;
    if (resum) {
      for (int r = y + L.lo; r <= y + L.hi; ++r)
        resum_rows[resum_count++] = ring_row(r);
    }
    SolveRow q{};
    if (solve) {
      q.w = w;
      q.prefix = prefix_;
      q.pstride = s_.prefix_stride;
      q.col = half ? col_ : nullptr;
      q.col_stride = s_.col_stride;
      q.lo = L.lo;
      q.hi = L.hi;
      q.inv_cx = L.inv_cx;
      q.inv_cy = 1.f / L.cy[y];
      q.lambda = L.lambda;
      q.uo = row_u(in_, y);
      q.vo = row_v(in_, y);
      q.un = row_u(out_, y);
      q.vn = row_v(out_, y);
      q.conf = conf_ ? conf_ + static_cast<Idx>(y) * conf_stride_ : nullptr;
      q.flow = flow_ ? flow_ + static_cast<Idx>(y) * flow_stride_ : nullptr;
      q.windowed = win_ != 0;
    }
    for (int c = 0; c < (win_ != 0 ? kCarryVectors : kChannels); ++c)
      Native::store(carry_ + c * N, Native::set1(0.f));
    // (A row of one chunk is warped with its pairs at once.)
    const bool whole = w <= kChunk;
    if (fresh >= 0) {
      if (whole) {
        warp_whole(fresh, fresh_slot);
      } else {
        warp_chunk(fresh, fresh_slot, 0, kChunk);
      }
    }
    int solved = 0;
    for (int x0 = 0; x0 < w; x0 += kChunk) {
      const int x1 = imin(x0 + kChunk, w);
      const int xe = x1 == w ? static_cast<int>(round_up(w, N)) : x1;
      if (fresh >= 0 && !whole) {
        // The pairs of x1 - 1 read column x1: the warp runs a chunk ahead.
        if (x1 < w) warp_chunk(fresh, fresh_slot, x1, imin(x1 + kChunk, w));
        pairs_chunk(fresh, fresh_slot, x0, xe);
      }
      enter(x0, xe, t, L.inv_s2, ring, acc_, top, col_, s_.col_stride, prefix_, s_.prefix_stride,
            carry_);
      if (resum) {
        resum_row(L.inv_s2 > 0.f, win_, x0, xe, resum_rows, resum_count, acc_, top, ring, col_,
                  s_.col_stride, solve ? prefix_ : nullptr, s_.prefix_stride, carry_, L.lo);
      }
      if (solve && x1 < w && win_ == 0) {
        // A vector's solve reads prefix sums up to hi columns past its end.
        const int end = (x1 - L.hi) / N * N;
        solve_row(q, solved, end);
        if (end > solved) solved = end;
      }
    }
    if (solve) finish_row(q, half, solved);
  }

  // The solve of the row's last columns (all of them with the direct windows).
  void finish_row(const SolveRow& q, bool half, int solved) {
    const LevelJob& L = *L_;
    constexpr int N = Native::N;
    const int w = L.w;
    if (win_ != 0) {
      // (Every chunk is solved here: the windows lag the column sums by two vectors.)
      const int xe = static_cast<int>(round_up(w, N));
      if (win_ == 8) window_flush<8, kChannels>(xe, L.lo, carry_, prefix_, s_.prefix_stride);
      if (win_ == 10) window_flush<10, kChannels>(xe, L.lo, carry_, prefix_, s_.prefix_stride);
      solve_row(q, 0, w);
      if (!flow_) {
        q.un[w] = q.un[w - 1];
        q.vn[w] = q.vn[w - 1];
      }
      return;
    }
    // Windows end at the last column: past it the prefix sums stay at their last value and the
    // half-weight columns are zero, to the end of the last vector, so the padding lanes solve to
    // their old flow (finite, never denormal or NaN).
    const int end = static_cast<int>(round_up(w, N)) + L.hi;
    for (int c = 0; c < kChannels; ++c) {
      float* pc = prefix_ + c * s_.prefix_stride;
      const float last = pc[w - 1];
      for (int x = w; x < end; ++x)
        pc[x] = last;
      if (half) {
        float* cc = col_ + c * s_.col_stride;
        for (int x = w; x < end; ++x)
          cc[x] = 0.f;
      }
    }
    solve_row(q, solved, w);
    if (!flow_) {
      q.un[w] = q.un[w - 1];
      q.vn[w] = q.vn[w - 1];
    }
  }

  const LevelJob* L_ = nullptr;
  FlowRows in_, out_;
  float* conf_ = nullptr;
  Idx conf_stride_ = 0;
  float* flow_ = nullptr;
  Idx flow_stride_ = 0;
  Layout s_{};
  float* m_[4] = {};
  float* d_[4] = {};
  float* pairs_[4] = {};
  int cache_row_[4] = {};
  float* ring_ = nullptr;
  float* acc_ = nullptr;
  float* col_ = nullptr;
  float* prefix_ = nullptr;
  alignas(64) float carry_[kCarryVectors * 16] = {};
  int first_ = 0, next_ = 0;
  int solve_from_ = -(1 << 30);
  int win_ = 0;  // the windows' width where the kernels make their sums directly, else 0
};

constexpr int kMaxIterations = 50;

// The rows each iteration computes for final rows [begin, end): the rows the next one reads,
// from a stripe start.
void iteration_rows(const LevelJob& L, int iterations, int begin, int end, int* first, int* last) {
  first[iterations - 1] = begin;
  last[iterations - 1] = end;
  for (int k = iterations - 2; k >= 0; --k) {
    first[k] = imax(0, floor_to(first[k + 1] - reach_up(L), L.stripe));
    last[k] = imin(L.h, last[k + 1] + reach_down(L));
  }
}

// Work of a band in units of a ninth of a solved row: a row that only enters the window (the
// rows filling it before a pass's first row, and those computed only for their sums) costs about
// 5/9 of a solved one (it skips the horizontal sums and the solve).
int band_rows(const LevelJob& L, int iterations, int begin, int end) {
  constexpr int kSolved = 9, kEntered = 5;
  int first[kMaxIterations], last[kMaxIterations];
  iteration_rows(L, iterations, begin, end, first, last);
  int work = 0;
  for (int k = 0; k < iterations; ++k) {
    const int from = k + 1 < iterations ? imax(first[k], first[k + 1] - reach_up(L)) : first[k];
    work += kSolved * (last[k] - from) + kEntered * (from - first[k] + L.hi - L.lo);
  }
  return work;
}

RowSpan input_rows(const LevelJob& L, int iterations, int begin, int end) {
  int first[kMaxIterations], last[kMaxIterations];
  iteration_rows(L, iterations, begin, end, first, last);
  const int a = imax(0, first[0] - reach_up(L));
  const int b = imin(L.h, last[0] + reach_down(L));
  return {a, b - a};
}

void run_band(const BandJob& job) {
  const LevelJob& L = *job.level;
  const int K = job.iterations;
  int first[kMaxIterations], last[kMaxIterations];
  iteration_rows(L, K, job.begin, job.end, first, last);
  RowPass passes[kMaxIterations];
  for (int k = 0; k < K; ++k) {
    const FlowRows& in = k == 0 ? job.input : job.rings[k - 1];
    const FlowRows& out = k == K - 1 ? job.output : job.rings[k];
    const bool final_pass = k == K - 1;
    passes[k].init(L, in, out, final_pass ? job.confidence : nullptr, job.confidence_stride,
                   final_pass ? job.flow : nullptr, job.flow_stride, job.scratch[k]);
  }
  // Iteration k handles row y at time y + k * lag, kBatchRows times at once (its vertical sums
  // stay in cache over them): the rows it reads of iteration k - 1 (down to y + reach_down) are
  // written by then, and the ring rows it still reads are not yet reused (the rings hold
  // reach_up + lag + kBatchRows rows).
  const int lag = reach_down(L) + 1;
  const int t_end = last[K - 1] + (K - 1) * lag;
  // With an on-demand input, the rows made so far end at filled_to.
  const RowSpan span = input_rows(L, K, job.begin, job.end);
  int filled_to = span.first;
  const int input_end = span.first + span.count;
  // Iteration k's rows from import_from[k] come from import_row; those in [export_from[k],
  // export_to[k]) go to export_row as they are made.
  int import_from[kMaxIterations], export_from[kMaxIterations], export_to[kMaxIterations];
  for (int k = 0; k < K; ++k) {
    import_from[k] = last[k];
    export_from[k] = export_to[k] = 0;
    if (k + 1 < K && job.shared && job.shared[k].count > 0) {
      const RowSpan& s = job.shared[k];
      if (job.import_row) import_from[k] = imax(first[k], imin(last[k], s.first));
      if (job.export_row) {
        export_from[k] = s.first;
        export_to[k] = s.first + s.count;
      }
    }
  }
  for (int t = first[0]; t < t_end; t += kBatchRows) {
    for (int k = 0; k < K; ++k) {
      for (int y = t - k * lag; y < t - k * lag + kBatchRows; ++y) {
        if (y >= import_from[k] && y < last[k]) {
          job.import_row(job.share_context, k, y, row_u(job.rings[k], y), row_v(job.rings[k], y));
          continue;
        }
        if (k == 0 && job.fill_input && y >= first[0] && y < last[0]) {
          // Iteration 0's row y reads input rows up to y + reach_down.
          const int need = imin(input_end, y + reach_down(L) + 1);
          for (; filled_to < need; ++filled_to)
            job.fill_input(job.fill_context, filled_to, row_u(job.input, filled_to),
                           row_v(job.input, filled_to));
        }
        if (y == first[k]) {
          if (k + 1 < K) passes[k].solve_from(first[k + 1] - reach_up(L));
          passes[k].start(y);
        }
        if (y >= first[k] && y < last[k]) {
          passes[k].next_row();
          if (y >= export_from[k] && y < export_to[k]) {
            job.export_row(job.share_context, k, y, row_u(job.rings[k], y), row_v(job.rings[k], y));
          }
        }
      }
    }
    if (job.rows_done) {
      const int done = imin(last[K - 1], t - (K - 1) * lag + kBatchRows);
      if (done > first[K - 1]) job.rows_done(job.done_context, done);
    }
  }
}

}  // namespace

extern const LkKernels ROIFLOW_KERNEL_TABLE;
const LkKernels ROIFLOW_KERNEL_TABLE = {simd::kNativeName,
                                        Native::N,
                                        scratch_floats,
                                        run_band,
                                        input_rows,
                                        band_rows,
                                        upsample_row,
                                        unit_row_u8,
                                        smooth_h,
                                        smooth_v,
                                        Native::kPermute2 ? pyr_down_h : nullptr,
                                        Native::kPermute2 ? pyr_down_v : nullptr};

}  // namespace roiflow::flow::detail
