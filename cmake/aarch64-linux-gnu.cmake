# CMake toolchain for an arm64 (aarch64) build on an x86-64 Debian machine: Debian's cross
# compiler (crossbuild-essential-arm64) against an arm64 sysroot (scripts/arm64.sh makes one),
# tests run under qemu-user.
#
#   cmake -S . -B build/arm64 -G Ninja -DCMAKE_TOOLCHAIN_FILE=cmake/aarch64-linux-gnu.cmake \
#         -DROIFLOW_ARM64_SYSROOT=$PWD/build/arm64-sysroot
set(CMAKE_SYSTEM_NAME Linux)
set(CMAKE_SYSTEM_PROCESSOR aarch64)
set(CMAKE_C_COMPILER aarch64-linux-gnu-gcc)
set(CMAKE_CXX_COMPILER aarch64-linux-gnu-g++)

if(NOT ROIFLOW_ARM64_SYSROOT)
  set(ROIFLOW_ARM64_SYSROOT "$ENV{ROIFLOW_ARM64_SYSROOT}")
endif()
if(NOT IS_DIRECTORY "${ROIFLOW_ARM64_SYSROOT}/usr/lib/aarch64-linux-gnu")
  message(FATAL_ERROR "ROIFLOW_ARM64_SYSROOT='${ROIFLOW_ARM64_SYSROOT}' is not an arm64 sysroot "
                      "(make one with scripts/arm64.sh)")
endif()
# Try-compiles see the same variable.
list(APPEND CMAKE_TRY_COMPILE_PLATFORM_VARIABLES ROIFLOW_ARM64_SYSROOT)

set(CMAKE_SYSROOT "${ROIFLOW_ARM64_SYSROOT}")
set(CMAKE_FIND_ROOT_PATH "${ROIFLOW_ARM64_SYSROOT}")
set(CMAKE_FIND_ROOT_PATH_MODE_PROGRAM NEVER)
set(CMAKE_FIND_ROOT_PATH_MODE_LIBRARY ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_INCLUDE ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_PACKAGE ONLY)
# The sysroot's dynamic loader and libraries for the test binaries (and gtest's test discovery).
set(CMAKE_CROSSCOMPILING_EMULATOR "qemu-aarch64;-L;${ROIFLOW_ARM64_SYSROOT}")
# The host's pkg-config reads the sysroot's .pc files.
set(ENV{PKG_CONFIG_SYSROOT_DIR} "${ROIFLOW_ARM64_SYSROOT}")
set(ENV{PKG_CONFIG_LIBDIR}
    "${ROIFLOW_ARM64_SYSROOT}/usr/lib/aarch64-linux-gnu/pkgconfig:${ROIFLOW_ARM64_SYSROOT}/usr/share/pkgconfig")
