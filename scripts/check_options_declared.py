#!/usr/bin/env python3
"""Checks that every field of RunOptions and of the structs nested in it is
declared in the options registry (DeclareOptions, src/u4d/util/options.h).

C++ has no reflection, so a field added to an options struct without a
DeclareOptions line would silently be missing from params.json, --config and
docs/options.md. This script reads the struct bodies from the headers
(one field per line: `type name = default;` or `type name;`) and the
`&o->name` of each DeclareOptions body, starting from RunOptions and
following nested structs that have a DeclareOptions of their own.

Usage: scripts/check_options_declared.py [source root]; exits 1 listing the
undeclared fields. Run by ctest (options_declared_test).
"""
import glob
import re
import sys

# Fields deliberately not declared, with the reason (keep short).
NOT_DECLARED = {
    ("FrameSetupOptions", "pose"): "the capsule model is joint.pose, copied in by the pipeline",
}

FIELD = re.compile(r"^\s*([A-Za-z_][\w:<>]*)\s+([a-z_][a-z_0-9]*)\s*(=[^;]*)?;")


def struct_fields(headers, name):
    for path in headers:
        text = open(path, encoding="utf-8").read()
        m = re.search(r"^struct %s \{\n(.*?)^\};" % name, text, re.M | re.S)
        if not m:
            continue
        fields = []
        for line in m.group(1).split("\n"):
            code = line.split("//")[0]
            f = FIELD.match(code)
            if f and "(" not in code and f.group(1) not in ("enum", "return", "using"):
                fields.append((f.group(1), f.group(2)))
        return fields
    return None


def main():
    root = sys.argv[1] if len(sys.argv) > 1 else "."
    headers = sorted(glob.glob(root + "/src/u4d/*/*.h"))
    sources = glob.glob(root + "/src/u4d/*/*_options.cc") + [root + "/src/u4d/pipeline/run_options.cc"]
    code = "".join(open(p, encoding="utf-8").read() for p in sources)
    declared = {}
    for m in re.finditer(r"void DeclareOptions\(OptionRegistry& r, (\w+)\* o\) \{\n(.*?)\n\}\n", code, re.S):
        declared[m.group(1)] = set(re.findall(r"&o->(\w+)", m.group(2)))
    # JointWeights is declared from a table; its fields are listed the same way.
    missing, todo, seen = [], ["RunOptions"], set()
    while todo:
        name = todo.pop()
        if name in seen:
            continue
        seen.add(name)
        fields = struct_fields(headers, name)
        if fields is None:
            missing.append("%s: struct not found in src/u4d/*/*.h" % name)
            continue
        for ftype, fname in fields:
            nested = ftype.split("::")[-1]
            if nested in declared:
                todo.append(nested)
            if (name, fname) in NOT_DECLARED or fname in declared.get(name, set()):
                continue
            missing.append("%s::%s (%s)" % (name, fname, ftype))
    if missing:
        print("fields without a DeclareOptions line (src/u4d/<module>/<module>_options.cc):")
        print("\n".join("  " + m for m in missing))
        return 1
    print("every field of RunOptions and its nested structs is declared (%d structs)" % len(seen))
    return 0


if __name__ == "__main__":
    sys.exit(main())
