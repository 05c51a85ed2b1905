// The dense LK kernels for AVX-512 (F, BW, VL, DQ); see lk_kernels.hpp.
#ifdef ROIFLOW_KERNELS_AVX512  // set by CMake on x86-64, with the instruction-set flags
#define ROIFLOW_KERNEL_TABLE lk_kernels_avx512
// GCC 12 warns inside its own AVX-512 headers (the _mm512_undefined_* operands of the unmasked
// intrinsics, GCC bug 105593, fixed in GCC 13).
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#endif
#include "flow/lk_band_impl.hpp"
#endif
