# Sourced by the gate scripts' tests: a scratch folder $work (removed on exit), `expect` to run
# one case and count a wrong outcome, and `report NAME` to print the tally and exit.
#
#   source "$(dirname "$0")/expect_lib.sh"
#   expect fail "gate, NaN mean" some_gate_command
#   report "benchmark gate"    # "all benchmark gate checks passed", or exit 1
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

report() {  # report NAME
  if ((failures > 0)); then
    echo "$failures $1 check(s) failed"
    exit 1
  fi
  echo "all $1 checks passed"
}
