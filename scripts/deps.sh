#!/usr/bin/env bash
# Installs the Debian/Ubuntu packages that roiflow's build, tests and benchmarks need.
# Idempotent: asks apt for nothing (no network, no root) when everything is already there.
#
#   scripts/deps.sh
set -euo pipefail

packages=(
  build-essential cmake ninja-build pkg-config
  libopencv-dev libopencv-contrib-dev libavformat-dev libavcodec-dev libavutil-dev libswscale-dev libtbb-dev libcli11-dev nlohmann-json3-dev libeigen3-dev
  libgtest-dev libgmock-dev libbenchmark-dev
  clang libclang-rt-14-dev dpkg-dev
)

missing=()
for package in "${packages[@]}"; do
  # dpkg-query fails for packages it has never heard of, and reports e.g. "deinstall ok
  # config-files" for removed ones: only "install ok installed" counts.
  status=$(dpkg-query -W -f='${Status}' "$package" 2>/dev/null || true)
  if [[ "$status" != "install ok installed" ]]; then
    missing+=("$package")
  fi
done

if ((${#missing[@]} == 0)); then
  echo "deps: all ${#packages[@]} packages already installed, nothing to do"
  exit 0
fi

as_root=()
if ((EUID != 0)); then
  if ! command -v sudo >/dev/null; then
    echo "deps: missing ${missing[*]}; run as root or install sudo" >&2
    exit 1
  fi
  as_root=(sudo)
fi

apt_get() { "${as_root[@]}" env DEBIAN_FRONTEND=noninteractive apt-get -qq "$@"; }
apt_get update
apt_get install -y --no-install-recommends "${missing[@]}" >/dev/null
echo "deps: installed ${#missing[@]} missing packages: ${missing[*]}"
