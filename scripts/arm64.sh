#!/usr/bin/env bash
# Cross-builds roiflow for arm64 (aarch64, NEON kernels) on an x86-64 Debian 12 machine and runs
# its tests under qemu-user: the paper's platform (a Raspberry Pi 4's Cortex-A72) checked from CI.
#
#   scripts/arm64.sh                 # the flow tests (the kernels): ~3 min on two cores
#   scripts/arm64.sh flow eval       # test labels to run (flow core eval report video tracking pipeline)
#
# Host packages (amd64, co-install with everything): crossbuild-essential-arm64 qemu-user
# mmdebstrap. The arm64 libraries live in a separate sysroot (build/arm64-sysroot, or
# $ROIFLOW_ARM64_SYSROOT): Debian 12's arm64 -dev packages do not co-install with the amd64 ones
# (`apt-get install -s libopencv-dev:arm64` removes libopencv-dev:amd64; only core, imgproc and
# video would co-install), so mmdebstrap extracts them into a directory of their own, without a
# chroot or binfmt. The toolchain file is cmake/aarch64-linux-gnu.cmake; test binaries run as
# `qemu-aarch64 -L <sysroot>` (CMAKE_CROSSCOMPILING_EMULATOR), also for gtest's discovery.
set -euo pipefail

root=$(cd "$(dirname "$0")/.." && pwd)
sysroot=${ROIFLOW_ARM64_SYSROOT:-$root/build/arm64-sysroot}
build=$root/build/arm64
labels=("$@")
((${#labels[@]})) || labels=(flow)
start=$(date +%s)

host_tools=(crossbuild-essential-arm64 qemu-user mmdebstrap)
missing=()
for package in "${host_tools[@]}"; do
  status=$(dpkg-query -W -f='${Status}' "$package" 2>/dev/null || true)
  [[ "$status" == "install ok installed" ]] || missing+=("$package")
done
if ((${#missing[@]})); then
  echo "arm64: installing ${missing[*]}"
  as_root=()
  ((EUID == 0)) || as_root=(sudo)
  "${as_root[@]}" env DEBIAN_FRONTEND=noninteractive apt-get -qq update
  "${as_root[@]}" env DEBIAN_FRONTEND=noninteractive apt-get -qq install -y --no-install-recommends \
    "${missing[@]}"
fi

# The arm64 counterparts of scripts/deps.sh's libraries (no benchmark: the benches are not built).
arm64_packages=libc6-dev,libstdc++-12-dev,libgcc-12-dev,libopencv-dev,libtbb-dev,libcli11-dev
arm64_packages+=,libfmt-dev,libeigen3-dev
arm64_packages+=,nlohmann-json3-dev,libavformat-dev,libavcodec-dev,libavutil-dev,libswscale-dev
arm64_packages+=,libgtest-dev,libgmock-dev
# The marker holds the package list: a sysroot made for an older list is made again.
if [[ "$(cat "$sysroot/.roiflow-sysroot" 2>/dev/null)" != "$arm64_packages" ]]; then
  echo "arm64: extracting the arm64 packages into $sysroot (about 1.1 GB)"
  rm -rf "$sysroot"
  mkdir -p "$(dirname "$sysroot")"
  mmdebstrap --quiet --variant=extract --architectures=arm64 --include="$arm64_packages" \
    bookworm "$sysroot" http://deb.debian.org/debian
  # Extracting runs no maintainer script: make the links update-alternatives would (BLAS and
  # LAPACK, which OpenCV's core links).
  triplet_dir=$sysroot/usr/lib/aarch64-linux-gnu
  for alternative in blas lapack; do
    for library in "$triplet_dir/$alternative"/lib*.so.3; do
      ln -sf "$alternative/$(basename "$library")" "$triplet_dir/$(basename "$library")"
    done
  done
  echo "$arm64_packages" >"$sysroot/.roiflow-sysroot"
fi

targets=()
for label in "${labels[@]}"; do
  case "$label" in
    flow | core | eval | report | video | tracking | pipeline) targets+=("roiflow_${label}_tests") ;;
    *) echo "arm64: unknown test label '$label' (flow core eval report video tracking pipeline)" >&2; exit 2 ;;
  esac
done

export CMAKE_CXX_COMPILER_LAUNCHER=${CMAKE_CXX_COMPILER_LAUNCHER:-$(command -v ccache || true)}
cmake -S "$root" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Release \
  -DCMAKE_TOOLCHAIN_FILE="$root/cmake/aarch64-linux-gnu.cmake" -DROIFLOW_ARM64_SYSROOT="$sysroot" \
  -DROIFLOW_NATIVE=OFF -DROIFLOW_BUILD_BENCH=OFF >/dev/null
cmake --build "$build" -j"${ROIFLOW_JOBS:-2}" --target "${targets[@]}"

# The flow tests check that the dispatch chose the NEON kernels (LkKernelsTest).
pattern=$(IFS='|'; echo "${labels[*]}")
(cd "$build" && ctest -L "^(${pattern})\$" -j"${ROIFLOW_JOBS:-2}" --output-on-failure)
echo "arm64: ${labels[*]} tests passed under qemu-aarch64 in $(($(date +%s) - start)) s"
