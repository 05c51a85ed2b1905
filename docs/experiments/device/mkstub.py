# mkstub.py ORIG_LIB OUT SONAME: a library exporting every dynamic symbol (with versions) ORIG_LIB exports, doing nothing
import subprocess, sys, collections
orig, out, soname = sys.argv[1:4]
lines = subprocess.run(['nm','-D','-S','--defined-only',orig],capture_output=True,text=True).stdout.splitlines()
src = []; nodes = collections.OrderedDict(); seen=set()
for i,l in enumerate(lines):
    parts = l.split()
    if len(parts) == 4: _, size, t, full = parts; size = int(size,16)
    elif len(parts) == 3: _, t, full = parts; size = 8
    else: continue
    if '@@' in full: name, ver = full.split('@@'); dflt = True
    elif '@' in full: name, ver = full.split('@'); dflt = False
    else: name, ver, dflt = full, None, True
    if t == 'A':  # the version node itself
        nodes.setdefault(name, []); continue
    if (name, ver) in seen: continue
    seen.add((name, ver))
    cname = name if dflt else f'__stub_{i}'
    if t in 'TtWiI':
        src.append(f'long s{i}(void) __asm__("{cname}"); long s{i}(void) {{ return 0; }}')
    elif t in 'DdBbVvRrGgSu':
        src.append(f'char s{i}[{max(size,1)}] __asm__("{cname}") __attribute__((aligned(64)));')
    else: continue
    if ver:
        nodes.setdefault(ver, [])
        if dflt: nodes[ver].append(name)
        else: src.append(f'__asm__(".symver {cname}, {name}@{ver}");')
open(out+'.c','w').write('\n'.join(src)+'\n')
args = ['gcc','-shared','-fPIC','-O0','-o',out,out+'.c','-Wl,-soname,'+soname]
if nodes:
    with open(out+'.map','w') as f:
        for v, syms in nodes.items():
            f.write(v + ' { ' + (' global: ' + ' '.join(s+';' for s in syms) if syms else '') + ' };\n')
    args.append('-Wl,--version-script='+out+'.map')
subprocess.run(args,check=True)
