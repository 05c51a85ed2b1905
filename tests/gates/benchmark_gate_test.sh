#!/usr/bin/env bash
# scripts/benchmark_gate.sh fails when it should: a stub `roiflow benchmark` writes a CSV with a
# bad row (NaN or empty mean, a dropped sequence, a mean that is not the rows' mean, an infinite
# frames/s, another tracker, an AUC under the floor, no CSV at all) and the gate must exit
# non-zero; the same stub with good figures must pass, so each failure is the bad row's doing.
#
#   tests/gates/benchmark_gate_test.sh REPO_DIR
set -uo pipefail
repo=$1
source "$(dirname "$0")/expect_lib.sh"

# The stub copies $work/benchmark.csv (when there is one) to --out's folder.
mkdir -p "$work/stub" "$work/data"
cat >"$work/stub/roiflow" <<STUB
#!/usr/bin/env bash
[[ \$1 == benchmark ]] || exit 3
while [[ \$# -gt 0 ]]; do
  if [[ \$1 == --out ]]; then
    mkdir -p "\$2"
    [[ -f "$work/benchmark.csv" ]] && cp "$work/benchmark.csv" "\$2/benchmark.csv"
    shift
  fi
  shift
done
exit 0
STUB
chmod +x "$work/stub/roiflow"

header="sequence,tracker,frames,scored,auc,precision20,mean_iou,fps,cpu_s,lost,zero_iou,zero_iou_lost,lost_share"
bench_csv() {  # bench_csv ROWS ROW_AUC MEAN_ROW [LAST_ROW]
  {
    echo "$header"
    for ((i = 0; i < $1; ++i)); do echo "seq$i,roiflow,100,100,$2,0.7,0.6,1500.00,0.0667,0,0,0,"; done
    [[ -n ${4:-} ]] && echo "$4"
    echo "$3"
  } >"$work/benchmark.csv"
}
gate() { "$repo/scripts/benchmark_gate.sh" "$work/data" "$work/stub"; }
good_mean="mean,roiflow,800,800,0.6600,0.7,0.6,1500.00,0.5333,0,0,0,"
bench_csv 8 0.6600 "$good_mean"
expect pass "benchmark gate, good figures" gate
bench_csv 8 0.6600 "mean,roiflow,800,800,nan,0.7,0.6,1500.00,0.5333,0,0,0,"
expect fail "benchmark gate, nan mean AUC" gate
bench_csv 8 0.6600 "mean,roiflow,800,800,,0.7,0.6,1500.00,0.5333,0,0,0,"
expect fail "benchmark gate, empty mean AUC" gate
bench_csv 8 0.6600 "mean,roiflow,800,800,0.6600,0.7,0.6,inf,0.5333,0,0,0,"
expect fail "benchmark gate, infinite fps" gate
bench_csv 8 0.6600 "mean,roiflow,800,800,0.6600,0.7,0.6,-nan,0.5333,0,0,0,"
expect fail "benchmark gate, nan fps" gate
bench_csv 7 0.6600 "mean,roiflow,700,700,0.6600,0.7,0.6,1500.00,0.4667,0,0,0,"
expect fail "benchmark gate, a sequence dropped" gate
bench_csv 8 0.6600 "mean,roiflow,800,800,0.6900,0.7,0.6,1500.00,0.5333,0,0,0,"
expect fail "benchmark gate, mean not the rows' mean" gate
bench_csv 8 0.5000 "mean,roiflow,800,800,0.5000,0.7,0.6,1500.00,0.5333,0,0,0,"
expect fail "benchmark gate, mean AUC under the floor" gate
bench_csv 7 0.6600 "$good_mean" "seq7,csrt,100,100,0.6600,0.7,0.6,40.00,2.5,0,0,0,"
expect fail "benchmark gate, another tracker's row" gate
bench_csv 7 0.6600 "$good_mean" "seq7,roiflow,100,100,0.6600,0.7,0.6,nan,0.0667,0,0,0,"
expect fail "benchmark gate, nan fps in a row" gate
bench_csv 8 0.6600 "$good_mean"
sed -i 1d "$work/benchmark.csv"
expect fail "benchmark gate, no header" gate
rm -f "$work/benchmark.csv"
expect fail "benchmark gate, no CSV written" gate

report "benchmark gate"
