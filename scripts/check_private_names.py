#!/usr/bin/env python3
"""The targets that build as unity sources (the CLI, the eval, report and pipeline libraries, and
the test parts marked UNITY in tests/CMakeLists.txt) must not hold a function private to one file (in an
anonymous namespace) whose name another file of the target also gives a private function, or
that a project header declares: in one unity source, the later file would silently call the
other function. Lists each such name and exits 1; exits 0 when there is none.

  scripts/check_private_names.py [ROOT]
"""
import collections, glob, os, re, sys

root = sys.argv[1] if len(sys.argv) > 1 else '.'
targets = {'apps': 'apps/*.cpp', 'src/eval': 'src/eval/*.cpp', 'src/report': 'src/report/*.cpp',
           'src/pipeline': 'src/pipeline/*.cpp'}
tests_cmake = os.path.join(root, 'tests/CMakeLists.txt')
if os.path.exists(tests_cmake):
    for part, args in re.findall(r'roiflow_add_tests\((\w+)([^)]*)\)', open(tests_cmake).read()):
        if re.search(r'\bUNITY\b', args):
            targets[f'tests/{part}'] = f'tests/{part}/*.cpp'
name_re = re.compile(r'^(?:template <.*> )?(?:static |inline |constexpr |\[\[nodiscard\]\] )*'
                     r'(?:const )?[A-Za-z_][\w:<>,\s\*&]*?[\s\*&]([A-Za-z_]\w*)\s*\(')
type_re = re.compile(r'^(?:struct|class|enum(?: class)?|using)\s+([A-Za-z_]\w*)')

def private_names(path):
    names, depth, inside = set(), 0, False
    for line in open(path, encoding='utf-8'):
        s = line.rstrip('\n')
        if not inside and re.match(r'^namespace\s*\{', s):
            inside, depth = True, 0
            continue
        if inside:
            if depth == 0 and re.match(r'^\}\s*//\s*namespace', s):
                inside = False
                continue
            if depth == 0 and s and not s[0].isspace() and not s.startswith(('//', '#', '}')):
                m = None if s.startswith(('namespace', 'using', 'struct', 'class', 'enum')) else name_re.match(s)
                if m and m.group(1) not in ('operator',):
                    names.add(m.group(1))
            depth += s.count('{') - s.count('}')
    return names

public = set()
for h in glob.glob(os.path.join(root, 'src/*/*.hpp')):
    for line in open(h, encoding='utf-8'):
        m = re.match(r'^(?:\s*(?:inline |constexpr |static |\[\[nodiscard\]\] )*[A-Za-z_][\w:<>,\s\*&]*?[\s\*&]'
                     r'([A-Za-z_]\w*)\()', line)
        if m and not line.startswith((' ', '\t')):
            public.add(m.group(1))
found = 0
for target, pattern in targets.items():
    owners = collections.defaultdict(list)
    for f in sorted(glob.glob(os.path.join(root, pattern))):
        for n in private_names(f):
            owners[n].append(os.path.relpath(f, root))
    for n, files in sorted(owners.items()):
        if len(files) > 1:
            print(f'{target}: {n} is private to several files: {", ".join(files)}'); found += 1
        elif n in public:
            print(f'{target}: {n} in {files[0]} has the name of a public function'); found += 1
sys.exit(1 if found else 0)
