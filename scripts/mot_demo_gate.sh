#!/usr/bin/env bash
# Multi-object demo gate (no external data): `roiflow demo --objects 16` tracks the synthetic
# traffic scene (16 vehicles crossing, entering and leaving; docs/TRACKING.md) and scores its
# MOTChallenge output against the scene's exact boxes. Fails when MOTA or IDF1 falls below its
# floor (a regression gate; see the floors below). Strict: summary.json must hold finite mota and idf1, mot.txt and gt_mot.txt must exist
# and be non-empty, and `roiflow score --mot mot.txt gt_mot.txt` must give the same MOTA and
# IDF1 as the summary (a summary that does not describe its own files fails).
#
#   scripts/mot_demo_gate.sh [build-dir]
set -euo pipefail
cd "$(dirname "$0")/.."
source scripts/gate_lib.sh
bin=${1:-build/release}/roiflow
# Floors: the values measured when they were set, minus a margin (session 12, a grey body between
# bright parts is no shadow: MOTA 0.938, IDF1 0.959). The issue's bar, MOTA >= 0.90 and IDF1 >=
# 0.90, is met; raise the floors as the tracker improves (docs/TRACKING.md).
min_mota=0.925
min_idf1=0.945
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
"$bin" demo --objects 16 --dir "$work/demo" --threads 2 --no-progress >/dev/null ||
  gate_fail "roiflow demo --objects 16 failed"
for f in summary.json mot.txt gt_mot.txt; do
  [[ -s $work/demo/$f ]] || gate_fail "demo wrote no $f"
done
summary=$(cat "$work/demo/summary.json")
mota=$(gate_json_number "$summary" mota)
idf1=$(gate_json_number "$summary" idf1)
gate_number "summary mota" "$mota"
gate_number "summary idf1" "$idf1"
json=$("$bin" score --mot "$work/demo/mot.txt" "$work/demo/gt_mot.txt" --format json) ||
  gate_fail "roiflow score --mot failed on the demo's files"
score_mota=$(gate_json_number "$json" mota)
score_idf1=$(gate_json_number "$json" idf1)
gate_number "scored mota" "$score_mota"
gate_number "scored idf1" "$score_idf1"
same() { awk -v a="$1" -v b="$2" 'BEGIN { d = a - b; exit !(d < 1e-6 && d > -1e-6) }'; }
same "$mota" "$score_mota" || gate_fail "summary mota $mota, its files score $score_mota"
same "$idf1" "$score_idf1" || gate_fail "summary idf1 $idf1, its files score $score_idf1"
verdict=pass
status=0
if ! gate_holds "$mota" '>=' "$min_mota" || ! gate_holds "$idf1" '>=' "$min_idf1"; then
  verdict=FAIL
  status=1
fi
printf 'gate mot demo  16 objects  MOTA %s (min %s)  IDF1 %s (min %s)  %s\n' \
  "$mota" "$min_mota" "$idf1" "$min_idf1" "$verdict"
exit $status
