#!/usr/bin/env bash
# Set-up, build, and every test: the GoogleTest suite (no external data needed), then, when
# ../shared/data exists beside the checkout, the accuracy gates on real data.
#
#   scripts/test.sh
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/build.sh release
ctest --preset release -j"$(nproc)"
if [[ -d ../shared/data/middlebury ]]; then
  scripts/eval_gate.sh ../shared/data/middlebury
else
  echo "test: ../shared/data/middlebury not found, real-data accuracy gates skipped"
fi
if [[ -d ../shared/data/tracking/Car4 ]]; then
  scripts/track_gate.sh ../shared/data/tracking/Car4
else
  echo "test: ../shared/data/tracking/Car4 not found, tracking gate skipped"
fi
