#!/usr/bin/env python3
"""Size limits of the sources (issue 16): apps/ at most 900 lines in all, no source file over 700
lines, no function over 120 lines. Functions are found with a brace-depth scanner: comments and
string literals are skipped, and a block whose header (the text since the previous ';', '{' or
'}') holds a parameter list and is not a class, namespace or enum opens a function (lambdas and
control blocks inside it count towards it). A function runs from its header's first line to its
closing brace.

  scripts/check_size.py [ROOT]          # exit 1 and one line per breach when a limit is broken
  scripts/check_size.py --files F...    # the file and function limits on these files only
  scripts/check_size.py --skip-apps-total [ROOT]   # all but the apps/ total (see tests/CMakeLists)
"""
import os
import re
import sys

APPS_MAX_LINES = 900
FILE_MAX_LINES = 700
FUNCTION_MAX_LINES = 120
SOURCE_DIRS = ("src", "apps", "tests", "bench", "fuzz")
EXTENSIONS = (".cpp", ".hpp", ".h", ".cc")
# Files another piece of work is rewriting; their limits are checked once it has landed.
EXEMPT = set()

SCOPE_HEADER = re.compile(r'\b(namespace|class|struct|union|enum)\b|extern\s+"C"')


def strip_code(text):
    """The text with comments and string/char literals blanked (newlines kept)."""
    out = []
    i, n = 0, len(text)
    while i < n:
        c = text[i]
        if text.startswith("//", i):
            j = text.find("\n", i)
            i = n if j < 0 else j
        elif text.startswith("/*", i):
            j = text.find("*/", i + 2)
            j = n if j < 0 else j + 2
            out.append("\n" * text.count("\n", i, j))
            i = j
        elif c == "R" and text.startswith('R"', i) and (i == 0 or not (text[i - 1].isalnum() or text[i - 1] == "_")):
            open_paren = text.find("(", i + 2)
            delim = text[i + 2:open_paren]
            end = text.find(")" + delim + '"', open_paren)
            end = n if end < 0 else end + len(delim) + 2
            out.append('""' + "\n" * text.count("\n", i, end))
            i = end
        elif c in "\"'":
            if c == "'" and i > 0 and text[i - 1].isalnum():  # digit separator 1'000
                i += 1
                continue
            j = i + 1
            while j < n and text[j] != c:
                j += 2 if text[j] == "\\" else 1
            out.append(c + c)
            i = j + 1
        else:
            out.append(c)
            i += 1
    return "".join(out)


def strip_preprocessor(code):
    """Preprocessor lines (and their continuations) blanked, newlines kept."""
    lines = code.split("\n")
    continued = False
    for k, text in enumerate(lines):
        if continued or text.lstrip().startswith("#"):
            continued = text.rstrip().endswith("\\")
            lines[k] = ""
    return "\n".join(lines)


def long_functions(text, limit):
    """(first line, length, header) of each function longer than `limit` lines."""
    code = strip_preprocessor(strip_code(text))
    found = []
    stack = []  # (kind, start line, header) per open brace
    header_start = 0
    line = 1
    for i, c in enumerate(code):
        if c == "\n":
            line += 1
        elif c == ";":
            if not stack or stack[-1][0] != "function":
                header_start = i + 1
        elif c == "{":
            if stack and stack[-1][0] in ("function", "inner"):
                stack.append(("inner", line, ""))
            else:
                header = code[header_start:i]
                stripped = header.strip()
                first = line - code[header_start + len(header) - len(header.lstrip()):i].count("\n")
                if SCOPE_HEADER.search(stripped) and "(" not in stripped.split("{")[0].split("=")[0]:
                    stack.append(("scope", first, stripped))
                elif ")" in stripped and not stripped.endswith("="):
                    stack.append(("function", first, " ".join(stripped.split())))
                else:
                    stack.append(("inner", first, ""))
            header_start = i + 1
        elif c == "}":
            if stack:
                kind, first, header = stack.pop()
                if kind == "function" and line - first + 1 > limit:
                    found.append((first, line - first + 1, header))
            if not stack or stack[-1][0] != "function":
                header_start = i + 1
    return found


def sources(root):
    for top in SOURCE_DIRS:
        for folder, _, names in os.walk(os.path.join(root, top)):
            for name in sorted(names):
                if name.endswith(EXTENSIONS):
                    yield os.path.relpath(os.path.join(folder, name), root)


def check_files(root, paths):
    breaches = []
    for rel in paths:
        if rel in EXEMPT:
            continue
        with open(os.path.join(root, rel), encoding="utf-8", errors="replace") as f:
            text = f.read()
        lines = text.count("\n") + (0 if text.endswith("\n") or not text else 1)
        if lines > FILE_MAX_LINES:
            breaches.append(f"{rel}: {lines} lines (max {FILE_MAX_LINES})")
        for first, length, header in long_functions(text, FUNCTION_MAX_LINES):
            breaches.append(f"{rel}:{first}: function of {length} lines (max "
                            f"{FUNCTION_MAX_LINES}): {header[:80]}")
    return breaches


def main(argv):
    skip_apps_total = len(argv) > 1 and argv[1] == "--skip-apps-total"
    if skip_apps_total:
        argv = argv[:1] + argv[2:]
    if len(argv) > 1 and argv[1] == "--files":
        breaches = check_files(".", argv[2:])
    else:
        root = argv[1] if len(argv) > 1 else os.path.join(os.path.dirname(__file__), "..")
        paths = list(sources(root))
        breaches = check_files(root, paths)
        apps = sum(open(os.path.join(root, p), encoding="utf-8", errors="replace").read().count("\n")
                   for p in paths if p.startswith("apps" + os.sep))
        if apps > APPS_MAX_LINES and not skip_apps_total:
            breaches.append(f"apps/: {apps} lines in all (max {APPS_MAX_LINES})")
        if not paths:
            breaches.append(f"no source files under {root}")
    for b in breaches:
        print("check_size: " + b)
    if breaches:
        return 1
    print("check_size: ok (%sfiles <= %d, functions <= %d)" %
          ("" if skip_apps_total else "apps/ <= %d lines, " % APPS_MAX_LINES, FILE_MAX_LINES, FUNCTION_MAX_LINES))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
