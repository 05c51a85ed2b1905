#!/usr/bin/env bash
# Soak: `roiflow track` over a synthetic stream of N frames for each N given (the whole
# pipeline: source, decode node, pyramid pool, tracker, log and summary sinks), then checks that
# the log holds exactly frames 1..N in order and that peak resident memory stays flat:
# fails when the peak at the largest N exceeds 1.2 x the peak at the smallest.
#
#   scripts/soak.sh                      # N = 1000 10000 100000
#   scripts/soak.sh 500 5000             # other lengths
#   SIZE=640x480 THREADS=4 BUILD=build/release scripts/soak.sh
#   OBJECTS=16 scripts/soak.sh 1000 10000   # the multi-object tracker on 16 vehicles
#
# Each N is a fresh process, so its peak is that run's own. 100000 frames at 320x240 take a few
# minutes on 2 cores.
set -euo pipefail
cd "$(dirname "$0")/.."
bin=${BUILD:-build/release}/roiflow
size=${SIZE:-320x240}
threads=${THREADS:-2}
objects=${OBJECTS:-0}  # 0: the single-object tracker (--single) on one vehicle
max_ratio=1.2
if [ $# -eq 0 ]; then set -- 1000 10000 100000; fi
[ -x "$bin" ] || { echo "soak: no $bin (build first, or set BUILD=dir)" >&2; exit 1; }
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

json_number() {  # json_number KEY FILE: the first number after "KEY":
  sed -n "s/.*\"$1\": *\([0-9.eE+-]*\).*/\1/p" "$2" | head -n 1
}

status=0
first_peak=""
first_n=""
last_peak=""
last_n=""
printf '%10s %10s %14s %10s %8s\n' N frames "peak RSS MiB" fps log
for n in "$@"; do
  log="$work/track_$n.csv"
  summary="$work/summary_$n.json"
  if [ "$objects" -gt 0 ]; then
    "$bin" track "synthetic:$n:$size:$objects" --threads "$threads" --no-progress --log "$log" \
      --summary "$summary" >/dev/null
  else
    "$bin" track "synthetic:$n:$size" --single --threads "$threads" --no-progress --log "$log" \
      --summary "$summary" >/dev/null
  fi
  frames=$(json_number frames "$summary")
  peak=$(json_number peak_rss_mb "$summary")
  fps=$(sed -n 's/^  "fps": *\([0-9.eE+-]*\).*/\1/p' "$summary")
  # Exactly frames 1..n, in order, one line each (after the header); with objects, one line
  # per object and frame: frames never go back and stay within 1..n.
  if [ "$objects" -gt 0 ]; then
    order=$(awk -F, -v n="$n" 'NR > 1 { if ($1 < last || $1 < 1 || $1 > n) bad = 1; last = $1 }
                                END { print bad ? "BAD" : "ok" }' "$log")
  else
    order=$(awk -F, -v n="$n" 'NR > 1 { if ($1 != NR - 1) bad = 1; count++ }
                                END { print (bad || count != n) ? "BAD" : "ok" }' "$log")
  fi
  if [ "$frames" != "$n" ] || [ "$order" != ok ]; then status=1; fi
  printf '%10s %10s %14.1f %10.1f %8s\n' "$n" "$frames" "$peak" "$fps" "$order"
  if [ -z "$first_n" ] || [ "$n" -lt "$first_n" ]; then first_n=$n; first_peak=$peak; fi
  if [ -z "$last_n" ] || [ "$n" -gt "$last_n" ]; then last_n=$n; last_peak=$peak; fi
done
ratio=$(awk -v a="$last_peak" -v b="$first_peak" 'BEGIN { printf "%.3f", a / b }')
verdict=pass
if awk -v r="$ratio" -v m="$max_ratio" 'BEGIN { exit !(r > m) }'; then verdict=FAIL; status=1; fi
[ "$status" -eq 0 ] || verdict=FAIL
printf 'soak %s: peak at %s frames / peak at %s frames = %s (max %s)  %s\n' "$size" "$last_n" \
  "$first_n" "$ratio" "$max_ratio" "$verdict"
exit $status
