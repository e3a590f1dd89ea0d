"""Numbers out of the steps' outputs, formatted as docs/results.md prints them.

The printf benches write their Markdown tables as JSON too (`--json`: md_table,
md_cell, fusion_chamfer, shelf_pcp) and print counters (the text scrapers
below); Google Benchmark benches
write JSON (gb_ms, gb_counter); `u4d run`, `u4d eval` and `u4d consistency`
write JSON (get, r3, mm, ...). Numbers are
rounded half away from zero and printed shortest, integers without a point.
"""
import json
import math
import re


def jround(x):
    return math.copysign(math.floor(abs(x) + 0.5), x)


def num(x):
    """x printed shortest, an integral value without a decimal point."""
    if x is None:
        return "null"
    if isinstance(x, float) and x.is_integer() and abs(x) < 1e17:
        return str(int(x))
    return str(x) if isinstance(x, (bool, str)) else repr(x)


def rounded(x, scale, per=1):
    """x / per rounded to 1/scale, printed; "" when missing."""
    return "" if x is None or not per else num(jround(x / per * scale) / scale)


def r3(x):
    return rounded(x, 1000)


def mm(metres):
    """Metres as millimetres with one decimal."""
    return "" if metres is None else num(jround(metres * 10000) / 10)


def get(d, path):
    """d's value at the dotted path; None where any part is missing."""
    for key in path.split("."):
        if not isinstance(d, dict):
            return None
        d = d.get(key)
    return d


def drift(e):
    """Vertex drift at the segments' last frames (true motion), mm."""
    d = get(e, "vertex_drift.last_frame_drift_m")
    if d is None:
        return ""
    return "%s (%s)" % (mm(d), mm(get(e, "vertex_drift.last_frame_motion_m")))


def stage_sum(run, name=None, field="seconds"):
    """The sum of field over run.json's stages (named name); None if none."""
    vals = [s.get(field) for s in (run or {}).get("stages", [])
            if (name is None or s.get("name") == name) and s.get(field) is not None]
    return sum(vals) if vals else None


def peak_mb(run):
    """The peak resident memory over run.json's stages, MB; "" if none."""
    vals = [s["peak_rss_mb"] for s in (run or {}).get("stages", [])
            if s.get("peak_rss_mb") is not None]
    return num(jround(max(vals))) if vals else ""


def per_frame(run, scale=10):
    """All stages' seconds per solved frame (segments' items), rounded to 1/scale."""
    try:
        return num(jround(stage_sum(run) / stage_sum(run, "segments", "items") * scale) / scale)
    except (TypeError, ZeroDivisionError):
        return ""


def load(path):
    """A JSON file, or None when it is missing or broken."""
    try:
        with open(path) as f:
            return json.load(f)
    except (OSError, ValueError):
        return None


def bench_table(tables, heading):
    """The first table of a bench's --json file whose title starts with heading; None if none."""
    for t in (tables or {}).get("tables", []):
        if t.get("title", "").startswith(heading):
            return t
    return None


def md_row(cells):
    return "|" + "".join(" %s |" % c for c in cells)


def md_table(tables, heading):
    """That table's lines as the bench printed them: header, rule, rows; [] if none."""
    t = bench_table(tables, heading)
    if t is None:
        return []
    rule = "|" + "---|" * len(t["columns"])
    return [md_row(t["columns"]), rule] + [md_row(r) for r in t["rows"]]


def md_cell(tables, heading, row, col):
    """Column col (1 = the method) of the row named row of that table; "" if none."""
    t = bench_table(tables, heading)
    for cells in t["rows"] if t else []:
        if cells[0] == row:
            return cells[col - 1] if col - 1 < len(cells) else ""
    return ""


def gb_ms(gbench, name):
    """The real time in ms of Google Benchmark's run name, "%.1f"; "" if none."""
    units = {"ns": 1e-6, "us": 1e-3, "ms": 1.0, "s": 1e3}
    for b in (gbench or {}).get("benchmarks", []):
        if b.get("name") == name:
            return "%.1f" % (b["real_time"] * units.get(b.get("time_unit"), 1.0))
    return ""


def ratio(a, b):
    try:
        a, b = float(a), float(b)
    except ValueError:
        return ""
    return "%.1f" % (a / b) if a > 0 and b > 0 else ""


def fusion_chamfer(tables):
    """fusion_bench's Chamfer (mm) per person at 8x480x270, joined by "/"."""
    t = bench_table(tables, "FuseObject from GT depth")
    return "/".join(r[6] for r in (t["rows"] if t else []) if r[1] == "8x480x270")


def shelf_pcp(tables):
    """The "all" PCP of shelf_pose_bench's tracked + smoothed table (actors 1-3)."""
    t = bench_table(tables, "PCP (%), tracked + smoothed")
    return md_cell(tables, t["title"], "all", len(t["columns"])) if t else ""


def gb_counter(gbench, counter):
    """The counter of the first Google Benchmark run that has it, "%.3f"; "" if none."""
    for b in (gbench or {}).get("benchmarks", []):
        if counter in b:
            return "%.3f" % b[counter]
    return ""


def synth_fps(text):
    """The writer's frames/s that `u4d synth` prints."""
    found = [m.group(1) for line in text.splitlines()
             for m in [re.match(r".*\(([0-9.]*) frames/s;", line)] if m]
    return "\n".join(found)
