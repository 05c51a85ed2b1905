#include "flow/lk_level.hpp"

#include <algorithm>
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <thread>
#include <vector>

namespace roiflow::flow::detail {

namespace {

// Rows between fresh window sums. A band starts on such a row, and each earlier iteration of a
// band on the one before what the next iteration reads: shorter stripes mean less work
// repeated at band edges, longer ones fewer fresh sums.
constexpr int kStripeRows = 16;

// A band shorter than this is not worth a task of its own.
constexpr int kMinBandRows = 32;

}  // namespace

Window make_window(int patch, bool half_pixel_grid) {
  const int h = patch / 2;
  const bool odd = (patch % 2) != 0;
  if (!half_pixel_grid) return odd ? Window{-h, h, false} : Window{-h, h, true};
  return odd ? Window{-h - 1, h, true} : Window{-h, h - 1, false};
}

float window_weight(const Window& win, int i, int n) {
  const int a = std::max(0, i + win.lo), b = std::min(n - 1, i + win.hi);
  float w = static_cast<float>(b - a + 1);
  if (win.half) {
    if (i + win.lo >= 0) w -= 0.5f;
    if (i + win.hi <= n - 1) w -= 0.5f;
  }
  return w;
}

LevelInput LevelInput::constant(float u, float v) {
  LevelInput in;
  in.kind = Kind::Constant;
  in.u = u;
  in.v = v;
  return in;
}

LevelInput LevelInput::planes(const cv::Mat& u, const cv::Mat& v) {
  LevelInput in;
  in.kind = Kind::Planes;
  in.pu = &u;
  in.pv = &v;
  return in;
}

LevelInput LevelInput::coarser(const cv::Mat& u, const cv::Mat& v, cv::Point origin) {
  LevelInput in;
  in.kind = Kind::Coarser;
  in.pu = &u;
  in.pv = &v;
  in.coarse_origin = origin;
  return in;
}

float* AlignedFloats::reserve(std::size_t n) {
  if (n > capacity_) {
    constexpr std::size_t kAlign = 16;                 // floats
    storage_ = std::make_unique<float[]>(n + kAlign);  // zero-initialised
    const auto address = reinterpret_cast<std::uintptr_t>(storage_.get());
    data_ = storage_.get() + (kAlign - (address / sizeof(float)) % kAlign) % kAlign;
    capacity_ = n;
  }
  return data_;
}

std::size_t LevelScratch::bytes() const {
  std::size_t n = (inv_cx.capacity() + cy.capacity()) * sizeof(float);
  for (const std::vector<std::vector<float>>* weights : {&chain_inv_cx, &chain_cy}) {
    for (const std::vector<float>& w : *weights)
      n += w.capacity() * sizeof(float);
  }
  for (const Band& b : bands)
    n += b.input.bytes() + b.rings.bytes() + b.rows.bytes();
  return n + chain_shared.bytes();
}

int padded_width(int w) {
  // Whole vectors of the widest kind past column w (the replicated column), plus one more for
  // the kernels' reads one column to the right.
  return (w + 1 + 15) / 16 * 16 + 16;
}

namespace {

// Row y (of the finer rectangle `dst`) of the coarser flow component `src` (origin `origin` in
// its level), upsampled x2 and doubled (LkKernels::upsample_row). `temp`:
// upsample_temp_floats(src.cols) floats.
void upsample_row(const LkKernels& k, const cv::Mat& src, cv::Point origin, const cv::Rect& dst,
                  int y, float* temp, float* out) {
  const int twice_x = dst.x - 2 * origin.x;
  const int twice_y = dst.y + y - 2 * origin.y;
  const int y0 = std::clamp(twice_y >> 1, 0, src.rows - 1);
  const int y1 = std::min(y0 + 1, src.rows - 1);
  // The coarser level was written a whole level ago and has left the nearer caches: the coarse
  // row two rows on (first read two finer rows later) is asked for now, so that its loads do not
  // wait on memory then. (Inline: GCC drops the calls of a function that only prefetches.)
  if ((twice_y & 1) == 0 && y0 + 2 < src.rows) {
    const char* next = reinterpret_cast<const char*>(src.ptr<float>(y0 + 2));
    const std::size_t bytes = static_cast<std::size_t>(src.cols) * sizeof(float);
    for (std::size_t i = 0; i < bytes; i += 64)
      __builtin_prefetch(next + i);
    __builtin_prefetch(next + bytes - 1);
  }
  k.upsample_row(src.ptr<float>(y0), src.ptr<float>(y1), (twice_y & 1) ? 0.5f : 0.f, src.cols,
                 twice_x >> 1, (twice_x & 1) != 0, dst.width, temp, out);
}

// Rows [first, first + count) of the level's starting flow into u, v (rows `stride` apart, row
// `first` at the start), with column w replicated into column w.
void fill_input(const LkKernels& k, const LevelInput& in, const cv::Rect& comp, int first,
                int count, float* u, float* v, std::ptrdiff_t stride, std::vector<float>& temp) {
  const int w = comp.width;
  if (in.kind == LevelInput::Kind::Coarser) temp.resize(upsample_temp_floats(in.pu->cols));
  for (int i = 0; i < count; ++i) {
    float* ur = u + i * stride;
    float* vr = v + i * stride;
    const int y = first + i;
    switch (in.kind) {
      case LevelInput::Kind::Constant:
        std::fill(ur, ur + w, in.u);
        std::fill(vr, vr + w, in.v);
        break;
      case LevelInput::Kind::Planes:
        std::copy_n(in.pu->ptr<float>(y), w, ur);
        std::copy_n(in.pv->ptr<float>(y), w, vr);
        break;
      case LevelInput::Kind::Coarser:
        upsample_row(k, *in.pu, in.coarse_origin, comp, y, temp.data(), ur);
        upsample_row(k, *in.pv, in.coarse_origin, comp, y, temp.data(), vr);
        break;
    }
    ur[w] = ur[w - 1];
    vr[w] = vr[w - 1];
  }
}

// Final rows of each band, each starting on a stripe row. A band below the first recomputes the
// rows its earlier iterations read above it: two bands are split where their work (rows times
// iterations, by LkKernels::band_rows's weights) is the most even; more bands about equally.
std::vector<int> band_starts(const LkKernels& k, const LevelJob& L, int iterations, int wanted) {
  const int h = L.h;
  const int bands = std::clamp(h / kMinBandRows, 1, std::max(1, wanted));
  std::vector<int> starts{0};
  if (bands == 2) {
    int best = 0, best_work = 0;
    for (int s = kStripeRows; s < h; s += kStripeRows) {
      const int work = std::max(k.band_rows(L, iterations, 0, s), k.band_rows(L, iterations, s, h));
      if (best == 0 || work < best_work) {
        best = s;
        best_work = work;
      }
    }
    if (best > 0) starts.push_back(best);
  } else {
    for (int b = 1; b < bands; ++b) {
      const int s = (h * b / bands) / kStripeRows * kStripeRows;
      if (s > starts.back()) starts.push_back(s);
    }
  }
  starts.push_back(h);
  return starts;
}

// Rows of a ring holding the rows an iteration reads around the row it computes, the lag between
// iterations and a batch of rows (see run_band): a power of two.
int ring_rows(const LevelJob& L) {
  const int need = reach_up(L) + reach_down(L) + 1 + kBatchRows;
  int q = 1;
  while (q <= need)
    q *= 2;
  return q;
}

}  // namespace

namespace {

// The window weights of level problem `p`: 1 / horizontal weight per column (padded_width
// entries), vertical weight per row.
void window_weights(const LevelProblem& p, std::vector<float>& inv_cx, std::vector<float>& cy) {
  // Windows are clipped at the computed rectangle; near the image border that is the
  // image border, elsewhere only pixels outside the wanted region are affected.
  const cv::Rect& c = p.comp;
  inv_cx.assign(padded_width(c.width), 1.f);
  for (int x = 0; x < c.width; ++x)
    inv_cx[x] = 1.f / window_weight(p.win, x, c.width);
  cy.resize(c.height);
  for (int y = 0; y < c.height; ++y)
    cy[y] = window_weight(p.win, y, c.height);
}

// The kernels' view of level problem `p` with window weights inv_cx, cy (window_weights), its
// outputs created as iterate_level says.
LevelJob level_job(const LevelProblem& p, cv::Mat& u, cv::Mat& v, cv::Mat* confidence,
                   cv::Mat* flow, const std::vector<float>& inv_cx, const std::vector<float>& cy) {
  const cv::Rect& c = p.comp;
  const int wp = padded_width(c.width);
  if (flow) {
    flow->create(c.size(), CV_32FC2);
    if (confidence) confidence->create(c.size(), CV_32F);
  } else {
    u.create(c.height, wp, CV_32F);
    v.create(c.height, wp, CV_32F);
    if (confidence) confidence->create(c.height, wp, CV_32F);
  }

  LevelJob L;
  L.i0 = p.i0->ptr<float>();
  L.i1 = p.i1->ptr<float>();
  L.i0_step = static_cast<std::ptrdiff_t>(p.i0->step1());
  L.i1_step = static_cast<std::ptrdiff_t>(p.i1->step1());
  L.cols = p.i0->cols;
  L.rows = p.i0->rows;
  L.x0 = c.x;
  L.y0 = c.y;
  L.w = c.width;
  L.h = c.height;
  L.wp = wp;
  L.derivative = static_cast<int>(p.derivative);
  L.lo = p.win.lo;
  L.hi = p.win.hi;
  L.half = p.win.half;
  L.lambda = p.lambda;
  L.inv_s2 = p.robust_inv_scale2;
  L.mask_outside = p.mask_outside;
  L.inv_cx = inv_cx.data();
  L.cy = cy.data();
  L.stripe = kStripeRows;
  return L;
}

// Floats of a band's three buffers at level L.
struct BandSizes {
  std::size_t input = 0, rings = 0, rows = 0;
};

BandSizes band_sizes(const LkKernels& k, const LevelJob& L, int iterations) {
  const std::size_t plane = static_cast<std::size_t>(ring_rows(L)) * L.wp;
  return {2 * plane, 2 * plane * static_cast<std::size_t>(std::max(0, iterations - 1)),
          k.scratch_floats(L) * static_cast<std::size_t>(iterations)};
}

struct BandBuffers {
  float* input;
  float* rings;
  float* rows;
};

BandBuffers reserve_band(LevelScratch::Band& s, const BandSizes& n) {
  return {s.input.reserve(n.input), s.rings.reserve(n.rings), s.rows.reserve(n.rows)};
}

// Where a band's last iteration puts its rows.
struct LevelOutputs {
  cv::Mat* u;
  cv::Mat* v;
  cv::Mat* confidence;
  cv::Mat* flow;
};

// Another thread's progress on the coarser level a band's input is upsampled from: its rows from
// `from` on are ready below *done (see iterate_levels_chained).
struct CoarserProgress {
  const std::atomic<int>* done = nullptr;
  int from = 0;
};

// The last row of the coarser flow that row `row` of the level's input reads (upsample_row's
// rows y0, y1).
int coarser_last_row(const LevelInput& in, const cv::Rect& comp, int row) {
  const int twice_y = comp.y + row - 2 * in.coarse_origin.y;
  const int y0 = std::clamp(twice_y >> 1, 0, in.pu->rows - 1);
  return std::min(y0 + 1, in.pu->rows - 1);
}

// What BandJob::fill_input needs to make one row of the level's starting flow.
struct InputSource {
  const LkKernels* kernels;
  const LevelInput* input;
  cv::Rect comp;
  std::vector<float> temp;
  CoarserProgress wait;
};

void fill_input_row(void* context, int row, float* u, float* v) {
  InputSource& s = *static_cast<InputSource*>(context);
  if (s.wait.done) {
    const int need = coarser_last_row(*s.input, s.comp, row);
    if (need >= s.wait.from) {
      while (s.wait.done->load(std::memory_order_acquire) <= need)
        std::this_thread::yield();
    }
  }
  fill_input(*s.kernels, *s.input, s.comp, row, 1, u, v, 0, s.temp);
}

void publish_rows(void* context, int end) {
  static_cast<std::atomic<int>*>(context)->store(end, std::memory_order_release);
}

// The rows of each iteration but the last that the chains share at level L split at `split`
// (shared_rows); none for an iteration whose share is longer than kMaxSharedRows (many
// iterations: the lower band's cone grows with each).
constexpr int kMaxSharedRows = 64;

std::vector<RowSpan> chain_shares(const LevelJob& L, int iterations, int split) {
  std::vector<RowSpan> spans(std::max(0, iterations - 1));
  for (int k = 0; k + 1 < iterations; ++k) {
    const RowSpan r = shared_rows(L, iterations, split, k);
    if (r.count <= kMaxSharedRows) spans[k] = r;
  }
  return spans;
}

// Where the lower chain hands the shared rows of one level to the upper chain: rows of
// iteration k at base + (offset[k] + row - spans[k].first) * 2 * wp (u then v, wp floats each);
// made[k]: the rows of iteration k made so far end there.
struct SharedRows {
  std::vector<RowSpan> spans;
  std::vector<std::size_t> offset;
  float* base = nullptr;
  std::ptrdiff_t wp = 0;
  std::atomic<int>* made = nullptr;
};

void export_shared(void* context, int k, int row, const float* u, const float* v) {
  SharedRows& s = *static_cast<SharedRows*>(context);
  float* d = s.base + (s.offset[k] + static_cast<std::size_t>(row - s.spans[k].first)) * 2 * s.wp;
  std::copy_n(u, s.wp, d);
  std::copy_n(v, s.wp, d + s.wp);
  s.made[k].store(row + 1, std::memory_order_release);
}

void import_shared(void* context, int k, int row, float* u, float* v) {
  SharedRows& s = *static_cast<SharedRows*>(context);
  while (s.made[k].load(std::memory_order_acquire) <= row)
    std::this_thread::yield();
  const float* d =
      s.base + (s.offset[k] + static_cast<std::size_t>(row - s.spans[k].first)) * 2 * s.wp;
  std::copy_n(d, s.wp, u);
  std::copy_n(d + s.wp, s.wp, v);
}

// The iterations of level L over its final rows [begin, end) with band buffers `bp`.
void run_level_band(const LkKernels& k, const LevelJob& L, const LevelInput& input,
                    const cv::Rect& comp, int iterations, int begin, int end, const BandBuffers& bp,
                    const LevelOutputs& out, CoarserProgress wait = {},
                    std::atomic<int>* done = nullptr, SharedRows* shared = nullptr,
                    bool import = false) {
  const int wp = L.wp;
  const int q = ring_rows(L);
  const std::size_t rows_floats = k.scratch_floats(L);
  const std::size_t plane = static_cast<std::size_t>(q) * wp;
  InputSource source{&k, &input, comp, {}, wait};
  std::vector<FlowRows> rings(std::max(0, iterations - 1));
  std::vector<float*> rows(iterations);
  for (int i = 0; i + 1 < iterations; ++i) {
    float* r = bp.rings + 2 * plane * i;
    rings[i] = FlowRows{r, r + plane, wp, q - 1, 0};
  }
  for (int i = 0; i < iterations; ++i)
    rows[i] = bp.rows + rows_floats * i;
  cv::Mat* flow = out.flow;
  cv::Mat* confidence = out.confidence;
  BandJob job;
  job.level = &L;
  job.iterations = iterations;
  job.begin = begin;
  job.end = end;
  job.input = FlowRows{bp.input, bp.input + plane, wp, q - 1, 0};
  job.fill_input = fill_input_row;
  job.fill_context = &source;
  job.output = flow ? FlowRows{} : FlowRows{out.u->ptr<float>(), out.v->ptr<float>(), wp, -1, 0};
  job.confidence = confidence ? confidence->ptr<float>() : nullptr;
  job.confidence_stride =
      confidence ? static_cast<std::ptrdiff_t>(confidence->step1()) : std::ptrdiff_t{0};
  job.flow = flow ? flow->ptr<float>() : nullptr;
  job.flow_stride = flow ? static_cast<std::ptrdiff_t>(flow->step1()) : std::ptrdiff_t{0};
  job.rings = rings.data();
  job.scratch = rows.data();
  if (done) {
    job.rows_done = publish_rows;
    job.done_context = done;
  }
  // The upper band of a split level takes the shared rows, the lower one hands them over.
  if (shared) {
    job.shared = shared->spans.data();
    if (import) {
      job.import_row = import_shared;
    } else {
      job.export_row = export_shared;
    }
    job.share_context = shared;
  }
  k.run_band(job);
}

}  // namespace

void iterate_level(const LevelProblem& p, const LevelInput& input, cv::Mat& u, cv::Mat& v,
                   cv::Mat* confidence, int iterations, const Executor& executor,
                   LevelScratch& scratch, cv::Mat* flow) {
  window_weights(p, scratch.inv_cx, scratch.cy);
  const LevelJob L = level_job(p, u, v, confidence, flow, scratch.inv_cx, scratch.cy);
  const LkKernels& k = lk_kernels();
  const std::vector<int> starts = band_starts(k, L, iterations, executor.concurrency());
  const int bands = static_cast<int>(starts.size()) - 1;
  if (static_cast<int>(scratch.bands.size()) < bands) scratch.bands.resize(bands);
  // Each band owns its buffers (sized before the bands start: nothing is allocated in them).
  const BandSizes sizes = band_sizes(k, L, iterations);
  std::vector<BandBuffers> plans(bands);
  for (int b = 0; b < bands; ++b)
    plans[b] = reserve_band(scratch.bands[b], sizes);
  const LevelOutputs out{&u, &v, confidence, flow};
  auto run = [&](int b) {
    run_level_band(k, L, input, p.comp, iterations, starts[b], starts[b + 1], plans[b], out);
  };
  if (bands == 1) {
    run(0);
  } else {
    executor.for_range(0, bands, 1, [&](int b0, int b1) {
      for (int b = b0; b < b1; ++b)
        run(b);
    });
  }
}

namespace {

// Two chains of bands (see iterate_levels_chained): at level j the lower chain takes the final
// rows [s[j], h), the upper one [0, s[j]). Each split is on a stripe row, the finest one inside
// the level, and the lower chain's input rows at level j lie at or below s[j - 1] on level
// j - 1, so that it reads only rows it wrote itself. Of those splits the one whose two chains'
// work (LkKernels::band_rows times the width) is the most even; empty when there is none.
std::vector<int> chain_splits(const LkKernels& k, const std::vector<LevelJob>& jobs,
                              const std::vector<ChainLevel>& levels) {
  const int n = static_cast<int>(jobs.size());
  // Per level and stripe split i (row i * kStripeRows): each chain's work; the lowest row of
  // level j - 1 the lower chain reads; the highest one the upper chain reads, and how far into
  // its band (a fraction of its work) it reads the first row below the split of level j - 1
  // would be needed, computed in the search.
  auto work = [&](int j, int begin, int end) {
    return begin < end
               ? static_cast<double>(k.band_rows(jobs[j], levels[j].iterations, begin, end)) *
                     jobs[j].w
               : 0.0;
  };
  auto coarse_row = [&](int j, int row) {  // the first row of level j - 1 that row of j reads
    const cv::Rect& c = levels[j].p.comp;
    const cv::Rect& cc = levels[j - 1].p.comp;
    return std::clamp((c.y + row - 2 * cc.y) >> 1, 0, cc.height - 1);
  };
  std::vector<int> count(n);
  for (int j = 0; j < n; ++j)
    count[j] = (jobs[j].h + kStripeRows - 1) / kStripeRows;
  std::vector<int> best, pick(n);
  double best_time = 0;
  // The two chains as two threads would run them (model time: work units), the upper chain
  // waiting where it reads a row of the lower one that is not made yet: the lower chain makes
  // the rows of a level in order, the upper one reads its input rows in order.
  auto timeline = [&]() {
    double lower = 0, upper = 0;  // when each chain starts the next level
    double lower_start_prev = 0;
    for (int j = 0; j < n; ++j) {
      const int s = pick[j] * kStripeRows;
      const int K = levels[j].iterations;
      double up = work(j, 0, s);
      const double low = work(j, s, jobs[j].h);
      // The upper chain takes the shared rows (solved rows: 9 units each) from the lower one,
      // which makes them at the start of its band.
      const std::vector<RowSpan> shares =
          s > 0 ? chain_shares(jobs[j], K, s) : std::vector<RowSpan>{};
      int shared_first = s, shared_end = 0;
      for (const RowSpan& r : shares) {
        up -= 9.0 * r.count * jobs[j].w;
        if (r.count > 0) {
          shared_first = std::min(shared_first, r.first);
          shared_end = std::max(shared_end, r.first + r.count);
        }
      }
      up = std::max(0.0, up);
      if (s > 0) {
        const RowSpan in = k.input_rows(jobs[j], K, 0, s);
        int last_in = in.first + in.count - 1;
        if (!shares.empty() && shares[0].count > 0)
          last_in = std::min(last_in, shares[0].first - 1 + reach_down(jobs[j]));
        if (j > 0) {
          const int sp = pick[j - 1] * kStripeRows;
          const int need = std::min(coarse_row(j, last_in) + 1, levels[j - 1].p.comp.height - 1);
          if (need >= sp) {
            // The first input row that reads below the coarser split.
            int r = in.first;
            while (r < last_in && coarse_row(j, r) + 1 < sp)
              ++r;
            const double at = upper + up * (r - in.first) / std::max(1, in.count);
            const double ready = lower_start_prev + work(j - 1, sp, need + 1);
            upper += std::max(0.0, ready - at);
          }
        }
        if (shared_end > 0) {
          const double at = upper + up * shared_first / s;
          const double ready = lower + work(j, s, std::min(jobs[j].h, shared_end + 1));
          upper += std::max(0.0, ready - at);
        }
      }
      lower_start_prev = lower;
      lower += low;
      upper += up;
    }
    return std::max(lower, upper);
  };
  auto search = [&](auto&& self, int j) -> void {
    int bound = jobs[j].h - 1;
    if (j < n - 1) {
      const int s = pick[j + 1] * kStripeRows;
      bound = coarse_row(
          j + 1, k.input_rows(jobs[j + 1], levels[j + 1].iterations, s, jobs[j + 1].h).first);
    }
    for (int i = j == n - 1 ? 1 : 0; i < count[j] && i * kStripeRows <= bound; ++i) {
      pick[j] = i;
      if (j > 0) {
        self(self, j - 1);
        continue;
      }
      const double t = timeline();
      if (best.empty() || t < best_time) {
        best_time = t;
        best = pick;
      }
    }
  };
  search(search, n - 1);
  for (int& i : best)
    i *= kStripeRows;
  return best;
}

}  // namespace

bool iterate_levels_chained(const std::vector<ChainLevel>& levels, const LevelInput& input,
                            const Executor& executor, LevelScratch& scratch) {
  const int n = static_cast<int>(levels.size());
  if (n < 2) return false;
  const LkKernels& k = lk_kernels();
  // The geometry the weights and splits were made for.
  std::vector<int> key;
  for (const ChainLevel& l : levels) {
    const cv::Rect& c = l.p.comp;
    key.insert(key.end(), {c.x, c.y, c.width, c.height, l.p.win.lo, l.p.win.hi, l.p.win.half,
                           static_cast<int>(l.p.derivative), l.iterations, k.lanes});
  }
  const bool same = key == scratch.chain_key;
  if (!same) {
    scratch.chain_inv_cx.resize(n);
    scratch.chain_cy.resize(n);
    for (int j = 0; j < n; ++j)
      window_weights(levels[j].p, scratch.chain_inv_cx[j], scratch.chain_cy[j]);
  }
  std::vector<LevelJob> jobs(n);
  for (int j = 0; j < n; ++j) {
    const ChainLevel& l = levels[j];
    jobs[j] = level_job(l.p, *l.u, *l.v, l.confidence, l.flow, scratch.chain_inv_cx[j],
                        scratch.chain_cy[j]);
  }
  if (!same) {
    scratch.chain_splits = chain_splits(k, jobs, levels);
    scratch.chain_key = key;
  }
  const std::vector<int>& split = scratch.chain_splits;
  if (split.empty()) return false;

  // Every level's input: the given one, then the coarser level's planes.
  std::vector<cv::Mat> coarse_u(n), coarse_v(n);
  std::vector<LevelInput> inputs(n);
  inputs[0] = input;
  for (int j = 1; j < n; ++j) {
    const cv::Rect& cc = levels[j - 1].p.comp;
    coarse_u[j] = (*levels[j - 1].u)(cv::Rect(cv::Point(), cc.size()));
    coarse_v[j] = (*levels[j - 1].v)(cv::Rect(cv::Point(), cc.size()));
    inputs[j] = LevelInput::coarser(coarse_u[j], coarse_v[j], cc.tl());
  }
  // Each chain's buffers, sized for its largest level before the chains start.
  if (scratch.bands.size() < 2) scratch.bands.resize(2);
  BandSizes most;
  for (int j = 0; j < n; ++j) {
    const BandSizes b = band_sizes(k, jobs[j], levels[j].iterations);
    most.input = std::max(most.input, b.input);
    most.rings = std::max(most.rings, b.rings);
    most.rows = std::max(most.rows, b.rows);
  }
  const BandBuffers buffers[2] = {reserve_band(scratch.bands[0], most),
                                  reserve_band(scratch.bands[1], most)};
  // The rows the chains share at each level, with room for them and their progress.
  std::vector<SharedRows> shared(n);
  int progress_count = 0;
  std::vector<std::size_t> level_start(n + 1, 0);
  for (int j = 0; j < n; ++j) {
    SharedRows& sh = shared[j];
    sh.spans = chain_shares(jobs[j], levels[j].iterations, split[j]);
    sh.wp = jobs[j].wp;
    std::size_t rows = 0;
    for (const RowSpan& r : sh.spans) {
      sh.offset.push_back(rows);
      rows += static_cast<std::size_t>(r.count);
    }
    progress_count += static_cast<int>(sh.spans.size());
    level_start[j + 1] = level_start[j] + rows * 2 * static_cast<std::size_t>(sh.wp);
  }
  const std::unique_ptr<std::atomic<int>[]> made(new std::atomic<int>[std::max(1, progress_count)]);
  float* const shared_base = scratch.chain_shared.reserve(std::max<std::size_t>(1, level_start[n]));
  for (int j = 0, p = 0; j < n; ++j) {
    SharedRows& sh = shared[j];
    sh.base = shared_base + level_start[j];
    sh.made = made.get() + p;
    for (const RowSpan& r : sh.spans)
      made[p++].store(r.first, std::memory_order_relaxed);
  }
  // done[j]: the lower chain's last iteration has written level j's rows [split[j], done[j]).
  const std::unique_ptr<std::atomic<int>[]> done(new std::atomic<int>[n]);
  for (int j = 0; j < n; ++j)
    done[j].store(split[j], std::memory_order_relaxed);
  std::atomic<int> claimed{0};
  auto chain = [&](int c) {
    for (int j = 0; j < n; ++j) {
      const ChainLevel& l = levels[j];
      const int begin = c == 0 ? split[j] : 0;
      const int end = c == 0 ? jobs[j].h : split[j];
      if (begin >= end) continue;
      const LevelOutputs out{l.u, l.v, l.confidence, l.flow};
      const CoarserProgress wait =
          c == 1 && j > 0 ? CoarserProgress{&done[j - 1], split[j - 1]} : CoarserProgress{};
      run_level_band(k, jobs[j], inputs[j], l.p.comp, l.iterations, begin, end, buffers[c], out,
                     wait, c == 0 ? &done[j] : nullptr, split[j] > 0 ? &shared[j] : nullptr,
                     c == 1);
    }
  };
  // The lower chain never waits; the upper one waits only on rows of the lower one, which the
  // first chunk to start claims: even one thread running both chunks in turn cannot deadlock.
  executor.for_range(0, 2, 1, [&](int b0, int b1) {
    for (int b = b0; b < b1; ++b)
      chain(claimed.fetch_add(1));
  });
  return true;
}

void upsample_flow(const cv::Mat& src, cv::Point src_origin, const cv::Rect& dst, cv::Mat& out,
                   const Executor* executor) {
  out.create(dst.size(), CV_32F);
  const LkKernels& k = lk_kernels();
  auto rows = [&](int y0, int y1) {
    std::vector<float> temp(upsample_temp_floats(src.cols));
    for (int y = y0; y < y1; ++y)
      upsample_row(k, src, src_origin, dst, y, temp.data(), out.ptr<float>(y));
  };
  if (executor && executor->concurrency() > 1) {
    executor->for_range(0, dst.height, kMinBandRows, rows);
  } else {
    rows(0, dst.height);
  }
}

void upsample_flow_pair(const cv::Mat& src_u, const cv::Mat& src_v, cv::Point src_origin,
                        const cv::Rect& dst, cv::Mat& flow, const Executor* executor) {
  flow.create(dst.size(), CV_32FC2);
  const LkKernels& k = lk_kernels();
  auto rows = [&](int y0, int y1) {
    std::vector<float> temp(upsample_temp_floats(std::max(src_u.cols, src_v.cols)));
    std::vector<float> u(static_cast<std::size_t>(dst.width)), v(u.size());
    for (int y = y0; y < y1; ++y) {
      upsample_row(k, src_u, src_origin, dst, y, temp.data(), u.data());
      upsample_row(k, src_v, src_origin, dst, y, temp.data(), v.data());
      float* out = flow.ptr<float>(y);
      for (int x = 0; x < dst.width; ++x) {
        out[2 * x] = u[x];
        out[2 * x + 1] = v[x];
      }
    }
  };
  if (executor && executor->concurrency() > 1) {
    executor->for_range(0, dst.height, kMinBandRows, rows);
  } else {
    rows(0, dst.height);
  }
}

}  // namespace roiflow::flow::detail
