#!/usr/bin/env bash
# scripts/check_private_names.py: passes on a tree whose unity targets keep their file-private
# functions apart, and fails, naming the function, when two CLI files share one or one takes
# a library function's name, and the same in the unity libraries (eval, report, pipeline).
set -euo pipefail
check=$1
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
mkdir -p "$tmp/apps" "$tmp/src/eval"
printf 'namespace {\nint parse(int a) { return a; }\n}  // namespace\n' >"$tmp/apps/a_command.cpp"
printf 'namespace {\nint other(int a) { return a; }\n}  // namespace\n' >"$tmp/apps/b_command.cpp"
printf 'double score(int a);\n' >"$tmp/src/eval/score.hpp"
python3 "$check" "$tmp"
printf 'namespace {\nstd::string parse(const std::string& a) {\n  return a;\n}\n}  // namespace\n' \
  >"$tmp/apps/b_command.cpp"
if out=$(python3 "$check" "$tmp"); then echo "shared private name not found" >&2; exit 1; fi
grep -q "parse is private to several files" <<<"$out"
printf 'namespace {\ndouble score(int a) { return a; }\n}  // namespace\n' >"$tmp/apps/b_command.cpp"
if out=$(python3 "$check" "$tmp"); then echo "library name not found" >&2; exit 1; fi
grep -q "score in apps/b_command.cpp has the name of a public function" <<<"$out"
# The unity libraries too: two pipeline files with one private name.
printf 'namespace {\nint other(int a) { return a; }\n}  // namespace\n' >"$tmp/apps/b_command.cpp"
mkdir -p "$tmp/src/pipeline"
printf 'namespace {\nint wire(int a) { return a; }\n}  // namespace\n' >"$tmp/src/pipeline/a.cpp"
printf 'namespace {\nint wire(double a) { return 1; }\n}  // namespace\n' >"$tmp/src/pipeline/b.cpp"
if out=$(python3 "$check" "$tmp"); then echo "shared private name in a library not found" >&2; exit 1; fi
grep -q "src/pipeline: wire is private to several files" <<<"$out"
echo "private_names_test: pass"
