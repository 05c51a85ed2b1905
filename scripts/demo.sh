#!/usr/bin/env bash
# The main job on a built-in input: set-up, build, then `roiflow demo`: a synthetic fixed-camera
# video (a textured vehicle crossing a textured background at changing speed, with one jump too
# fast for the local region) is tracked without being told where the vehicle is — the global
# treatment finds it, LK in a 50x50-or-larger local region follows it, the global treatment
# finds it again after the jump. Writes out/demo/demo.mp4 (annotated), track.csv,
# summary.json and groundtruth.txt, and prints the error against the scene's exact boxes and
# the speed of local against whole-frame processing.
#
#   scripts/demo.sh
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/build.sh release
build/release/roiflow demo --dir out/demo
