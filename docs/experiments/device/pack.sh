#!/usr/bin/env bash
# pack.sh BUILD_DIR OUT_TGZ BIN... : binaries + their shared-library closure (big unused subtrees stubbed)
# Run on this (Debian 12) machine; on the lent machine: tar xzf OUT, then
#   p/lib/ld-linux-x86-64.so.2 --inhibit-cache --library-path p/lib p/bin/roiflow ...
# (run.sh is the script of session 9's two runs). The stubs (stubs.txt) stand for libraries that
# OpenCV and FFmpeg link but these binaries never call (GDAL, codecs' encoders, network
# protocols): each exports the original's symbols and versions, doing nothing, so that the
# closure fits the 64 MiB the device tool carries. Build with -DROIFLOW_NATIVE=OFF.
set -euo pipefail
export HERE=$(cd "$(dirname "$0")" && pwd)
build=$1; out=$2; shift 2
stage=$(mktemp -d); mkdir -p $stage/p/bin $stage/p/lib
S=$(cat "$HERE/stubs.txt")
for b in "$@"; do cp "$build/$b" $stage/p/bin/; done
cd $stage/p/bin
python3 - "$S" "$@" <<'PY'
import subprocess, sys, os, re, shutil
def needed(path):
    out = subprocess.run(['readelf','-d',path],capture_output=True,text=True).stdout
    return re.findall(r'\(NEEDED\).*\[(.+?)\]', out)
ldmap = {}
for line in subprocess.run(['ldconfig','-p'],capture_output=True,text=True).stdout.splitlines()[1:]:
    m = re.match(r'\s*(\S+) \((.*?)\) => (\S+)', line)
    if m and 'x86-64' in m.group(2): ldmap.setdefault(m.group(1), m.group(3))
stubs = set(sys.argv[1].split(','))
seen=set(); stack=[os.path.basename(b) for b in sys.argv[2:]]
while stack:
    p = stack.pop()
    for n in needed(p):
        if n in seen: continue
        seen.add(n)
        if n in stubs:
            c='../lib/'+n
            subprocess.run(['python3',os.environ['HERE']+'/mkstub.py',os.path.realpath(ldmap[n]),c,n],check=True); os.remove(c+'.c'); os.path.exists(c+'.map') and os.remove(c+'.map')
            continue
        src = ldmap[n]
        shutil.copy(os.path.realpath(src), '../lib/'+n)
        stack.append('../lib/'+n)
PY
cp /lib64/ld-linux-x86-64.so.2 ../lib/
cd $stage && tar -czf "$out" p && rm -rf $stage
ls -la "$out"
