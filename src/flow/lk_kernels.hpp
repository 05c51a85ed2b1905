// The hand-vectorised kernels of dense LK (internal to roiflow::flow), compiled once per
// instruction set and chosen at run time: lk_kernels() is the table of the best kind this CPU
// runs (AVX-512, AVX2 + FMA, or the build's baseline: SSE2 on x86-64, NEON on arm64, plain C++
// elsewhere). Everything crossing this boundary is a plain struct of numbers and pointers, so
// that no inline function is compiled with two instruction sets.
//
//   const roiflow::flow::detail::LkKernels& k = roiflow::flow::detail::lk_kernels();
//   std::cout << k.name << ": " << k.lanes << " lanes\n";  // 16 with AVX-512, 8 with AVX2, 4 else
#pragma once

#include <cstddef>
#include <cstdint>

namespace roiflow::flow::detail {

// Rows of a flow field (u, v planar): row r at u + ((r - first) & mask) * stride. A plane has
// mask -1; a ring of 2^k rows has mask 2^k - 1. Every row holds w + 1 floats readable past the
// computed width (the last column is replicated into column w) and is padded to LevelJob::wp.
struct FlowRows {
  float* u = nullptr;
  float* v = nullptr;
  std::ptrdiff_t stride = 0;
  int mask = -1;
  int first = 0;
};

// Rows an iteration computes in a row before the next iteration takes its turn.
inline constexpr int kBatchRows = 8;

// One level's problem, as the kernels see it.
struct LevelJob {
  const float* i0 = nullptr;                // frame t's level, whole image
  const float* i1 = nullptr;                // frame t+1's level, whole image
  std::ptrdiff_t i0_step = 0, i1_step = 0;  // in floats
  int cols = 0, rows = 0;                   // level size
  int x0 = 0, y0 = 0, w = 0, h = 0;         // the computed rectangle
  int wp = 0;                               // padded length of every internal row
  int derivative = 0;                       // 0 Horn–Schunck, 1 Scharr, 2 central
  int lo = 0, hi = 0;                       // window offsets (see lk_level.hpp's Window)
  bool half = false;                        // half-weight end taps
  float lambda = 0.f;
  float inv_s2 = 0.f;  // robust weights: 1 / scale^2, 0 = least squares
  // Samples of frame t+1 outside the level carry no brightness term: It = 0 and the gradient of
  // frame t alone (LkParams::mask_outside).
  bool mask_outside = false;
  const float* inv_cx = nullptr;  // wp entries: 1 / horizontal window weight
  const float* cy = nullptr;      // h entries: vertical window weight
  int stripe = 16;                // rows between fresh window sums (a band starts on one)
};

// How far rows of one iteration reach into the previous one's: row y reads rows
// y - reach_up .. y + reach_down.
int reach_up(const LevelJob& level);
int reach_down(const LevelJob& level);

// Rows [first, first + count) of a level (what each use says).
struct RowSpan {
  int first = 0, count = 0;
};

// Rows of iteration k (< iterations - 1) that the bands on both sides of row `split` compute
// alike: from the first row the band starting at `split` solves in iteration k to the last row
// the band ending there computes in it. Empty when split is 0.
RowSpan shared_rows(const LevelJob& level, int iterations, int split, int k);

// The iterations of one level over the final rows [begin, end), each earlier iteration over the
// rows the next one reads (rounded out to a stripe start, so that every row is computed exactly
// as in a single pass over the level: the result never depends on how rows are split).
struct BandJob {
  const LevelJob* level = nullptr;
  int iterations = 1;
  int begin = 0, end = 0;
  FlowRows input;  // what iteration 0 reads
  // Non-null: `input` is a ring (a FlowRows with a mask) that run_band fills row by row just
  // before iteration 0 reads it, calling fill_input(fill_context, r, u, v) to write input row r
  // (w + 1 floats of each component) at u, v. Rows come in increasing order, each once, from the
  // first row input_rows() names; the ring must hold reach_up + reach_down + 1 + kBatchRows rows.
  void (*fill_input)(void* context, int row, float* u, float* v) = nullptr;
  void* fill_context = nullptr;
  FlowRows output;                       // what the last iteration writes
  float* confidence = nullptr;           // last iteration: per row, or null
  std::ptrdiff_t confidence_stride = 0;  // floats, rows indexed from 0 like `output`
  // Non-null: the last iteration writes (u, v) interleaved here (rows `flow_stride` floats apart,
  // not padded) instead of into `output`; `confidence` is then not padded either.
  float* flow = nullptr;
  std::ptrdiff_t flow_stride = 0;
  const FlowRows* rings = nullptr;  // iterations - 1 intermediate results
  // Non-null: called with e each time the last iteration's rows [begin, e) are all written
  // (e increasing), so that another thread may read them while the band goes on.
  void (*rows_done)(void* context, int end) = nullptr;
  void* done_context = nullptr;
  // Non-null: per iteration k < iterations - 1, rows of iteration k this band shares with a
  // band beside it (shared_rows; count 0: none). The band ending at `end` takes its shared rows
  // from import_row (instead of computing them: into u, v, wp floats each); the band starting
  // at `begin` hands each shared row it computes to export_row.
  const RowSpan* shared = nullptr;
  void (*import_row)(void* context, int k, int row, float* u, float* v) = nullptr;
  void (*export_row)(void* context, int k, int row, const float* u, const float* v) = nullptr;
  void* share_context = nullptr;
  float* const* scratch = nullptr;  // per iteration: scratch_floats(level) floats, 64-byte aligned
};

struct LkKernels {
  const char* name;  // "avx512", "avx2", "sse2", "neon" or "scalar"
  int lanes;         // floats per vector
  std::size_t (*scratch_floats)(const LevelJob& level);
  void (*run_band)(const BandJob& job);
  // The rows iteration 0 reads for final rows [begin, end) (all of them: without shared rows).
  RowSpan (*input_rows)(const LevelJob& level, int iterations, int begin, int end);
  // The work of run_band for final rows [begin, end): the rows all iterations compute, each
  // weighted by what it costs (a row solved 9, a row that only enters the window 5).
  int (*band_rows)(const LevelJob& level, int iterations, int begin, int end);
  // A row of the finer level's flow component upsampled x2 from coarse rows a and b (blended by
  // fy in {0, 1/2}), n coarse pixels, starting at coarse pixel k0 (between k0 and k0 + 1 when
  // `between`), `width` long, doubled. temp: upsample_temp_floats(n, lanes) floats.
  void (*upsample_row)(const float* a, const float* b, float fy, int n, int k0, bool between,
                       int width, float* temp, float* out);
  // An 8-bit row as floats in [0, 1].
  void (*unit_row_u8)(const std::uint8_t* src, int w, float* dst);
  // The symmetric filter k[0 .. 2 radius] (radius 1..4) of a row padded by `radius` pixels on
  // each side, and of the 2 radius + 1 rows `rows` at each column.
  void (*smooth_h)(const float* padded, const float* k, int radius, int w, float* out);
  void (*smooth_v)(const float* const* rows, const float* k, int radius, int w, float* out);
  // cv::pyrDown of float images, bit for bit, in two row steps (null without two-vector
  // permutes: OpenCV's own is used there): a row of w >= 8 columns filtered and halved into
  // (w + 1) / 2, and the output row from the five halved rows 2y - 2 .. 2y + 2 (reflected).
  void (*pyr_down_h)(const float* src, int w, float* row);
  void (*pyr_down_v)(const float* const* rows, int dw, float* dst);
};

// Floats of LkKernels::upsample_row's temporary for n coarse pixels.
inline std::size_t upsample_temp_floats(int n) {
  return 2 * (static_cast<std::size_t>(n) + 2 + 64) + 64;
}

// The kernels of the best instruction set this CPU runs. ROIFLOW_SIMD=avx512|avx2|base in the
// environment picks a lower one (for comparisons); an unavailable one is ignored.
const LkKernels& lk_kernels();
// Every kind built into this library that this CPU runs, best first.
int available_lk_kernels(const LkKernels** out, int capacity);
// Tests and benchmarks: use `kernels` from now on (nullptr: back to lk_kernels()'s choice).
void set_lk_kernels_for_testing(const LkKernels* kernels);

}  // namespace roiflow::flow::detail
