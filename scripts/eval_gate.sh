#!/usr/bin/env bash
# Accuracy gates on the Middlebury "other" training set with ground truth: fails when the mean
# EPE or AAE of a preset rises above its gate. Gates are the values measured when they were
# set (README, "Accuracy") plus about 4 %: enough for compiler and CPU differences, tight
# enough to catch a real regression.
#
#   scripts/eval_gate.sh DIR [build-dir]
set -euo pipefail
cd "$(dirname "$0")/.."
dir=$1
bin=${2:-build/release}/roiflow
#        preset    max mean EPE  max mean AAE (measured: EPE / AAE)
gates=("paper      0.88          7.40"   # 0.843 / 7.11
       "accurate   0.465         5.60")  # 0.443 / 5.35
status=0
for gate in "${gates[@]}"; do
  read -r preset max_epe max_aae <<<"$gate"
  csv=$("$bin" eval "$dir" --preset "$preset" --format csv)
  mean=$(tail -n 1 <<<"$csv")
  IFS=, read -r name aae epe r1 r3 ms <<<"$mean"
  if [[ "$name" != mean ]]; then
    echo "gate: roiflow eval printed no mean row for preset $preset" >&2
    exit 1
  fi
  verdict=pass
  if awk -v e="$epe" -v a="$aae" -v me="$max_epe" -v ma="$max_aae" \
      'BEGIN { exit !(e > me || a > ma) }'; then
    verdict=FAIL
    status=1
  fi
  printf 'gate %-8s mean EPE %s (max %s)  mean AAE %s deg (max %s)  %s ms/pair  %s\n' \
    "$preset" "$epe" "$max_epe" "$aae" "$max_aae" "$ms" "$verdict"
done
exit $status
