#!/usr/bin/env bash
# The real-data gates fail when they should: a stub `roiflow` feeds them bad figures (an empty
# or NaN mean row, a dropped sequence, a mean that is not the rows' mean, a truncated track log)
# and each must make its gate exit non-zero; the same stub with good figures must pass, so a
# failure is the bad row's doing. scripts/test.sh under CI=true without the data must fail.
#
#   tests/gates/gate_scripts_test.sh REPO_DIR ROIFLOW_BINARY
set -uo pipefail
repo=$1
real_bin=$2
source "$(dirname "$0")/expect_lib.sh"

# --- eval_gate.sh: a stub whose `eval DIR` prints $work/eval_<folder of DIR>.csv; the cases
# below spoil middlebury's, the other datasets keep good figures.
data="$work/data"
mkdir -p "$data/middlebury" "$data/kitti" "$data/sintel" "$data/flyingchairs" "$work/stub"
cat >"$work/stub/roiflow" <<STUB
#!/usr/bin/env bash
if [[ \$1 == eval ]]; then cat "$work/eval_\$(basename "\$2").csv"; exit 0; fi
if [[ \$1 == motion-check ]]; then
  log="$work/motion_\$(basename "\$3" .csv).json"  # a log's own answer, else its video's
  [[ -f \$log ]] || log="$work/motion_\$(basename "\$2").json"
  cat "\$log"
  exit "\$(cat "$work/motion.rc")"
fi
if [[ \$1 == track ]]; then
  while [[ \$# -gt 0 ]]; do
    case \$1 in
      --log) cp "$work/track.csv" "\$2"; shift ;;
      --summary) echo '{"tracker_fps": 1000.0}' >"\$2"; shift ;;
      --mot) cp "$work/mot.txt" "\$2"; shift ;;
    esac
    shift
  done
  exit 0
fi
exec "$real_bin" "\$@"
STUB
chmod +x "$work/stub/roiflow"

dataset_csv() {  # dataset_csv FOLDER ROWS AAE EPE: every row and the mean alike
  {
    echo "sequence,aae_deg,epe,r1,r3,ms"
    for ((i = 0; i < $2; ++i)); do echo "seq$i,$3,$4,1.0,1.0,10.0"; done
    echo "mean,$3,$4,1.0,1.0,10.0"
  } >"$work/eval_$1.csv"
}
dataset_csv kitti 2 15.000 10.0000
dataset_csv sintel 4 15.000 10.0000
dataset_csv flyingchairs 6 10.000 3.0000
eval_csv() {  # eval_csv ROWS MEAN_ROW [ROW_EPE]: middlebury's
  {
    echo "sequence,aae_deg,epe,r1,r3,ms"
    for ((i = 0; i < $1; ++i)); do echo "seq$i,5.000,${3:-0.3500},1.0,1.0,10.0"; done
    echo "$2"
  } >"$work/eval_middlebury.csv"
}
gate() { "$repo/scripts/eval_gate.sh" "$data" "$work/stub"; }
eval_csv 8 "mean,5.000,0.3500,1.0,1.0,10.0"
expect pass "eval gate, good figures" gate
eval_csv 8 "mean,,,,,"
expect fail "eval gate, empty mean row" gate
eval_csv 8 "mean,nan,nan,nan,nan,nan"
expect fail "eval gate, nan mean row" gate
eval_csv 8 "mean,-nan,-nan,1.0,1.0,10.0"
expect fail "eval gate, -nan mean row" gate
eval_csv 7 "mean,5.000,0.3500,1.0,1.0,10.0"
expect fail "eval gate, a sequence dropped" gate
eval_csv 8 "mean,5.000,0.3000,1.0,1.0,10.0"
expect fail "eval gate, mean not the rows' mean" gate
eval_csv 8 "mean,5.000,0.9000,1.0,1.0,10.0" 0.9000
expect fail "eval gate, EPE above its gate" gate
{
  echo "sequence,aae_deg,epe,r1,r3,ms"
  for ((i = 0; i < 7; ++i)); do echo "seq$i,5.000,0.3500,1.0,1.0,10.0"; done
  echo "seq7,inf,0.3500,1.0,1.0,10.0"
  echo "mean,5.000,0.3500,1.0,1.0,10.0"
} >"$work/eval_middlebury.csv"
expect fail "eval gate, inf in a row" gate
rm -rf "$data/middlebury"
eval_csv 8 "mean,5.000,0.3500,1.0,1.0,10.0"
expect fail "eval gate, dataset folder missing" gate
mkdir -p "$data/middlebury"
dataset_csv sintel 3 15.000 10.0000  # a Sintel pair dropped
expect fail "eval gate, a Sintel pair dropped" gate
dataset_csv sintel 4 15.000 12.5000  # above accurate's gate
expect fail "eval gate, Sintel EPE above its gate" gate
dataset_csv sintel 4 15.000 10.0000

# --- track_gate.sh: the stub writes $work/track.csv as the log; `score` is the real roiflow.
seq="$work/seq"
mkdir -p "$seq"
: >"$seq/groundtruth_rect.txt"
for ((i = 1; i <= 20; ++i)); do echo "10,20,30,40" >>"$seq/groundtruth_rect.txt"; done
track_csv() {  # track_csv ROWS
  echo "frame,x,y,w,h,vx,vy,mode,lost,ms" >"$work/track.csv"
  for ((i = 1; i <= $1; ++i)); do echo "$i,10,20,30,40,0,0,local,0,0.1" >>"$work/track.csv"; done
}
tgate() { "$repo/scripts/track_gate.sh" "$seq" "$work/stub"; }
track_csv 20
expect pass "track gate, a full log" tgate
track_csv 12
expect fail "track gate, a truncated log" tgate
sed -i '5s/.*/NaN,NaN,NaN,NaN/' "$seq/groundtruth_rect.txt"
track_csv 20
expect pass "track gate, an absent-target frame is not scored" tgate
track_csv 19
expect fail "track gate, one frame short with an absent-target frame" tgate

# --- mot_gate.sh: the stub writes $work/mot.txt as the --mot output and prints
# $work/motion_<video>.json for motion-check; `score --mot` is the real roiflow, against a
# made-up ground truth of 795 frames and 19 people.
mdata="$work/mdata"
mkdir -p "$mdata/video" "$mdata/mot/PETS09-S2L1/gt"
: >"$mdata/video/opencv_vtest.avi"
: >"$mdata/video/bgslibrary_video02.avi"
mgt="$mdata/mot/PETS09-S2L1/gt/gt.txt"
for ((f = 1; f <= 795; ++f)); do
  echo "$f,$((f % 19 + 1)),$((10 + f % 50)),20,30,80,1,1,1"
  if ((f <= 771)); then  # 795 + 771 x 5 = 4650 boxes, as PETS09-S2L1's
    for ((k = 1; k <= 5; ++k)); do echo "$f,$(((f + k) % 19 + 1)),$((100 + 60 * k)),200,30,80,1,1,1"; done
  fi
done >"$mgt"
motion_json() {  # motion_json VIDEO FRAMES LONGEST RC (RC: the stub's exit code for every video)
  printf '{\n  "frames": %s,\n  "objects": 3,\n  "longest_run": %s,\n  "violations": []\n}\n' \
    "$2" "$3" >"$work/motion_$1.json"
  echo "$4" >"$work/motion.rc"
}
mgate() { "$repo/scripts/mot_gate.sh" "$mdata" "$work/stub"; }
cut -d, -f1-6 "$mgt" | sed 's/$/,1,-1,-1,-1/' >"$work/mot.txt"
track_csv 20
motion_json opencv_vtest.avi 795 3 0
motion_json bgslibrary_video02.avi 748 3 0
expect pass "mot gate, tracker output equal to the ground truth" mgate
sed -i '100s/.*/100,5,nan,20,30,80,1,-1,-1,-1/' "$work/mot.txt"
expect fail "mot gate, a NaN row in the MOT output" mgate
head -n 400 "$mgt" | cut -d, -f1-6 | sed 's/$/,1,-1,-1,-1/' >"$work/mot.txt"
expect fail "mot gate, half the frames missing (MOTA below the floor)" mgate
cut -d, -f1-6 "$mgt" | sed 's/$/,1,-1,-1,-1/' >"$work/mot.txt"
motion_json bgslibrary_video02.avi 700 3 0
expect fail "mot gate, motion check read too few frames" mgate
motion_json bgslibrary_video02.avi 748 nan 0
expect fail "mot gate, motion check longest run nan" mgate
motion_json bgslibrary_video02.avi 748 3 0
motion_json opencv_vtest.avi 795 45 1
expect fail "mot gate, an object found on empty background for 45 frames" mgate
motion_json opencv_vtest.avi 795 45 0
expect fail "mot gate, a 45-frame run even with exit 0" mgate
motion_json opencv_vtest.avi 795 3 0
motion_json highway_single 748 379 0
expect fail "mot gate, the --single run on the highway holds a collapsed box for 379 frames" mgate
rm "$work/motion_highway_single.json"
motion_json vtest_single 795 nan 0
expect fail "mot gate, the --single run's longest run nan" mgate
rm "$work/motion_vtest_single.json"
head -n 700 "$mgt" >"$work/gt_short.txt" && cp "$mgt" "$work/gt_full.txt" && cp "$work/gt_short.txt" "$mgt"
expect fail "mot gate, ground truth of 700 frames" mgate
cp "$work/gt_full.txt" "$mgt"
expect pass "mot gate, good again" mgate

# --- dropin_gate.sh: a stub roiflow (track copies $work/dcli.csv to --log; batch prints
# $work/batch<N>.txt and writes $work/batch.csv into --out) and a stub gst-launch-1.0 (copies
# $work/dgst.csv to log=); `score` is the real roiflow.
ddata="$work/ddata"
mkdir -p "$ddata/video" "$work/dstub"
: >"$ddata/video/opencv_vtest.avi"
cat >"$work/dstub/roiflow" <<STUB
#!/usr/bin/env bash
case \$1 in
  track)
    while [[ \$# -gt 0 ]]; do [[ \$1 == --log ]] && cp "$work/dcli.csv" "\$2"; shift; done
    exit 0 ;;
  batch)
    while [[ \$# -gt 0 ]]; do [[ \$1 == --out ]] && out=\$2; shift; done
    n=\$(cat "$work/batch_runs" 2>/dev/null || echo 0); n=\$((n + 1)); echo \$n >"$work/batch_runs"
    mkdir -p "\$out/clip_a" "\$out/clip_b"
    cp "$work/dbatch.csv" "\$out/batch.csv"
    cp "$work/dlog.csv" "\$out/clip_a/track.csv"; cp "$work/dlog.csv" "\$out/clip_b/track.csv"
    cat "$work/batch\$n.txt"; exit 0 ;;
esac
exec "$real_bin" "\$@"
STUB
cat >"$work/dstub/gst-launch-1.0" <<STUB
#!/usr/bin/env bash
for a in "\$@"; do [[ \$a == log=* ]] && cp "$work/dgst.csv" "\${a#log=}"; done
exit 0
STUB
chmod +x "$work/dstub/roiflow" "$work/dstub/gst-launch-1.0"
dlog() {  # dlog FILE ROWS [ROW_TO_SHIFT]
  echo "frame,x,y,w,h,vx,vy,mode,lost,ms" >"$1"
  for ((i = 1; i <= $2; ++i)); do
    x=$((10 + i % 50))
    [[ $i == "${3:-0}" ]] && x=400
    echo "$i,$x,20,30,40,0,0,local,0,0.$((i % 7))" >>"$1"
  done
}
dbatch() {  # dbatch FPS_OF_B
  printf 'video,status,frames,fps,seconds\nv/clip_a.avi,done,750,500.0,1.5\nv/clip_b.avi,done,750,%s,1.5\n' "$1" >"$work/dbatch.csv"
}
dreset() {
  rm -f "$work/batch_runs"
  dlog "$work/dcli.csv" 795
  dlog "$work/dgst.csv" 795
  dlog "$work/dlog.csv" 750
  dbatch 400.0
  echo "batch: 2 videos: 2 run, 0 already done, 0 failed; wrote x" >"$work/batch1.txt"
  echo "batch: 2 videos: 0 run, 2 already done, 0 failed; wrote x" >"$work/batch2.txt"
}
dgate() { GST_LAUNCH="$work/dstub/gst-launch-1.0" "$repo/scripts/dropin_gate.sh" "$ddata" "$work/dstub"; }
dreset
expect pass "dropin gate, good figures" dgate
dreset; dlog "$work/dgst.csv" 795 300
expect fail "dropin gate, the element's log differs in one row" dgate
dreset; dlog "$work/dgst.csv" 790
expect fail "dropin gate, the element's log is short" dgate
dreset; echo "batch: 2 videos: 1 run, 1 already done, 0 failed; wrote x" >"$work/batch2.txt"
expect fail "dropin gate, the second batch run did work" dgate
dreset; dbatch nan
expect fail "dropin gate, nan fps in batch.csv" dgate
dreset; dlog "$work/dlog.csv" 749
expect fail "dropin gate, a track log one row short of batch.csv" dgate

# --- test.sh under CI without the data: a copy of scripts/ with no ../shared/data beside it,
# and a build step that does nothing (the suite itself is not what is checked here).
ci="$work/ci/repo"
mkdir -p "$ci/scripts"
cp "$repo"/scripts/*.sh "$ci/scripts/"
printf '#!/usr/bin/env bash\nexit 0\n' >"$ci/scripts/build.sh"
mkdir -p "$work/ci/bin"
printf '#!/usr/bin/env bash\nexit 0\n' >"$work/ci/bin/ctest"
chmod +x "$ci"/scripts/*.sh "$work/ci/bin/ctest"
expect fail "test.sh, CI=true without ../shared/data" env PATH="$work/ci/bin:$PATH" CI=true "$ci/scripts/test.sh"
expect pass "test.sh, no CI and no data: a warning" env PATH="$work/ci/bin:$PATH" CI= "$ci/scripts/test.sh"

report "gate"
