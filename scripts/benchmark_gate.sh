#!/usr/bin/env bash
# Benchmark gate on the development tracking set: `roiflow benchmark` with roiflow alone over
# every sequence (OTB one-pass evaluation, docs/BENCHMARK.md), then roiflow's mean AUC against its
# floor, set just under the value measured when it was set. Strict: the CSV must have its
# header, one roiflow row per sequence (a sequence silently dropped fails), finite figures in
# every row, a mean row that is the mean of the rows, and a finite frames/s.
#
#   scripts/benchmark_gate.sh TRACKING_DIR [build-dir]      # e.g. ../shared/data/tracking
set -euo pipefail
cd "$(dirname "$0")/.."
source scripts/gate_lib.sh
dir=$1
bin=${2:-build/release}/roiflow
sequences=8    # Car4 and the seven of SOURCES.md section 4
min_auc=0.645  # measured: 0.651 (sot9, issue 20: a weak look alone is no hold; a held box after a loss needs the colours)
[[ -d $dir ]] || gate_fail "$dir not found"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
"$bin" benchmark "$dir" --out "$work/out" --trackers roiflow --threads 2 --no-progress \
  >/dev/null || gate_fail "roiflow benchmark $dir failed"
csv="$work/out/benchmark.csv"
[[ -f $csv ]] || gate_fail "no $csv"
header=$(head -n 1 "$csv")
[[ $header == sequence,tracker,frames,scored,auc,precision20,mean_iou,fps,* ]] ||
  gate_fail "unexpected header '$header'"
rows=$(tail -n +2 "$csv" | grep -v '^mean,' || true)
gate_count "sequences" "$(grep -c . <<<"$rows" || true)" "$sequences"
sum_auc=0
while IFS=, read -r name tracker frames scored auc _ _ fps _; do
  [[ $tracker == roiflow ]] || gate_fail "row $name: tracker '$tracker', expected roiflow"
  gate_number "$name frames" "$frames"
  gate_number "$name scored frames" "$scored"
  gate_number "$name AUC" "$auc"
  gate_number "$name fps" "$fps"
  sum_auc=$(awk -v s="$sum_auc" -v x="$auc" 'BEGIN { printf "%.6f", s + x }')
done <<<"$rows"
mean=$(grep '^mean,' "$csv" || true)
[[ $(grep -c . <<<"$mean" || true) == 1 ]] || gate_fail "no single mean row"
IFS=, read -r _ _ frames _ auc _ _ fps _ <<<"$mean"
gate_number "mean AUC" "$auc"
gate_number "mean fps" "$fps"
gate_number "frames" "$frames"
# The printed mean must be the mean of the printed rows (to their rounding).
awk -v s="$sum_auc" -v n="$sequences" -v m="$auc" 'BEGIN { d = s / n - m; exit !(d < 1e-3 && d > -1e-3) }' ||
  gate_fail "mean AUC $auc is not the mean of the $sequences rows"
verdict=pass
status=0
if ! gate_holds "$auc" '>=' "$min_auc"; then
  verdict=FAIL
  status=1
fi
printf 'gate benchmark %d sequences, %d frames  roiflow mean AUC %s (min %s)  %.0f fps  %s\n' \
  "$sequences" "$frames" "$auc" "$min_auc" "$fps" "$verdict"
exit $status
