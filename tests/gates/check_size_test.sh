#!/usr/bin/env bash
# scripts/check_size.sh must fail on each broken limit and pass at the limits: a function of 121
# lines (and one of 120), a file of 701 lines, apps/ of 901 lines in two files, and braces in
# strings and comments that must not open or close a function.
#
#   tests/gates/check_size_test.sh REPO_ROOT
set -euo pipefail
repo=$1
check=$repo/scripts/check_size.sh
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
fail() { echo "check_size_test: $*" >&2; exit 1; }

# A function of `lines` lines in all (header and closing brace included).
function_of() {
  echo "int f$2(int x) {"
  for ((i = 0; i < $1 - 2; ++i)); do echo "  x += $i;  // } not a brace"; done
  echo "}"
}
root() { rm -rf "$work/root"; mkdir -p "$work/root/src" "$work/root/apps"; }
expect() {  # expect STATUS PATTERN
  local out status=0
  out=$("$check" "$work/root") || status=$?
  [[ $status == "$1" ]] || fail "expected exit $1, got $status: $out"
  grep -q -- "$2" <<<"$out" || fail "expected '$2' in: $out"
}

root
function_of 120 a >"$work/root/src/ok.cpp"
{ echo 'const char* s = "{{{ }";'; echo "/* { */"; function_of 50 b; } >>"$work/root/src/ok.cpp"
expect 0 "check_size: ok"

function_of 121 c >"$work/root/src/long.cpp"
expect 1 "src/long.cpp:1: function of 121 lines"

root
for ((i = 0; i < 701; ++i)); do echo "// line $i"; done >"$work/root/src/big.cpp"
expect 1 "src/big.cpp: 701 lines"

root
for f in a b; do for ((i = 0; i < 451; ++i)); do echo "// $f $i"; done >"$work/root/apps/$f.cpp"; done
expect 1 "apps/: 902 lines in all"

root
cat >"$work/root/src/class.hpp" <<'CPP'
namespace n {
class C {
 public:
  int g() const {
    auto l = [](int y) { return y; };
    return l(1);
  }
};
}  // namespace n
CPP
function_of 130 d | sed 's/^/  /' | { echo "struct S {"; cat; echo "};"; } >>"$work/root/src/class.hpp"
expect 1 "src/class.hpp:11: function of 130 lines"
echo "check_size_test: ok"
