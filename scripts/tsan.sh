#!/usr/bin/env bash
# The concurrency tests under ThreadSanitizer (ROIFLOW_TEST_FILTER of the tsan preset): the
# flow-graph, stripe-executor, tracker, banded background model, cancellation and soak tests, and
# the video decoder's and DeferredImage's (colour converted on whichever thread asks first),
# against a oneTBB built with TSan.
#
#   scripts/tsan.sh
#
# Debian's oneTBB is not instrumented, so scripts/tsan_tbb.sh first builds Debian's own oneTBB
# source with -fsanitize=thread (once, ~1 minute); the tsan preset links it. What TSan cannot see
# into (OpenCV, FFmpeg) is listed in tests/tsan.supp with the reason. The preset leaves out
# tests that start no thread of their own and would cost minutes under TSan (e.g.
# Tracker.TheWholeFramePyramidsNeverChangeTheResult: nine serial tracker runs, 3 minutes).
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/deps.sh
scripts/tsan_tbb.sh
cmake --preset tsan >/dev/null
cmake --build --preset tsan -j"$(nproc)"
ctest --preset tsan -j"$(nproc)"
