#!/usr/bin/env bash
# The main job on a built-in input: set-up, build, then dense LK on the built-in synthetic
# pair (a textured object moving over a moving textured background), writing the flow, its
# colour coding and the colour-wheel legend to out/ and printing the error against the
# scene's exact ground truth.
#
#   scripts/demo.sh
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/build.sh release
mkdir -p out
build/release/roiflow flow --synthetic -o out/synthetic.flo --color out/synthetic.png \
  --legend out/legend.png
