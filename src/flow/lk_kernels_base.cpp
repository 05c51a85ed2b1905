// The dense LK kernels for the build's baseline instruction set (SSE2 on x86-64, NEON on arm64);
// see lk_kernels.hpp.
#define ROIFLOW_KERNEL_TABLE lk_kernels_base
#include "flow/lk_band_impl.hpp"
