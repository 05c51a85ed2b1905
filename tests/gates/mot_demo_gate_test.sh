#!/usr/bin/env bash
# scripts/mot_demo_gate.sh fails when it should: a stub `roiflow demo` writes a summary and
# MOTChallenge files chosen by each case (NaN or missing figures, a missing file, figures below
# the floor, a summary that its own files contradict); `score` is the real roiflow. The same
# stub with good figures must pass, so each failure is the bad row's doing.
#
#   tests/gates/mot_demo_gate_test.sh REPO_DIR ROIFLOW_BINARY
set -uo pipefail
repo=$1
real_bin=$2
source "$(dirname "$0")/expect_lib.sh"

# The stub's demo copies $work/case/* into --dir.
mkdir -p "$work/stub" "$work/case"
cat >"$work/stub/roiflow" <<STUB
#!/usr/bin/env bash
if [[ \$1 == demo ]]; then
  while [[ \$# -gt 0 ]]; do
    if [[ \$1 == --dir ]]; then mkdir -p "\$2" && cp "$work"/case/* "\$2"/; fi
    shift
  done
  exit 0
fi
exec "$real_bin" "\$@"
STUB
chmod +x "$work/stub/roiflow"

# Ground truth: 2 objects x 10 frames. Tracker output: the same, or object 2 missed in
# frames 1..MISSED.
gt() {
  : >"$work/case/gt_mot.txt"
  for ((f = 1; f <= 10; ++f)); do
    echo "$f,1,10,10,20,20,1,-1,-1,-1" >>"$work/case/gt_mot.txt"
    echo "$f,2,100,10,20,20,1,-1,-1,-1" >>"$work/case/gt_mot.txt"
  done
}
pred() {  # pred MISSED [STRAYS]: object 2 missed in frames 1..MISSED, STRAYS stray boxes a frame
  : >"$work/case/mot.txt"
  for ((f = 1; f <= 10; ++f)); do
    echo "$f,7,10,10,20,20,1,-1,-1,-1" >>"$work/case/mot.txt"
    ((f <= $1)) || echo "$f,8,100,10,20,20,1,-1,-1,-1" >>"$work/case/mot.txt"
    for ((k = 0; k < ${2:-0}; ++k)); do
      echo "$f,$((20 + k)),$((300 + 40 * k)),300,20,20,1,-1,-1,-1" >>"$work/case/mot.txt"
    done
  done
}
summary() { printf '{\n  "frames": 10,\n  "mota": %s,\n  "idf1": %s\n}\n' "$1" "$2" >"$work/case/summary.json"; }
gate() { "$repo/scripts/mot_demo_gate.sh" "$work/stub"; }

gt
pred 0
summary 1.0 1.0
expect pass "mot demo gate, good figures" gate
summary nan 1.0
expect fail "mot demo gate, nan mota" gate
summary 1.0 '""'
expect fail "mot demo gate, empty idf1" gate
printf '{"frames": 10, "mota": 1.0}\n' >"$work/case/summary.json"
expect fail "mot demo gate, idf1 missing" gate
summary 0.95 1.0
expect fail "mot demo gate, summary mota not what its files score" gate
# Object 2 missed in all 10 frames and 4 stray boxes a frame: MOTA 1 - (10 + 40)/20 = -1.5,
# IDF1 2*10/(20+50) = 0.2857: below the MOTA floor.
pred 10 4
summary -1.5 0.285714285714286
expect fail "mot demo gate, MOTA below its floor" gate
# Everything missed but object 1 in frame 1: IDF1 2*1/(20+1) = 0.095, below its floor.
printf '1,7,10,10,20,20,1,-1,-1,-1\n' >"$work/case/mot.txt"
summary 0.05 0.0952380952380952
expect fail "mot demo gate, IDF1 below its floor" gate
rm "$work/case/gt_mot.txt"
pred 0
summary 1.0 1.0
expect fail "mot demo gate, gt_mot.txt missing" gate
gt
: >"$work/case/mot.txt"
expect fail "mot demo gate, empty mot.txt" gate

report "mot demo gate"
