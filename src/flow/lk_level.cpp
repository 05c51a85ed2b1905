#include "flow/lk_level.hpp"

#include <algorithm>
#include <cstddef>
#include <cstdint>
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
  for (const Band& b : bands)
    n += b.input.bytes() + b.rings.bytes() + b.rows.bytes();
  return n;
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

// What BandJob::fill_input needs to make one row of the level's starting flow.
struct InputSource {
  const LkKernels* kernels;
  const LevelInput* input;
  cv::Rect comp;
  std::vector<float> temp;
};

void fill_input_row(void* context, int row, float* u, float* v) {
  InputSource& s = *static_cast<InputSource*>(context);
  fill_input(*s.kernels, *s.input, s.comp, row, 1, u, v, 0, s.temp);
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

void iterate_level(const LevelProblem& p, const LevelInput& input, cv::Mat& u, cv::Mat& v,
                   cv::Mat* confidence, int iterations, const Executor& executor,
                   LevelScratch& scratch, cv::Mat* flow) {
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

  // Windows are clipped at the computed rectangle; near the image border that is the
  // image border, elsewhere only pixels outside the wanted region are affected.
  scratch.inv_cx.assign(wp, 1.f);
  for (int x = 0; x < c.width; ++x)
    scratch.inv_cx[x] = 1.f / window_weight(p.win, x, c.width);
  scratch.cy.resize(c.height);
  for (int y = 0; y < c.height; ++y)
    scratch.cy[y] = window_weight(p.win, y, c.height);

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
  L.inv_cx = scratch.inv_cx.data();
  L.cy = scratch.cy.data();
  L.stripe = kStripeRows;

  const LkKernels& k = lk_kernels();
  const std::vector<int> starts = band_starts(k, L, iterations, executor.concurrency());
  const int bands = static_cast<int>(starts.size()) - 1;
  if (static_cast<int>(scratch.bands.size()) < bands) scratch.bands.resize(bands);
  const int q = ring_rows(L);
  const std::size_t rows_floats = k.scratch_floats(L);
  const std::size_t plane = static_cast<std::size_t>(q) * wp;
  // Each band owns its buffers (sized before the bands start: nothing is allocated in them).
  struct BandPlan {
    float* input;
    float* rings;
    float* rows;
  };
  std::vector<BandPlan> plans(bands);
  for (int b = 0; b < bands; ++b) {
    LevelScratch::Band& s = scratch.bands[b];
    BandPlan& bp = plans[b];
    // Iteration 0's input rows are made as it reaches them, into a ring like the iterations'.
    bp.input = s.input.reserve(2 * plane);
    bp.rings = s.rings.reserve(2 * plane * std::max(0, iterations - 1));
    bp.rows = s.rows.reserve(rows_floats * iterations);
  }
  auto run = [&](int b) {
    const BandPlan& bp = plans[b];
    InputSource source{&k, &input, c, {}};
    std::vector<FlowRows> rings(std::max(0, iterations - 1));
    std::vector<float*> rows(iterations);
    for (int i = 0; i + 1 < iterations; ++i) {
      float* r = bp.rings + 2 * plane * i;
      rings[i] = FlowRows{r, r + plane, wp, q - 1, 0};
    }
    for (int i = 0; i < iterations; ++i)
      rows[i] = bp.rows + rows_floats * i;
    BandJob job;
    job.level = &L;
    job.iterations = iterations;
    job.begin = starts[b];
    job.end = starts[b + 1];
    job.input = FlowRows{bp.input, bp.input + plane, wp, q - 1, 0};
    job.fill_input = fill_input_row;
    job.fill_context = &source;
    job.output = flow ? FlowRows{} : FlowRows{u.ptr<float>(), v.ptr<float>(), wp, -1, 0};
    job.confidence = confidence ? confidence->ptr<float>() : nullptr;
    job.confidence_stride =
        confidence ? static_cast<std::ptrdiff_t>(confidence->step1()) : std::ptrdiff_t{0};
    job.flow = flow ? flow->ptr<float>() : nullptr;
    job.flow_stride = flow ? static_cast<std::ptrdiff_t>(flow->step1()) : std::ptrdiff_t{0};
    job.rings = rings.data();
    job.scratch = rows.data();
    k.run_band(job);
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
