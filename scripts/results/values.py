"""Numbers out of the steps' outputs, formatted as docs/results.md prints them.

The benches print Markdown tables (md_table, md_cell) or counters (the text
scrapers below); Google Benchmark benches write JSON (gb_ms, gb_counter); `u4d run`,
`u4d eval` and `u4d consistency` write JSON (get, r3, mm, ...). Numbers are
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


def md_table(text, heading):
    """The Markdown table printed after the first line starting with heading."""
    rows, on = [], False
    for line in text.splitlines():
        if line.startswith(heading):
            on = True
        elif on and line.startswith("|"):
            rows.append(line)
        elif on and rows:
            break
    return rows


def md_cell(text, heading, row, col):
    """Column col (1 = the method) of the row named row of that table; "" if none."""
    for line in md_table(text, heading):
        cells = line.split("|")
        if cells[1].strip(" ") == row:
            return cells[col].strip(" ") if col < len(cells) else ""
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


def fusion_chamfer(text):
    """fusion_bench's Chamfer (mm) per person at 8x480x270, joined by "/"."""
    found = []
    for line in text.splitlines():
        if line.startswith("8x480x270 person"):
            m = re.match(r".*chamfer ([0-9.]*) mm", line)
            if m:
                found.append(m.group(1))
    return "/".join(found)


def shelf_pcp(text):
    """The "all" PCP of shelf_pose_bench's tracked + smoothed table."""
    on = False
    for line in text.splitlines():
        on = on or "tracked + smoothed" in line
        fields = line.split()
        if on and fields and fields[0] == "all":
            return fields[-1]
    return ""


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
