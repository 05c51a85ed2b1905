#!/usr/bin/env bash
# Tracking gate on an OTB sequence (OTB protocol: --init from the first ground-truth box, default
# settings, then roiflow score): fails when the success AUC or precision@20 falls below its gate.
# Gates are the values measured when they were set (README, "Tracking") minus a small margin.
#
#   scripts/track_gate.sh SEQUENCE_DIR [build-dir]      # e.g. ../shared/data/tracking/Car4
set -euo pipefail
cd "$(dirname "$0")/.."
dir=$1
bin=${2:-build/release}/roiflow
min_auc=0.80        # measured on Car4: 0.872
min_precision=0.98  # measured on Car4: 1.000
truth="$dir/groundtruth_rect.txt"
init=$(head -n 1 "$truth" | tr '\t ' ',,' | tr -d '\r')
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
"$bin" track "$dir" --init "$init" --threads 1 --no-progress --log "$work/track.csv" \
  --summary "$work/summary.json" >/dev/null
json=$("$bin" score "$work/track.csv" "$truth" --format json)
auc=$(sed -n 's/.*"auc": *\([0-9.eE+-]*\).*/\1/p' <<<"$json")
precision=$(sed -n 's/.*"precision20": *\([0-9.eE+-]*\).*/\1/p' <<<"$json")
fps=$(sed -n 's/.*"tracker_fps": *\([0-9.eE+-]*\).*/\1/p' "$work/summary.json")
verdict=pass
status=0
if awk -v a="$auc" -v p="$precision" -v ma="$min_auc" -v mp="$min_precision" \
    'BEGIN { exit !(a < ma || p < mp) }'; then
  verdict=FAIL
  status=1
fi
printf 'gate track %s  AUC %s (min %s)  precision@20 %s (min %s)  tracker %.0f fps  %s\n' \
  "$(basename "$dir")" "$auc" "$min_auc" "$precision" "$min_precision" "$fps" "$verdict"
exit $status
