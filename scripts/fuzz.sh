#!/usr/bin/env bash
# Builds the libFuzzer targets (the `fuzz` preset: clang-14, ASan + UBSan), writes their seed
# corpus, and runs each target for a bounded time, one after the other.
#
#   scripts/fuzz.sh                 # 60 s per target
#   scripts/fuzz.sh 600 flo_fuzz    # 10 minutes, one target
#
# The corpus grows in build/fuzz/corpus/<target> across runs; the saved crash inputs in
# tests/fuzz_regressions/<name>/ are replayed first. A crash leaves its input in
# build/fuzz/artifacts/<target>/ and the log in build/fuzz/logs/<target>.log; the script then
# goes on with the next target and exits 1 at the end. Copy a crash input to
# tests/fuzz_regressions/<name>/ once it is fixed: the normal test suite replays it.
# FUZZ_JOBS (default: nproc) bounds the build's parallelism, FUZZ_RSS_MB (default 2048) each
# target's memory; FUZZ_NO_BUILD=1 runs the targets as last built.
set -euo pipefail
cd "$(dirname "$0")/.."

seconds=${1:-60}
shift || true
if ! [[ $seconds =~ ^[1-9][0-9]*$ ]]; then
  echo "fuzz: SECONDS must be a positive whole number, got '$seconds'" >&2
  exit 2
fi
all_targets=(flo_fuzz ground_truth_fuzz track_csv_fuzz cli_options_fuzz kitti_flow_fuzz)
targets=("${@:-${all_targets[@]}}")

build=build/fuzz
if [[ -z ${FUZZ_NO_BUILD:-} ]]; then
  cmake --preset fuzz >/dev/null
  cmake --build --preset fuzz -j "${FUZZ_JOBS:-$(nproc)}" --target "${targets[@]}" fuzz_seeds
fi

rm -rf "$build/seeds"
"$build/fuzz/fuzz_seeds" "$build/seeds" >/dev/null

failed=()
printf '%-20s %10s %12s %8s %8s %s\n' target seconds execs exec/s corpus result
for target in "${targets[@]}"; do
  name=${target%_fuzz}
  binary="$build/fuzz/$target"
  if [[ ! -x $binary ]]; then
    echo "fuzz: no target '$target' (have: ${all_targets[*]})" >&2
    exit 2
  fi
  corpus="$build/corpus/$target"
  artifacts="$build/artifacts/$target"
  log="$build/logs/$target.log"
  mkdir -p "$corpus" "$artifacts" "$(dirname "$log")"
  inputs=("$corpus")
  for dir in "$build/seeds/$name" "tests/fuzz_regressions/$name"; do
    [[ -d $dir ]] && inputs+=("$dir")
  done
  options=(-max_total_time="$seconds" -rss_limit_mb="${FUZZ_RSS_MB:-2048}" -timeout=10
           -max_len=4096 -print_final_stats=1 -artifact_prefix="$artifacts/")
  [[ -f fuzz/$name.dict ]] && options+=(-dict="fuzz/$name.dict")

  result=ok
  "$binary" "${options[@]}" "${inputs[@]}" >"$log" 2>&1 || result=CRASH
  if ls "$artifacts" | grep -q .; then result=CRASH; fi
  execs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -1)
  rate=$(sed -n 's/^stat::average_exec_per_sec: *//p' "$log" | tail -1)
  size=$(find "$corpus" -type f | wc -l)
  printf '%-20s %10s %12s %8s %8s %s\n' "$target" "$seconds" "${execs:-?}" "${rate:-?}" "$size" \
    "$result"
  if [[ $result != ok ]]; then
    failed+=("$target")
    grep -m1 -E 'ERROR: |runtime error|terminate called|SUMMARY' "$log" >&2 || true
    echo "  log: $log, input: $(ls -t "$artifacts" | head -1 | sed "s|^|$artifacts/|")" >&2
  fi
done
if ((${#failed[@]})); then
  echo "fuzz: crashes in ${failed[*]}" >&2
  exit 1
fi
