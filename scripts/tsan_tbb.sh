#!/usr/bin/env bash
# Builds Debian's own oneTBB (the source package of the installed libtbb-dev, with Debian's
# patches) with ThreadSanitizer, into build/tbb-tsan/install, for the tsan preset.
#
#   scripts/tsan_tbb.sh        # idempotent: does nothing when the install is already there
#
# Why: Debian's libtbb is not instrumented, so TSan cannot see the hand-overs inside oneTBB's
# scheduler and reports every message that crosses a thread as a race. Suppressing libtbb
# would also hide real races in our node bodies; an instrumented oneTBB makes the tsan run
# exact. The result is used only by the tsan preset (CMakePresets.json sets TBB_DIR).
# Needs deb-src access to the machine's Debian mirror (the same one apt-get install uses).
set -euo pipefail
cd "$(dirname "$0")/.."
root=$PWD/build/tbb-tsan
prefix=$root/install
if [[ -f $prefix/lib/cmake/TBB/TBBConfig.cmake && -f $root/.done ]]; then
  echo "tsan_tbb: $prefix already built"
  exit 0
fi

command -v dpkg-source >/dev/null || { echo "tsan_tbb: needs dpkg-source (scripts/deps.sh)" >&2; exit 1; }
version=$(dpkg-query -W -f='${source:Version}' libtbb-dev)
echo "tsan_tbb: building oneTBB $version (Debian source package onetbb) with -fsanitize=thread"

# A private source list, so that the machine's apt configuration is left as it is: the
# machine's own Debian entries for this release, as source (deb-src) entries.
rm -rf "$root/src" "$root/apt"
mkdir -p "$root/src" "$root/apt/lists/partial" "$root/apt/archives/partial" "$root/apt/sources.list.d"
suite=$(. /etc/os-release && echo "${VERSION_CODENAME}")
: >"$root/apt/sources.list"
for list in /etc/apt/sources.list /etc/apt/sources.list.d/*.list; do
  if [[ -f $list ]]; then
    sed -n "s/^deb \(.* $suite[ -].*\)/deb-src \1/p" "$list" >>"$root/apt/sources.list"
  fi
done
for sources in /etc/apt/sources.list.d/*.sources; do
  if [[ -f $sources ]] && grep -q "^Suites:.*\b$suite\b" "$sources"; then
    sed 's/^Types:.*/Types: deb-src/' "$sources" >"$root/apt/sources.list.d/$(basename "$sources")"
  fi
done
apt_opts=(-o "Dir::Etc::SourceList=$root/apt/sources.list" -o "Dir::Etc::SourceParts=$root/apt/sources.list.d"
  -o "Dir::State::Lists=$root/apt/lists" -o "Dir::Cache::Archives=$root/apt/archives"
  -o "APT::Sandbox::User=root")
apt-get "${apt_opts[@]}" update -q >/dev/null
(cd "$root/src" && apt-get "${apt_opts[@]}" source -q "onetbb=$version" >/dev/null)
srcdir=$(find "$root/src" -maxdepth 1 -mindepth 1 -type d -name 'onetbb*' | head -n 1)
[[ -n $srcdir ]] || { echo "tsan_tbb: no onetbb source unpacked in $root/src" >&2; exit 1; }

cmake -S "$srcdir" -B "$root/build" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DCMAKE_INSTALL_PREFIX="$prefix" -DTBB_SANITIZE=thread -DTBB_TEST=OFF -DTBB_EXAMPLES=OFF \
  -DTBB_STRICT=OFF -DTBBMALLOC_BUILD=OFF -DTBB_ENABLE_IPO=OFF >/dev/null
cmake --build "$root/build" -j"$(nproc)" >/dev/null
cmake --install "$root/build" >/dev/null
touch "$root/.done"
echo "tsan_tbb: installed in $prefix"
