// The dense LK kernels for AVX2 + FMA; see lk_kernels.hpp.
#ifdef ROIFLOW_KERNELS_AVX2  // set by CMake on x86-64, with the instruction-set flags
#define ROIFLOW_KERNEL_TABLE lk_kernels_avx2
#include "flow/lk_band_impl.hpp"
#endif
