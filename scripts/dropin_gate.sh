#!/usr/bin/env bash
# Drop-in gate on the shared videos (docs/DROPIN.md):
#  - GStreamer: `filesrc ! decodebin ! videoconvert ! roiflowtrack log=... ! fakesink` on
#    video/opencv_vtest.avi writes the track log `roiflow track` writes on the same file (every
#    column but ms identical), and `roiflow score` reads it (scored against the CLI's own boxes:
#    mean IoU 1).
#  - batch: `roiflow batch video/ --out DIR -- track`, run twice: the first runs both videos, the
#    second does no work and reports both done; batch.csv holds one strict row per video.
# Strict: missing rows, NaN figures or wrong counts fail.
#
#   scripts/dropin_gate.sh DATA_DIR [build-dir]     # e.g. ../shared/data
#   GST_LAUNCH=... picks the gst-launch-1.0 binary (the gate-script test stubs it).
set -euo pipefail
cd "$(dirname "$0")/.."
source scripts/gate_lib.sh
data=$1
build=${2:-build/release}
bin=$build/roiflow
launch=${GST_LAUNCH:-gst-launch-1.0}
video="$data/video/opencv_vtest.avi"
[[ -f $video ]] || gate_fail "$video not found"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
export GST_PLUGIN_PATH=$build/gstreamer GST_REGISTRY=$work/registry.bin

# --- GStreamer element vs roiflow track
"$bin" track "$video" --single --no-progress --log "$work/cli.csv" >/dev/null || gate_fail "roiflow track failed"
"$launch" -q filesrc location="$video" ! decodebin ! videoconvert \
  ! roiflowtrack log="$work/gst.csv" ! fakesink >/dev/null 2>"$work/gst.err" ||
  gate_fail "gst-launch-1.0 pipeline failed: $(tail -n 1 "$work/gst.err")"
cli_rows=$(($(grep -c . "$work/cli.csv" || true) - 1))
gst_rows=$(($(grep -c . "$work/gst.csv" 2>/dev/null || true) - 1))
gate_count "roiflow track log rows" "$cli_rows" 795
gate_count "roiflowtrack log rows" "$gst_rows" "$cli_rows"
differ=$(diff <(cut -d, -f1-9 "$work/cli.csv") <(cut -d, -f1-9 "$work/gst.csv") | grep -c '^>' || true)
gate_count "rows where roiflowtrack differs from roiflow track" "$differ" 0
# The box columns x,y,w,h, found by name (the log gained an id column after frame).
awk -F, 'NR == 1 { for (i = 1; i <= NF; ++i) col[$i] = i; next }
  { print $col["x"] "," $col["y"] "," $col["w"] "," $col["h"] }' "$work/cli.csv" >"$work/cli_boxes.txt"
json=$("$bin" score "$work/gst.csv" "$work/cli_boxes.txt" --format json) ||
  gate_fail "roiflow score cannot read the element's log"
iou=$(gate_json_number "$json" mean_iou)
scored=$(gate_json_number "$json" frames)
gate_number "mean IoU" "$iou"
gate_number "scored frames" "$scored"
gate_holds "$iou" '>=' 0.999 || gate_fail "mean IoU of the element's log against roiflow track's: $iou"
printf 'gate dropin gstreamer  %d frames identical to roiflow track  score: %s frames, mean IoU %s  pass\n' \
  "$gst_rows" "$scored" "$iou"

# --- roiflow batch, twice
out="$work/batch"
"$bin" batch "$data/video" --out "$out" -- track >"$work/batch1.txt" 2>&1 ||
  gate_fail "roiflow batch failed: $(tail -n 1 "$work/batch1.txt")"
"$bin" batch "$data/video" --out "$out" -- track >"$work/batch2.txt" 2>&1 ||
  gate_fail "roiflow batch (second run) failed: $(tail -n 1 "$work/batch2.txt")"
grep -q "^batch: 2 videos: 2 run, 0 already done, 0 failed" "$work/batch1.txt" ||
  gate_fail "first batch run: $(tail -n 1 "$work/batch1.txt")"
grep -q "^batch: 2 videos: 0 run, 2 already done, 0 failed" "$work/batch2.txt" ||
  gate_fail "second batch run did work: $(tail -n 1 "$work/batch2.txt")"
rows=$(($(grep -c . "$out/batch.csv" || true) - 1))
gate_count "batch.csv rows" "$rows" 2
while IFS=, read -r name status frames fps seconds; do
  [[ $status == done ]] || gate_fail "batch.csv: $name: status '$status'"
  gate_number "$name frames" "$frames"
  gate_number "$name fps" "$fps"
  gate_number "$name seconds" "$seconds"
  gate_holds "$frames" '>' 700 || gate_fail "batch.csv: $name: $frames frames"
  log_rows=$(($(grep -c . "$out/$(basename "${name%.*}")/track.csv" || true) - 1))
  gate_count "$name track log rows" "$log_rows" "$frames"
done < <(tail -n +2 "$out/batch.csv")
echo "gate dropin batch  2 videos run, then 0 run and 2 already done  pass"
