#!/usr/bin/env python3
"""Every function declared in include/amgsplat/*.h must be defined in the library archive.

Usage: scripts/check_declared.py LIBAMGSPLAT.a [SKIPPED_HEADER.h ...]
A reduced build (ASP_WITH_GL=OFF) leaves out whole modules: their headers are named as skipped.
Within a built module, a declared function without a definition links only until a caller
appears (asp_amg_shutdown without hypre did), so scripts/test.sh runs this on every build.
"""
import glob
import os
import re
import subprocess
import sys


def declared(skip):
    found = {}
    for h in sorted(glob.glob(os.path.join(os.path.dirname(__file__), "..", "include", "amgsplat", "*.h"))):
        if os.path.basename(h) in skip:
            continue
        s = open(h).read()
        s = re.sub(r"/\*.*?\*/", "", s, flags=re.S)
        s = re.sub(r"//[^\n]*", "", s)
        s = re.sub(r"#[^\n]*(\\\n[^\n]*)*", "", s)  # macros, including ASP_ASSERT's
        # a declaration at file scope: return type, asp_name, parameters, ';' (no body, no typedef)
        for m in re.finditer(r"(?:^|(?<=[;}]))\s*([A-Za-z_][\w\s\*]*?)\b(asp_\w+)\s*\(([^;{]*?)\)\s*;", s, re.S):
            if "typedef" not in m.group(1):
                found.setdefault(m.group(2), os.path.basename(h))
    return found


def main():
    lib, skip = sys.argv[1], set(sys.argv[2:])
    out = subprocess.run(["nm", "-g", "--defined-only", lib], check=True, capture_output=True, text=True).stdout
    defined = {f[-1] for f in (line.split() for line in out.splitlines()) if len(f) >= 3}
    decl = declared(skip)
    missing = sorted((h, n) for n, h in decl.items() if n not in defined)
    for h, n in missing:
        print(f"{lib}: {n} is declared in include/amgsplat/{h} but not defined", file=sys.stderr)
    if not decl:
        print("check_declared: no declarations found; the parser is broken", file=sys.stderr)
        return 1
    print(f"check_declared: {len(decl)} declared functions, {len(missing)} undefined in {lib}", file=sys.stderr)
    return 1 if missing else 0


if __name__ == "__main__":
    sys.exit(main())
