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
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
failures=0

expect() {  # expect pass|fail DESCRIPTION COMMAND...
  local want=$1 what=$2
  shift 2
  if "$@" >"$work/out.txt" 2>&1; then got=pass; else got=fail; fi
  if [[ $got != "$want" ]]; then
    echo "FAILED: $what: expected $want, got $got"
    sed 's/^/  | /' "$work/out.txt"
    failures=$((failures + 1))
  else
    echo "ok: $what ($got: $(tail -n 1 "$work/out.txt"))"
  fi
}

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
pred() {  # pred MISSED
  : >"$work/case/mot.txt"
  for ((f = 1; f <= 10; ++f)); do
    echo "$f,7,10,10,20,20,1,-1,-1,-1" >>"$work/case/mot.txt"
    ((f <= $1)) || echo "$f,8,100,10,20,20,1,-1,-1,-1" >>"$work/case/mot.txt"
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
# Object 2 missed in 3 of 10 frames: MOTA 1 - 3/20 = 0.85, IDF1 2*17/(20+17) = 0.9189.
pred 3
summary 0.85 0.918918918918919
expect fail "mot demo gate, MOTA below its floor" gate
rm "$work/case/gt_mot.txt"
pred 0
summary 1.0 1.0
expect fail "mot demo gate, gt_mot.txt missing" gate
gt
: >"$work/case/mot.txt"
expect fail "mot demo gate, empty mot.txt" gate

if ((failures > 0)); then
  echo "$failures mot demo gate check(s) failed"
  exit 1
fi
echo "all mot demo gate checks passed"
