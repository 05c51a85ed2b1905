// A thin SIMD layer for the flow kernels (internal to roiflow::flow): float and int32 vectors of
// the widest kind the translation unit is compiled for (AVX-512, AVX2 + FMA, SSE2, NEON), and a
// one-lane scalar kind with the same operations, so that a kernel written once as a template runs
// on whole vectors and on the row tails with the same arithmetic per lane. Every name lives in an
// anonymous namespace: the kernel file is compiled once per instruction set (lk_kernels_*.cpp) and
// no inline function may be shared between those copies.
//
//   using V = roiflow::flow::simd::Native;  // or simd::Scalar for tails
//   float in[16] = {1.f}, out[16];
//   V::store(out, V::madd(V::load(in), V::set1(2.f), V::load(in)));  // in * 2 + in, fused
//                                                                     // where the ISA has FMA
//
// OpenCV's universal intrinsics would serve the 128-bit kinds, but an application built outside
// OpenCV gets only their SSE2/NEON width from the installed headers (cv_cpu_dispatch.h's
// compatibility branch), so the wide kinds need their own intrinsics either way.
#pragma once

#include <cmath>
#include <cstdint>
#include <cstring>

#if defined(__AVX512F__) && defined(__AVX512BW__) && defined(__AVX512VL__) && defined(__AVX512DQ__)
#define ROIFLOW_SIMD_AVX512 1
#include <immintrin.h>
#elif defined(__AVX2__) && defined(__FMA__)
#define ROIFLOW_SIMD_AVX2 1
#include <immintrin.h>
#elif defined(__SSE2__)
#define ROIFLOW_SIMD_SSE2 1
#include <emmintrin.h>
#elif defined(__ARM_NEON) && defined(__aarch64__)
#define ROIFLOW_SIMD_NEON 1
#include <arm_neon.h>
#endif

// The kernels' building blocks must inline: a vector passed to an out-of-line call goes through
// memory.
#if defined(__GNUC__)
#define ROIFLOW_INLINE inline __attribute__((always_inline))
#else
#define ROIFLOW_INLINE inline
#endif

#if defined(__FMA__) || defined(__aarch64__)
#define ROIFLOW_SIMD_FMA 1
#endif

namespace roiflow::flow::simd {
namespace {

#if defined(ROIFLOW_SIMD_AVX512)
constexpr const char* kNativeName = "avx512";
#elif defined(ROIFLOW_SIMD_AVX2)
constexpr const char* kNativeName = "avx2";
#elif defined(ROIFLOW_SIMD_SSE2)
constexpr const char* kNativeName = "sse2";
#elif defined(ROIFLOW_SIMD_NEON)
constexpr const char* kNativeName = "neon";
#else
constexpr const char* kNativeName = "scalar";
#endif

// One lane: the tails of rows, and the whole row where the target has no vectors.
struct Scalar {
  using F = float;
  using I = std::int32_t;
  using M = bool;
  static constexpr int N = 1;
  // Whether permute2, below, any and either exist (two-vector permutes: AVX-512 only).
  static constexpr bool kPermute2 = false;
  ROIFLOW_INLINE static F load(const float* p) { return *p; }
  ROIFLOW_INLINE static void store(float* p, F a) { *p = a; }
  ROIFLOW_INLINE static F set1(float a) { return a; }
  ROIFLOW_INLINE static F iota() { return 0.f; }
  ROIFLOW_INLINE static F add(F a, F b) { return a + b; }
  ROIFLOW_INLINE static F sub(F a, F b) { return a - b; }
  ROIFLOW_INLINE static F mul(F a, F b) { return a * b; }
  ROIFLOW_INLINE static F div(F a, F b) { return a / b; }
#ifdef ROIFLOW_SIMD_FMA
  ROIFLOW_INLINE static F madd(F a, F b, F c) {
    return __builtin_fmaf(a, b, c);
  }
  ROIFLOW_INLINE static F nmadd(F a, F b, F c) {
    return __builtin_fmaf(-a, b, c);
  }
#else
  ROIFLOW_INLINE static F madd(F a, F b, F c) {
    return a * b + c;
  }
  ROIFLOW_INLINE static F nmadd(F a, F b, F c) {
    return c - a * b;
  }
#endif
  ROIFLOW_INLINE static F min(F a, F b) {
    return b < a ? b : a;
  }
  ROIFLOW_INLINE static F max(F a, F b) {
    return a < b ? b : a;
  }
  ROIFLOW_INLINE static F sqrt(F a) {
    return __builtin_sqrtf(a);
  }
  ROIFLOW_INLINE static F recip(F a) {
    return 1.f / a;
  }
  ROIFLOW_INLINE static I seti(std::int32_t a) {
    return a;
  }
  ROIFLOW_INLINE static I iotai() {
    return 0;
  }
  ROIFLOW_INLINE static I addi(I a, I b) {
    return a + b;
  }
  ROIFLOW_INLINE static I subi(I a, I b) {
    return a - b;
  }
  ROIFLOW_INLINE static I muli(I a, I b) {
    return a * b;
  }
  ROIFLOW_INLINE static I mini(I a, I b) {
    return b < a ? b : a;
  }
  ROIFLOW_INLINE static I cvtt(F a) {
    return static_cast<I>(a);
  }
  ROIFLOW_INLINE static F cvt(I a) {
    return static_cast<F>(a);
  }
  ROIFLOW_INLINE static M eqi(I a, I b) {
    return a == b;
  }
  ROIFLOW_INLINE static bool all(M m) {
    return m;
  }
  ROIFLOW_INLINE static F select(M m, F a, F b) {
    return m ? a : b;
  }
  ROIFLOW_INLINE static std::int32_t first(I a) {
    return a;
  }
  ROIFLOW_INLINE static F gather(const float* base, I idx) {
    return base[idx];
  }
  ROIFLOW_INLINE static F prefix(F a) {
    return a;
  }
  ROIFLOW_INLINE static F last(F a) {
    return a;
  }
  // The lanes one column to the right: a's lanes 1.., then b's lane 0 (b: the next vector).
  ROIFLOW_INLINE static F next1(F, F b) {
    return b;
  }
  ROIFLOW_INLINE static F load_u8(const std::uint8_t* p) {
    return static_cast<F>(*p);
  }
  // Interleaves a and b: lo = (a0, b0, a1, b1, ...) over the first half of the lanes, hi the rest.
  ROIFLOW_INLINE static void zip(F a, F b, F& lo, F& hi) {
    lo = a;
    hi = b;
  }
};

#if defined(ROIFLOW_SIMD_AVX512)
struct Native {
  using F = __m512;
  using I = __m512i;
  using M = __mmask16;
  static constexpr int N = 16;
  // Whether permute2, below, any and either exist (two-vector permutes: AVX-512 only).
  static constexpr bool kPermute2 = true;
  ROIFLOW_INLINE static F load(const float* p) { return _mm512_loadu_ps(p); }
  ROIFLOW_INLINE static void store(float* p, F a) { _mm512_storeu_ps(p, a); }
  ROIFLOW_INLINE static F set1(float a) { return _mm512_set1_ps(a); }
  ROIFLOW_INLINE static F iota() {
    return _mm512_setr_ps(0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15);
  }
  ROIFLOW_INLINE static F add(F a, F b) { return _mm512_add_ps(a, b); }
  ROIFLOW_INLINE static F sub(F a, F b) { return _mm512_sub_ps(a, b); }
  ROIFLOW_INLINE static F mul(F a, F b) { return _mm512_mul_ps(a, b); }
  ROIFLOW_INLINE static F div(F a, F b) { return _mm512_div_ps(a, b); }
  ROIFLOW_INLINE static F madd(F a, F b, F c) { return _mm512_fmadd_ps(a, b, c); }
  ROIFLOW_INLINE static F nmadd(F a, F b, F c) { return _mm512_fnmadd_ps(a, b, c); }
  ROIFLOW_INLINE static F min(F a, F b) { return _mm512_min_ps(a, b); }
  ROIFLOW_INLINE static F max(F a, F b) { return _mm512_max_ps(a, b); }
  ROIFLOW_INLINE static F sqrt(F a) { return _mm512_sqrt_ps(a); }
  // 1 / a: the 14-bit estimate and one Newton step (a division costs ten times as much).
  ROIFLOW_INLINE static F recip(F a) {
    const F r = _mm512_rcp14_ps(a);
    return _mm512_fmadd_ps(r, _mm512_fnmadd_ps(a, r, _mm512_set1_ps(1.f)), r);
  }
  ROIFLOW_INLINE static I seti(std::int32_t a) { return _mm512_set1_epi32(a); }
  ROIFLOW_INLINE static I iotai() {
    return _mm512_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15);
  }
  ROIFLOW_INLINE static I addi(I a, I b) { return _mm512_add_epi32(a, b); }
  ROIFLOW_INLINE static I subi(I a, I b) { return _mm512_sub_epi32(a, b); }
  ROIFLOW_INLINE static I muli(I a, I b) { return _mm512_mullo_epi32(a, b); }
  ROIFLOW_INLINE static I mini(I a, I b) { return _mm512_min_epi32(a, b); }
  ROIFLOW_INLINE static I cvtt(F a) { return _mm512_cvttps_epi32(a); }
  ROIFLOW_INLINE static F cvt(I a) { return _mm512_cvtepi32_ps(a); }
  ROIFLOW_INLINE static M eqi(I a, I b) { return _mm512_cmpeq_epi32_mask(a, b); }
  ROIFLOW_INLINE static bool all(M m) { return m == 0xFFFF; }
  ROIFLOW_INLINE static F select(M m, F a, F b) { return _mm512_mask_blend_ps(m, b, a); }
  ROIFLOW_INLINE static std::int32_t first(I a) {
    return _mm_cvtsi128_si32(_mm512_castsi512_si128(a));
  }
  ROIFLOW_INLINE static F gather(const float* base, I idx) {
    return _mm512_i32gather_ps(idx, base, 4);
  }
  // Inclusive prefix sum of the lanes.
  ROIFLOW_INLINE static F prefix(F a) {
    const __m512i zero = _mm512_setzero_si512();
    __m512i x = _mm512_castps_si512(a);
    x = _mm512_castps_si512(_mm512_add_ps(_mm512_castsi512_ps(x),
                                          _mm512_castsi512_ps(_mm512_alignr_epi32(x, zero, 15))));
    x = _mm512_castps_si512(_mm512_add_ps(_mm512_castsi512_ps(x),
                                          _mm512_castsi512_ps(_mm512_alignr_epi32(x, zero, 14))));
    x = _mm512_castps_si512(_mm512_add_ps(_mm512_castsi512_ps(x),
                                          _mm512_castsi512_ps(_mm512_alignr_epi32(x, zero, 12))));
    x = _mm512_castps_si512(_mm512_add_ps(_mm512_castsi512_ps(x),
                                          _mm512_castsi512_ps(_mm512_alignr_epi32(x, zero, 8))));
    return _mm512_castsi512_ps(x);
  }
  // The last lane in every lane.
  ROIFLOW_INLINE static F last(F a) { return _mm512_permutexvar_ps(_mm512_set1_epi32(15), a); }
  // Lane i: lane idx[i] of the 32 lanes of lo and hi.
  ROIFLOW_INLINE static F permute2(F lo, F hi, I idx) {
    return _mm512_permutex2var_ps(lo, idx, hi);
  }
  // The lanes with 0 <= a < n.
  ROIFLOW_INLINE static M below(I a, std::int32_t n) {
    return _mm512_cmplt_epu32_mask(a, _mm512_set1_epi32(n));
  }
  ROIFLOW_INLINE static bool any(M m) { return m != 0; }
  ROIFLOW_INLINE static M either(M a, M b) { return a | b; }
  ROIFLOW_INLINE static F next1(F a, F b) {
    return _mm512_castsi512_ps(
        _mm512_alignr_epi32(_mm512_castps_si512(b), _mm512_castps_si512(a), 1));
  }
  ROIFLOW_INLINE static F load_u8(const std::uint8_t* p) {
    return _mm512_cvtepi32_ps(
        _mm512_cvtepu8_epi32(_mm_loadu_si128(reinterpret_cast<const __m128i*>(p))));
  }
  ROIFLOW_INLINE static void zip(F a, F b, F& lo, F& hi) {
    const __m512i l = _mm512_setr_epi32(0, 16, 1, 17, 2, 18, 3, 19, 4, 20, 5, 21, 6, 22, 7, 23);
    const __m512i h =
        _mm512_setr_epi32(8, 24, 9, 25, 10, 26, 11, 27, 12, 28, 13, 29, 14, 30, 15, 31);
    lo = _mm512_permutex2var_ps(a, l, b);
    hi = _mm512_permutex2var_ps(a, h, b);
  }
};
#elif defined(ROIFLOW_SIMD_AVX2)
struct Native {
  using F = __m256;
  using I = __m256i;
  using M = __m256i;
  static constexpr int N = 8;
  // Whether permute2, below, any and either exist (two-vector permutes: AVX-512 only).
  static constexpr bool kPermute2 = false;
  ROIFLOW_INLINE static F load(const float* p) { return _mm256_loadu_ps(p); }
  ROIFLOW_INLINE static void store(float* p, F a) { _mm256_storeu_ps(p, a); }
  ROIFLOW_INLINE static F set1(float a) { return _mm256_set1_ps(a); }
  ROIFLOW_INLINE static F iota() { return _mm256_setr_ps(0, 1, 2, 3, 4, 5, 6, 7); }
  ROIFLOW_INLINE static F add(F a, F b) { return _mm256_add_ps(a, b); }
  ROIFLOW_INLINE static F sub(F a, F b) { return _mm256_sub_ps(a, b); }
  ROIFLOW_INLINE static F mul(F a, F b) { return _mm256_mul_ps(a, b); }
  ROIFLOW_INLINE static F div(F a, F b) { return _mm256_div_ps(a, b); }
  ROIFLOW_INLINE static F madd(F a, F b, F c) { return _mm256_fmadd_ps(a, b, c); }
  ROIFLOW_INLINE static F nmadd(F a, F b, F c) { return _mm256_fnmadd_ps(a, b, c); }
  ROIFLOW_INLINE static F min(F a, F b) { return _mm256_min_ps(a, b); }
  ROIFLOW_INLINE static F max(F a, F b) { return _mm256_max_ps(a, b); }
  ROIFLOW_INLINE static F sqrt(F a) { return _mm256_sqrt_ps(a); }
  // 1 / a: the 12-bit estimate and one Newton step.
  ROIFLOW_INLINE static F recip(F a) {
    const F r = _mm256_rcp_ps(a);
    return _mm256_fmadd_ps(r, _mm256_fnmadd_ps(a, r, _mm256_set1_ps(1.f)), r);
  }
  ROIFLOW_INLINE static I seti(std::int32_t a) { return _mm256_set1_epi32(a); }
  ROIFLOW_INLINE static I iotai() { return _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7); }
  ROIFLOW_INLINE static I addi(I a, I b) { return _mm256_add_epi32(a, b); }
  ROIFLOW_INLINE static I subi(I a, I b) { return _mm256_sub_epi32(a, b); }
  ROIFLOW_INLINE static I muli(I a, I b) { return _mm256_mullo_epi32(a, b); }
  ROIFLOW_INLINE static I mini(I a, I b) { return _mm256_min_epi32(a, b); }
  ROIFLOW_INLINE static I cvtt(F a) { return _mm256_cvttps_epi32(a); }
  ROIFLOW_INLINE static F cvt(I a) { return _mm256_cvtepi32_ps(a); }
  ROIFLOW_INLINE static M eqi(I a, I b) { return _mm256_cmpeq_epi32(a, b); }
  ROIFLOW_INLINE static bool all(M m) { return _mm256_movemask_epi8(m) == -1; }
  ROIFLOW_INLINE static F select(M m, F a, F b) {
    return _mm256_blendv_ps(b, a, _mm256_castsi256_ps(m));
  }
  ROIFLOW_INLINE static std::int32_t first(I a) {
    return _mm_cvtsi128_si32(_mm256_castsi256_si128(a));
  }
  ROIFLOW_INLINE static F gather(const float* base, I idx) {
    return _mm256_i32gather_ps(base, idx, 4);
  }
  ROIFLOW_INLINE static F prefix(F a) {
    __m256 x = _mm256_add_ps(a, _mm256_castsi256_ps(_mm256_slli_si256(_mm256_castps_si256(a), 4)));
    x = _mm256_add_ps(x, _mm256_castsi256_ps(_mm256_slli_si256(_mm256_castps_si256(x), 8)));
    // Each 128-bit half holds its own prefix: carry the low half's total into the high one.
    const __m256 low_total = _mm256_permute_ps(x, _MM_SHUFFLE(3, 3, 3, 3));
    return _mm256_add_ps(x, _mm256_permute2f128_ps(low_total, low_total, 0x08));
  }
  ROIFLOW_INLINE static F last(F a) {
    const __m256 l = _mm256_permute_ps(a, _MM_SHUFFLE(3, 3, 3, 3));
    return _mm256_permute2f128_ps(l, l, 0x11);
  }
  ROIFLOW_INLINE static F next1(F a, F b) {
    // [a's high half, b's low half], then each 128-bit half shifted by one lane.
    const __m256i t = _mm256_castps_si256(_mm256_permute2f128_ps(a, b, 0x21));
    return _mm256_castsi256_ps(_mm256_alignr_epi8(t, _mm256_castps_si256(a), 4));
  }
  ROIFLOW_INLINE static F load_u8(const std::uint8_t* p) {
    return _mm256_cvtepi32_ps(
        _mm256_cvtepu8_epi32(_mm_loadl_epi64(reinterpret_cast<const __m128i*>(p))));
  }
  ROIFLOW_INLINE static void zip(F a, F b, F& lo, F& hi) {
    const F l = _mm256_unpacklo_ps(a, b), h = _mm256_unpackhi_ps(a, b);
    lo = _mm256_permute2f128_ps(l, h, 0x20);
    hi = _mm256_permute2f128_ps(l, h, 0x31);
  }
};
#elif defined(ROIFLOW_SIMD_SSE2)
struct Native {
  using F = __m128;
  using I = __m128i;
  using M = __m128i;
  static constexpr int N = 4;
  // Whether permute2, below, any and either exist (two-vector permutes: AVX-512 only).
  static constexpr bool kPermute2 = false;
  ROIFLOW_INLINE static F load(const float* p) { return _mm_loadu_ps(p); }
  ROIFLOW_INLINE static void store(float* p, F a) { _mm_storeu_ps(p, a); }
  ROIFLOW_INLINE static F set1(float a) { return _mm_set1_ps(a); }
  ROIFLOW_INLINE static F iota() { return _mm_setr_ps(0, 1, 2, 3); }
  ROIFLOW_INLINE static F add(F a, F b) { return _mm_add_ps(a, b); }
  ROIFLOW_INLINE static F sub(F a, F b) { return _mm_sub_ps(a, b); }
  ROIFLOW_INLINE static F mul(F a, F b) { return _mm_mul_ps(a, b); }
  ROIFLOW_INLINE static F div(F a, F b) { return _mm_div_ps(a, b); }
  ROIFLOW_INLINE static F madd(F a, F b, F c) { return _mm_add_ps(_mm_mul_ps(a, b), c); }
  ROIFLOW_INLINE static F nmadd(F a, F b, F c) { return _mm_sub_ps(c, _mm_mul_ps(a, b)); }
  ROIFLOW_INLINE static F min(F a, F b) { return _mm_min_ps(a, b); }
  ROIFLOW_INLINE static F max(F a, F b) { return _mm_max_ps(a, b); }
  ROIFLOW_INLINE static F sqrt(F a) { return _mm_sqrt_ps(a); }
  ROIFLOW_INLINE static F recip(F a) { return _mm_div_ps(_mm_set1_ps(1.f), a); }
  ROIFLOW_INLINE static I seti(std::int32_t a) { return _mm_set1_epi32(a); }
  ROIFLOW_INLINE static I iotai() { return _mm_setr_epi32(0, 1, 2, 3); }
  ROIFLOW_INLINE static I addi(I a, I b) { return _mm_add_epi32(a, b); }
  ROIFLOW_INLINE static I subi(I a, I b) { return _mm_sub_epi32(a, b); }
  ROIFLOW_INLINE static I muli(I a, I b) {
    // SSE2 has no 32-bit low multiply: two 32x32->64 products of the even and odd lanes.
    const __m128i even = _mm_mul_epu32(a, b);
    const __m128i odd = _mm_mul_epu32(_mm_srli_si128(a, 4), _mm_srli_si128(b, 4));
    return _mm_unpacklo_epi32(_mm_shuffle_epi32(even, _MM_SHUFFLE(0, 0, 2, 0)),
                              _mm_shuffle_epi32(odd, _MM_SHUFFLE(0, 0, 2, 0)));
  }
  ROIFLOW_INLINE static I mini(I a, I b) {
    const __m128i lt = _mm_cmplt_epi32(b, a);
    return _mm_or_si128(_mm_and_si128(lt, b), _mm_andnot_si128(lt, a));
  }
  ROIFLOW_INLINE static I cvtt(F a) { return _mm_cvttps_epi32(a); }
  ROIFLOW_INLINE static F cvt(I a) { return _mm_cvtepi32_ps(a); }
  ROIFLOW_INLINE static M eqi(I a, I b) { return _mm_cmpeq_epi32(a, b); }
  ROIFLOW_INLINE static bool all(M m) { return _mm_movemask_epi8(m) == 0xFFFF; }
  ROIFLOW_INLINE static F select(M m, F a, F b) {
    const __m128 mf = _mm_castsi128_ps(m);
    return _mm_or_ps(_mm_and_ps(mf, a), _mm_andnot_ps(mf, b));
  }
  ROIFLOW_INLINE static std::int32_t first(I a) { return _mm_cvtsi128_si32(a); }
  ROIFLOW_INLINE static F gather(const float* base, I idx) {
    alignas(16) std::int32_t i[4];
    _mm_store_si128(reinterpret_cast<__m128i*>(i), idx);
    return _mm_setr_ps(base[i[0]], base[i[1]], base[i[2]], base[i[3]]);
  }
  ROIFLOW_INLINE static F prefix(F a) {
    F x = _mm_add_ps(a, _mm_castsi128_ps(_mm_slli_si128(_mm_castps_si128(a), 4)));
    return _mm_add_ps(x, _mm_castsi128_ps(_mm_slli_si128(_mm_castps_si128(x), 8)));
  }
  ROIFLOW_INLINE static F last(F a) { return _mm_shuffle_ps(a, a, _MM_SHUFFLE(3, 3, 3, 3)); }
  ROIFLOW_INLINE static F next1(F a, F b) {
    const F t = _mm_move_ss(a, b);  // b0 a1 a2 a3
    return _mm_shuffle_ps(t, t, _MM_SHUFFLE(0, 3, 2, 1));
  }
  ROIFLOW_INLINE static F load_u8(const std::uint8_t* p) {
    std::int32_t word;
    std::memcpy(&word, p, 4);
    const __m128i zero = _mm_setzero_si128();
    const __m128i b = _mm_unpacklo_epi8(_mm_cvtsi32_si128(word), zero);
    return _mm_cvtepi32_ps(_mm_unpacklo_epi16(b, zero));
  }
  ROIFLOW_INLINE static void zip(F a, F b, F& lo, F& hi) {
    lo = _mm_unpacklo_ps(a, b);
    hi = _mm_unpackhi_ps(a, b);
  }
};
#elif defined(ROIFLOW_SIMD_NEON)
struct Native {
  using F = float32x4_t;
  using I = int32x4_t;
  using M = uint32x4_t;
  static constexpr int N = 4;
  // Whether permute2, below, any and either exist (two-vector permutes: AVX-512 only).
  static constexpr bool kPermute2 = false;
  ROIFLOW_INLINE static F load(const float* p) { return vld1q_f32(p); }
  ROIFLOW_INLINE static void store(float* p, F a) { vst1q_f32(p, a); }
  ROIFLOW_INLINE static F set1(float a) { return vdupq_n_f32(a); }
  ROIFLOW_INLINE static F iota() {
    static const float v[4] = {0, 1, 2, 3};
    return vld1q_f32(v);
  }
  ROIFLOW_INLINE static F add(F a, F b) { return vaddq_f32(a, b); }
  ROIFLOW_INLINE static F sub(F a, F b) { return vsubq_f32(a, b); }
  ROIFLOW_INLINE static F mul(F a, F b) { return vmulq_f32(a, b); }
  ROIFLOW_INLINE static F div(F a, F b) { return vdivq_f32(a, b); }
  ROIFLOW_INLINE static F madd(F a, F b, F c) { return vfmaq_f32(c, a, b); }
  ROIFLOW_INLINE static F nmadd(F a, F b, F c) { return vfmsq_f32(c, a, b); }
  ROIFLOW_INLINE static F min(F a, F b) { return vminq_f32(a, b); }
  ROIFLOW_INLINE static F max(F a, F b) { return vmaxq_f32(a, b); }
  ROIFLOW_INLINE static F sqrt(F a) { return vsqrtq_f32(a); }
  // 1 / a: the estimate and two Newton steps.
  ROIFLOW_INLINE static F recip(F a) {
    F r = vrecpeq_f32(a);
    r = vmulq_f32(r, vrecpsq_f32(a, r));
    return vmulq_f32(r, vrecpsq_f32(a, r));
  }
  ROIFLOW_INLINE static I seti(std::int32_t a) { return vdupq_n_s32(a); }
  ROIFLOW_INLINE static I iotai() {
    static const std::int32_t v[4] = {0, 1, 2, 3};
    return vld1q_s32(v);
  }
  ROIFLOW_INLINE static I addi(I a, I b) { return vaddq_s32(a, b); }
  ROIFLOW_INLINE static I subi(I a, I b) { return vsubq_s32(a, b); }
  ROIFLOW_INLINE static I muli(I a, I b) { return vmulq_s32(a, b); }
  ROIFLOW_INLINE static I mini(I a, I b) { return vminq_s32(a, b); }
  ROIFLOW_INLINE static I cvtt(F a) { return vcvtq_s32_f32(a); }
  ROIFLOW_INLINE static F cvt(I a) { return vcvtq_f32_s32(a); }
  ROIFLOW_INLINE static M eqi(I a, I b) { return vceqq_s32(a, b); }
  ROIFLOW_INLINE static bool all(M m) { return vminvq_u32(m) == 0xFFFFFFFFu; }
  ROIFLOW_INLINE static F select(M m, F a, F b) { return vbslq_f32(m, a, b); }
  ROIFLOW_INLINE static std::int32_t first(I a) { return vgetq_lane_s32(a, 0); }
  ROIFLOW_INLINE static F gather(const float* base, I idx) {
    const float v[4] = {base[vgetq_lane_s32(idx, 0)], base[vgetq_lane_s32(idx, 1)],
                        base[vgetq_lane_s32(idx, 2)], base[vgetq_lane_s32(idx, 3)]};
    return vld1q_f32(v);
  }
  ROIFLOW_INLINE static F prefix(F a) {
    const F zero = vdupq_n_f32(0.f);
    const F x = vaddq_f32(a, vextq_f32(zero, a, 3));
    return vaddq_f32(x, vextq_f32(zero, x, 2));
  }
  ROIFLOW_INLINE static F last(F a) { return vdupq_laneq_f32(a, 3); }
  ROIFLOW_INLINE static F next1(F a, F b) { return vextq_f32(a, b, 1); }
  ROIFLOW_INLINE static F load_u8(const std::uint8_t* p) {
    std::uint32_t word;
    std::memcpy(&word, p, 4);
    const uint8x8_t b = vcreate_u8(word);
    return vcvtq_f32_u32(vmovl_u16(vget_low_u16(vmovl_u8(b))));
  }
  ROIFLOW_INLINE static void zip(F a, F b, F& lo, F& hi) {
    lo = vzip1q_f32(a, b);
    hi = vzip2q_f32(a, b);
  }
};
#else
using Native = Scalar;
#endif

}  // namespace
}  // namespace roiflow::flow::simd
