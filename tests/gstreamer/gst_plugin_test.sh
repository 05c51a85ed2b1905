#!/usr/bin/env bash
# The plugin module libgstroiflow.so as GStreamer's own tools load it: gst-inspect-1.0 lists both
# elements with nothing on stderr (also at GST_DEBUG=2, warnings), gst-launch-1.0 runs them, and a
# bad property ends gst-launch with an error naming it.
#
#   tests/gstreamer/gst_plugin_test.sh build/release/gstreamer build/release/roiflow
set -euo pipefail
plugin_dir=$1
roiflow=$2
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
export GST_PLUGIN_PATH=$plugin_dir GST_REGISTRY=$tmp/registry.bin
fail() { echo "gst_plugin_test: $*" >&2; exit 1; }

[[ -f $plugin_dir/libgstroiflow.so ]] || fail "no libgstroiflow.so in $plugin_dir"
for element in roiflowtrack roiflowflow; do
  gst-inspect-1.0 "$element" >"$tmp/out" 2>"$tmp/err" || fail "gst-inspect-1.0 $element failed: $(cat "$tmp/err")"
  [[ ! -s $tmp/err ]] || fail "gst-inspect-1.0 $element wrote to stderr: $(cat "$tmp/err")"
  grep -q "Factory Details" "$tmp/out" || fail "gst-inspect-1.0 $element: no factory details"
  GST_DEBUG=2 gst-inspect-1.0 "$element" >/dev/null 2>"$tmp/err" || fail "GST_DEBUG=2 gst-inspect-1.0 $element failed"
  if grep -iE "roiflow|critical" "$tmp/err"; then
    fail "gst-inspect-1.0 $element: warnings at GST_DEBUG=2"
  fi
done
grep -q "max-lost" < <(gst-inspect-1.0 roiflowtrack) || fail "roiflowtrack has no max-lost property"
plugin=$(gst-inspect-1.0 roiflow 2>&1)
grep -q "roiflowtrack" <<<"$plugin" && grep -q "roiflowflow" <<<"$plugin" ||
  fail "the plugin does not list both elements: $plugin"

# Both elements in one gst-launch pipeline; the log has a line per frame and a header.
gst-launch-1.0 -q videotestsrc num-buffers=20 pattern=ball \
  ! video/x-raw,format=I420,width=160,height=120 ! roiflowtrack log="$tmp/t.csv" \
  ! roiflowflow ! videoconvert ! fakesink >"$tmp/out" 2>"$tmp/err" ||
  fail "gst-launch-1.0 failed: $(cat "$tmp/err")"
lines=$(wc -l <"$tmp/t.csv")
[[ $lines == 21 ]] || fail "track log has $lines lines, expected 21"
[[ $(head -1 "$tmp/t.csv") == "frame,id,x,y,w,h,vx,vy,mode,lost,ms" ]] || fail "track log header"

# A bad property: gst-launch fails and says why.
if gst-launch-1.0 -q videotestsrc num-buffers=2 ! video/x-raw,format=GRAY8 \
  ! roiflowtrack init=1,2,3 ! fakesink >"$tmp/out" 2>&1; then
  fail "gst-launch-1.0 accepted init=1,2,3"
fi
grep -q "init: expected boxes x,y,w,h" "$tmp/out" || fail "no error about init: $(cat "$tmp/out")"
"$roiflow" --help >/dev/null
echo "gst_plugin_test: ok"
