#!/usr/bin/env python3
"""Mutation fuzzer of U4D's input readers, through the `u4d` command.

Makes a tiny synthetic capture with `u4d synth`, then, for each target, writes
N mutated copies of one input file and runs the command that reads it:

  calibration   calibration.json           u4d info <capture>
  capture       capture.json (structural)  u4d info <capture>
  mask          masks/<view>/000000.json   u4d eval <capture> --initial
  flo           <pred>/flow/<view>/000000.flo   u4d eval <capture> --pred <pred>
  pfm           <pred>/depth/<view>/000000.pfm  u4d eval <capture> --pred <pred>

Each run is classified as
  clean     exit status 1 or 2 with "error:" and no "internal error" (a u4d::Error)
  accepted  exit status 0
  abort     killed by a signal (SIGABRT from an uncaught exception, SIGSEGV),
            or "internal error" (the last-resort handler in apps/main.cc)
  hang      ran past the timeout
  other     anything else
and "accepted" runs whose mutation put a non-finite or out-of-range number in
the file are counted again as "accepted_bad" (a silent acceptance).

  scripts/mutation_fuzz.py --u4d build/apps/u4d [-n 200] [--seed 1]
      [--targets calibration,capture,mask,flo,pfm] [--work DIR] [--json out.json]

Python 3 standard library only. The mutations are random but reproducible
from --seed; a failing case is kept under <work>/cases/ with its stderr.
"""
import argparse
import copy
import json
import os
import random
import re
import shutil
import struct
import subprocess
import sys
import tempfile

# ------------------------------------------------------------------ JSON

# Values a mutation may put anywhere. Whether one is out of range depends on
# the field, so only the non-finite tokens, an extra camera and the
# structural cases known to be invalid count as "bad" when accepted.
JSON_VALUES = [
    ("null", None), ("true", True), ("zero", 0), ("neg", -1), ("big_int", 2**31),
    ("huge_int", 2**64 - 1), ("neg_big", -(2**40)), ("frac", 0.5), ("string", "x"),
    ("num_string", "3"), ("empty_array", []), ("empty_object", {}), ("array", [1, 2, 3]),
    ("nested", {"a": [None]}), ("pattern", "{:06q}"),
]
# Raw tokens that json.dumps cannot produce; spliced into the text.
RAW_TOKENS = [("overflow", "1e999", True), ("neg_overflow", "-1e999", True),
              ("nan", "NaN", True), ("infinity", "Infinity", True),
              ("tiny", "1e-999", False), ("long_int", "9" * 40, False)]


def json_paths(node, path=()):
    """Every (path, value) in a JSON tree, root first."""
    yield path, node
    if isinstance(node, dict):
        for k, v in node.items():
            yield from json_paths(v, path + (k,))
    elif isinstance(node, list):
        for i, v in enumerate(node):
            yield from json_paths(v, path + (i,))


def get_at(node, path):
    for p in path:
        node = node[p]
    return node


def set_at(root, path, value):
    if not path:
        return value
    get_at(root, path[:-1])[path[-1]] = value
    return root


MARK = "__U4D_FUZZ_RAW__"


def mutate_json(doc, rng):
    """Returns (text, kind, bad): one random mutation of a JSON document."""
    doc = copy.deepcopy(doc)
    paths = list(json_paths(doc))
    path, value = rng.choice(paths)
    op = rng.choice(["replace", "replace", "raw", "delete", "scale", "wrap", "text"])
    if op == "replace":
        name, new = rng.choice(JSON_VALUES)
        return json.dumps(set_at(doc, path, copy.deepcopy(new))), f"replace:{name}", False
    if op == "raw":
        name, token, bad = rng.choice(RAW_TOKENS)
        text = json.dumps(set_at(doc, path, MARK))
        return text.replace(json.dumps(MARK), token, 1), f"raw:{name}", bad
    if op == "delete" and path:
        parent = get_at(doc, path[:-1])
        del parent[path[-1]]
        return json.dumps(doc), "delete", False
    if op == "scale" and isinstance(value, (int, float)) and not isinstance(value, bool):
        factor = rng.choice([-1, 1e6, 1e300, 0])
        return json.dumps(set_at(doc, path, value * factor)), f"scale:{factor:g}", False
    if op == "wrap":
        return json.dumps(set_at(doc, path, [value])), "wrap", False
    text = json.dumps(doc)
    cut = rng.randrange(len(text))
    if rng.random() < 0.5:
        return text[:cut], "truncate", False
    return text[:cut] + rng.choice("{}[],:\"0e-") + text[cut + 1:], "byte", False


def mutate_capture(doc, rng):
    """Structural mutations of capture.json: (text, kind, bad)."""
    doc = copy.deepcopy(doc)
    views = doc.get("views", [])
    v = rng.randrange(len(views)) if views else 0
    choices = {
        "array": lambda: [doc],
        "views_object": lambda: dict(doc, views={"a": 1}),
        "views_number": lambda: dict(doc, views=7),
        "no_views": lambda: dict(doc, views=[]),
        "drop_view": lambda: dict(doc, views=views[:v] + views[v + 1:]),
        "dup_view": lambda: dict(doc, views=views + [copy.deepcopy(views[v])]),
        "unknown_view": lambda: dict(doc, views=views + [dict(views[v], name="ghost")]),
        "view_number": lambda: set_at(doc, ("views", v), 7),
        "name_number": lambda: set_at(doc, ("views", v, "name"), 7),
        "first_index_string": lambda: set_at(doc, ("views", v, "first_index"), "3"),
        "first_index_negative": lambda: set_at(doc, ("views", v, "first_index"), -5),
        "first_index_huge": lambda: set_at(doc, ("views", v, "first_index"), 2**40),
        "bad_pattern": lambda: set_at(doc, ("views", v, "path"), "images/x/{:06q}.png"),
        "two_fields": lambda: set_at(doc, ("views", v, "path"), "images/x/{}{}.png"),
        "no_field": lambda: set_at(doc, ("views", v, "path"), "images/x/a.png"),
        "source_video_bad": lambda: set_at(doc, ("views", v, "source"), "tape"),
        "files_wrong_count": lambda: set_at(doc, ("views", v, "files"), ["a.png"]),
        "num_frames_zero": lambda: dict(doc, num_frames=0),
        "num_frames_string": lambda: dict(doc, num_frames="2"),
        "num_frames_huge": lambda: dict(doc, num_frames=2**33),
        "fps_negative": lambda: dict(doc, fps=-25),
        "fps_string": lambda: dict(doc, fps="fast"),
        "scene_bad": lambda: dict(doc, scene="space"),
        "classes_number": lambda: dict(doc, classes=3),
        "format_missing": lambda: {k: x for k, x in doc.items() if k != "format"},
    }
    bad_kinds = {"first_index_negative", "first_index_huge", "num_frames_huge", "fps_negative",
                 "num_frames_zero"}
    if rng.random() < 0.7 and views:
        kind = rng.choice(sorted(choices))
        return json.dumps(choices[kind]()), f"struct:{kind}", kind in bad_kinds
    if rng.random() < 0.5:
        text = re.sub(r'"fps": [-0-9.eE+]+', '"fps": 1e999', json.dumps(doc), count=1)
        return text, "raw:fps_overflow", True
    return mutate_json(doc, rng)


def mutate_calibration(doc, rng):
    if rng.random() < 0.15 and doc.get("cameras"):
        doc = copy.deepcopy(doc)
        extra = copy.deepcopy(doc["cameras"][0])
        extra["view"] = "extra_cam"
        doc["cameras"].append(extra)
        return json.dumps(doc), "extra_camera", True
    return mutate_json(doc, rng)


# ---------------------------------------------------------------- binary

def mutate_flo(data, rng):
    """Returns (bytes, kind, bad) for a Middlebury .flo."""
    op = rng.choice(["header", "header", "flip", "truncate", "append", "value"])
    if op == "header":
        w = rng.choice([0, -1, 1, 3, 99999, 100000, 2**31 - 1, -(2**31)])
        h = rng.choice([0, -1, 1, 3, 99999, 100000, 2**31 - 1])
        return data[:4] + struct.pack("<ii", w, h) + data[12:], f"header:{w}x{h}", False
    return mutate_bytes(data, rng, op, header=12)


def mutate_pfm(data, rng):
    end = data.index(b"\n", data.index(b"\n", data.index(b"\n") + 1) + 1) + 1
    op = rng.choice(["header", "header", "flip", "truncate", "append", "value"])
    if op == "header":
        magic = rng.choice([b"Pf", b"PF", b"P6", b"pf"])
        w = rng.choice([b"0", b"-1", b"1", b"99999", b"100000", b"4294967297", b"x", b"1e3"])
        h = rng.choice([b"0", b"1", b"99999", b"2147483648", b""])
        scale = rng.choice([b"-1", b"1", b"0", b"nan", b"inf", b"-1e999"])
        header = magic + b"\n" + w + b" " + h + b"\n" + scale + b"\n"
        return header + data[end:], f"header:{w.decode()}x{h.decode()}", False
    return mutate_bytes(data, rng, op, header=end)


def mutate_bytes(data, rng, op, header):
    data = bytearray(data)
    if op == "flip":
        for _ in range(rng.randint(1, 8)):
            i = rng.randrange(min(len(data), header + 16))
            data[i] = rng.randrange(256)
        return bytes(data), "flip", False
    if op == "truncate":
        return bytes(data[:rng.randrange(len(data))]), "truncate", False
    if op == "append":
        return bytes(data) + os.urandom(rng.randint(1, 64)), "append", False
    # A non-finite value in the data: accepted where the format says it means
    # "unknown" (NaN depth or flow), so not counted as bad.
    i = header + 4 * rng.randrange((len(data) - header) // 4)
    data[i:i + 4] = struct.pack("<f", rng.choice([float("nan"), float("inf"), -1e30]))
    return bytes(data), "value", False


# ---------------------------------------------------------------- runs

def run(cmd, timeout):
    try:
        p = subprocess.run(cmd, capture_output=True, text=True, timeout=timeout)
    except subprocess.TimeoutExpired:
        return "hang", None, ""
    err = p.stderr + p.stdout
    if p.returncode < 0 or "internal error" in err or p.returncode in (134, 139):
        return "abort", p.returncode, err
    if p.returncode == 0:
        return "accepted", 0, err
    if p.returncode in (1, 2) and "error:" in err:
        return "clean", p.returncode, err
    return "other", p.returncode, err


def make_capture(u4d, work):
    cap = os.path.join(work, "capture")
    cmd = [u4d, "synth", "--preset", "handshake", "--frames", "2", "--views", "2", "--width", "64",
           "--height", "48", "--no-meshes", "-o", cap]
    p = subprocess.run(cmd, capture_output=True, text=True)
    if p.returncode != 0:
        sys.exit(f"u4d synth failed ({p.returncode}):\n{p.stderr}")
    return cap


def first_view(cap):
    with open(os.path.join(cap, "capture.json")) as f:
        return json.load(f)["views"][0]["name"]


def targets(cap, work, u4d):
    view = first_view(cap)
    pred = os.path.join(work, "pred")
    if not os.path.isdir(pred):
        os.makedirs(pred)
        for sub in ("instances", "depth", "flow"):
            shutil.copytree(os.path.join(cap, "gt", sub), os.path.join(pred, sub))
    out = os.path.join(work, "eval.json")
    info = [u4d, "info", cap]
    initial = [u4d, "eval", cap, "--initial", "-o", out]
    predict = [u4d, "eval", cap, "--pred", pred, "-o", out]
    return {
        "calibration": (os.path.join(cap, "calibration.json"), "json", mutate_calibration, info),
        "capture": (os.path.join(cap, "capture.json"), "json", mutate_capture, info),
        "mask": (os.path.join(cap, "masks", view, "000000.json"), "json", mutate_json, initial),
        "flo": (os.path.join(pred, "flow", view, "000000.flo"), "bin", mutate_flo, predict),
        "pfm": (os.path.join(pred, "depth", view, "000000.pfm"), "bin", mutate_pfm, predict),
    }


def fuzz_target(name, spec, n, rng, timeout, cases_dir):
    path, kind, mutate, cmd = spec
    with open(path, "rb") as f:
        original = f.read()
    doc = json.loads(original) if kind == "json" else None
    counts = {"clean": 0, "accepted": 0, "abort": 0, "hang": 0, "other": 0, "accepted_bad": 0}
    findings = []
    try:
        for i in range(n):
            if kind == "json":
                text, what, bad = mutate(doc, rng)
                data = text.encode()
            else:
                data, what, bad = mutate(original, rng)
            with open(path, "wb") as f:
                f.write(data)
            verdict, rc, err = run(cmd, timeout)
            counts[verdict] += 1
            if verdict == "accepted" and bad:
                counts["accepted_bad"] += 1
            if verdict in ("abort", "hang", "other") or (verdict == "accepted" and bad):
                case = os.path.join(cases_dir, f"{name}_{i:04d}")
                with open(case + os.path.splitext(path)[1], "wb") as f:
                    f.write(data)
                with open(case + ".stderr", "w") as f:
                    f.write(f"{what} rc={rc}\n{err}")
                findings.append({"case": case, "mutation": what, "verdict": verdict, "rc": rc,
                                 "message": err.strip().splitlines()[-1] if err.strip() else ""})
    finally:
        with open(path, "wb") as f:
            f.write(original)
    return counts, findings


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--u4d", required=True, help="the u4d binary")
    ap.add_argument("-n", type=int, default=200, help="mutations per target")
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--targets", default="calibration,capture,mask,flo,pfm")
    ap.add_argument("--work", help="work folder (default: a new temporary one)")
    ap.add_argument("--capture", help="reuse this tiny capture (copied) instead of synthesising")
    ap.add_argument("--timeout", type=float, default=120)
    ap.add_argument("--json", help="write the counts and findings here")
    a = ap.parse_args()
    u4d = os.path.abspath(a.u4d)
    work = a.work or tempfile.mkdtemp(prefix="u4d_mutation_fuzz_")
    os.makedirs(work, exist_ok=True)
    cases_dir = os.path.join(work, "cases")
    os.makedirs(cases_dir, exist_ok=True)
    cap = os.path.join(work, "capture")
    if a.capture:
        if not os.path.isdir(cap):
            shutil.copytree(a.capture, cap)
    elif not os.path.isdir(cap):
        make_capture(u4d, work)
    specs = targets(cap, work, u4d)
    for name, spec in specs.items():  # the unmutated inputs must be accepted
        verdict, rc, err = run(spec[3], a.timeout)
        if verdict != "accepted":
            sys.exit(f"{name}: the unmutated input is not accepted ({verdict}, rc {rc}):\n{err}")
    report = {"u4d": u4d, "n": a.n, "seed": a.seed, "targets": {}}
    print(f"{'target':<12} {'clean':>6} {'accepted':>9} {'abort':>6} {'hang':>5} {'other':>6}"
          f" {'acc.bad':>8}")
    for t, name in enumerate(a.targets.split(",")):
        rng = random.Random(a.seed * 1000 + t)
        counts, findings = fuzz_target(name, specs[name], a.n, rng, a.timeout, cases_dir)
        report["targets"][name] = {"counts": counts, "findings": findings}
        print(f"{name:<12} {counts['clean']:>6} {counts['accepted']:>9} {counts['abort']:>6}"
              f" {counts['hang']:>5} {counts['other']:>6} {counts['accepted_bad']:>8}",
              flush=True)
    if a.json:
        with open(a.json, "w") as f:
            json.dump(report, f, indent=1)
    print(f"cases kept in {cases_dir}")


if __name__ == "__main__":
    main()
