#!/usr/bin/env bash
# One device run: 1-16 thread scaling of roiflow (portable build + its libraries, packed by /tmp/devpack/pack.sh)
set -uo pipefail
R=$PWD; cd /tmp && tar xzf $R/devpack/p.tgz
L="p/lib/ld-linux-x86-64.so.2 --inhibit-cache --library-path p/lib"
q() { grep -v 'no version information'; }
log=$OUT/log.txt
{
echo "== machine"; nproc; lscpu | grep -E 'Model name|Socket|Core|Thread|NUMA node|L2|L3|Flags' | cut -c1-200; free -g | head -2; date -u
for spec in "local 300:640x480:16 local640" "local 300:1280x720:64 local720" "dense 300:1280x720:1 dense720" "global 200:640x480:4 global640"; do
  set -- $spec
  echo "== scaling $1 synthetic:$2"
  t0=$(date +%s); $L p/bin/roiflow scaling synthetic:$2 --threads 1,2,4,8,16 --mode $1 --repeat 2 --out /tmp/$3 2>&1 | q; echo "($(( $(date +%s) - t0 )) s)"
  cp /tmp/$3/scaling.csv $OUT/$3.csv; [ "$3" = local720 -o "$3" = dense720 ] && cp /tmp/$3/scaling.svg $OUT/$3.svg
done
echo "== mot_bench"; $L p/bin/mot_bench --benchmark_filter='BM_TrackObjects/(16|64)/1280x720' 2>&1 | q
echo "== flow_bench 1 thread"; $L p/bin/flow_bench --benchmark_filter='BM_Flow/(roiflow_paper|roiflow_fast|dis_ultrafast)/640x480/threads:1' --benchmark_repetitions=5 --benchmark_report_aggregates_only=true 2>&1 | q | grep -E 'median|Benchmark'
echo "== flow_bench two-thread bound"; $L p/bin/flow_bench --benchmark_filter='BM_TwoThreadBound|BM_Flow/roiflow_paper/640x480/threads:2' 2>&1 | q | tail -n 6
echo "== pipeline_bench: main and the build at issue 17's filing (d5de529), in turn"
for r in 1 2 3; do for b in pipeline_bench_base pipeline_bench; do echo -n "$b: "; $L p/bin/$b --benchmark_filter='BM_TrackVsDecode' 2>&1 | q | grep -o 'decode_fps=[0-9.k]* .*track_fps=[0-9.k]* vs_decode=[0-9.]*'; done; done
for b in pipeline_bench_base pipeline_bench; do echo "$b: "; $L p/bin/$b --benchmark_filter='BM_TrackerOnly' 2>&1 | q | grep median; done
date -u
} 2>&1 | tee $log
