#!/usr/bin/env bash
# Strict checks shared by the real-data gates (sourced, not run). A gate fails on a figure that
# is missing, not a finite decimal number (nan, inf, empty), or on a count of sequences, pairs or
# frames other than expected: a figure that cannot be read never passes.
#
#   source "$(dirname "$0")/gate_lib.sh"
#   gate_number "mean EPE" "$epe"            # exits 1 unless $epe is a finite number
#   gate_count "sequences" "$rows" 8         # exits 1 unless $rows == 8
#   if gate_holds "$epe" '<=' 0.88; then ...

gate_fail() {
  echo "gate: FAIL: $*" >&2
  exit 1
}

# A finite decimal number: digits with an optional sign, point and exponent. Rejects the empty
# string, nan, inf, and anything with trailing text.
gate_number() {
  local name=$1 value=$2
  [[ $value =~ ^[-+]?([0-9]+\.?[0-9]*|\.[0-9]+)([eE][-+]?[0-9]+)?$ ]] ||
    gate_fail "$name is not a finite number: '$value'"
}

gate_count() {
  local name=$1 value=$2 expected=$3
  [[ $value =~ ^[0-9]+$ ]] || gate_fail "$name is not a count: '$value'"
  ((value == expected)) || gate_fail "$name: $value, expected $expected"
}

# gate_holds VALUE OP LIMIT with OP one of <= >= < >; both numbers already checked.
gate_holds() {
  awk -v v="$1" -v op="$2" -v l="$3" 'BEGIN {
    if (op == "<=") exit !(v + 0 <= l + 0)
    if (op == ">=") exit !(v + 0 >= l + 0)
    if (op == "<") exit !(v + 0 < l + 0)
    if (op == ">") exit !(v + 0 > l + 0)
    exit 2
  }'
}

# gate_json_number JSON KEY: the number a flat JSON object holds under "KEY" (empty when absent;
# check it with gate_number).
gate_json_number() {
  sed -n "s/.*\"$2\": *\\([^,}]*\\).*/\\1/p" <<<"$1" | head -n 1 | tr -d ' "'
}
