"""Renders docs/results.md from a work folder of step outputs.

A step <id> left <id>.step.json (its provenance: cmd, started, load, wall,
rss, rc), <id>.out and <id>.err; the end-to-end steps also JSON files of
their scenes (<id>.run.json, <id>.eval.json, ...). document(ctx) assembles
the sections in the order of the paper's evaluation; write() writes it, or
with --update splices the regenerated sections into the existing file.
"""
import datetime
import os
import string

import config
import scenes
import sections
import summary
import values

PROSE_FILE = os.path.join(os.path.dirname(os.path.abspath(__file__)), "prose.md")


def load_prose(path=PROSE_FILE):
    blocks, name = {}, None
    with open(path) as f:
        for line in f:
            if line.startswith("@@ "):
                name = line[3:].strip()
                blocks[name] = ""
            elif name:
                blocks[name] += line
    return blocks


class Work:
    """The outputs of the steps in one work folder."""

    def __init__(self, folder):
        self.folder = folder

    def path(self, name):
        return os.path.join(self.folder, name)

    def has(self, sid):
        return os.path.isfile(self.path(sid + ".step.json"))

    def text(self, name):
        try:
            with open(self.path(name), errors="replace") as f:
                return f.read()
        except OSError:
            return ""

    def out(self, sid):
        return self.text(sid + ".out")

    def json(self, name):
        return values.load(self.path(name))

    def tables(self, sid):
        """The tables the step's bench wrote with --json <work>/<sid>.json."""
        return self.json(sid + ".json")

    def hide(self, text):
        return text.replace(self.folder, "<tmp>")

    def raw(self, sid, hide=False):
        """The step's stdout verbatim in a text block."""
        out = self.out(sid)
        return "```text\n" + (self.hide(out) if hide else out) + "```\n"

    def provenance(self, sid):
        """The lines under a section naming how it was produced."""
        m = self.json(sid + ".step.json") or {}
        s = "\nCommand: `%s`  \n" % self.hide(m.get("cmd", ""))
        s += "Run: %s, wall %s s, peak RSS %s MB, load average at start %s.\n" % (
            m.get("started", ""), m.get("wall", ""), m.get("rss", ""), m.get("load", ""))
        if str(m.get("rc", "")) != "0":
            err = self.text(sid + ".err").splitlines(keepends=True)[-20:]
            s += "\n**FAILED (exit status %s).** Last lines of stderr:\n\n" % m.get("rc", "")
            s += "```text\n"
            s += "".join(err) + "```\n"
        return s + "\n"


def machine():
    with open("/proc/cpuinfo") as f:
        cpu = next((l.split(":", 1)[1].strip() for l in f if l.startswith("model name")), "")
    with open("/proc/meminfo") as f:
        kb = next(int(l.split()[1]) for l in f if l.startswith("MemTotal"))
    return {"cores": len(os.sched_getaffinity(0)), "cpu": cpu,
            "memory": "%.0f GiB" % (kb / 1048576)}


def build_type(build):
    try:
        with open(os.path.join(build, "CMakeCache.txt")) as f:
            for line in f:
                if line.startswith("CMAKE_BUILD_TYPE:"):
                    return line.split("=", 1)[1].strip()
    except OSError:
        pass
    return ""


def utc(t, fmt="%Y-%m-%d %H:%M:%S UTC"):
    return datetime.datetime.fromtimestamp(t, datetime.timezone.utc).strftime(fmt)


def context(c, work, commit, commit_now, t0, wall):
    """What the renderer needs of a run: c (config.py) and the run's facts."""
    ctx = dict(c, work=work, commit=commit, commit_now=commit_now, t0=t0, wall=wall,
               build_type=build_type(c["build"]), today=utc(t0 + wall, "%Y-%m-%d"))
    ctx.update(machine())
    return ctx


def header(ctx, prose):
    fields = dict(ctx, quick_flag=" --quick" if ctx["mode"] == "quick" else "",
                  speed_views=ctx["speed_views"].replace(" ", ", "),
                  speed_sizes=ctx["speed_sizes"].replace(" ", ", "),
                  build_type=ctx["build_type"] or "unknown build type",
                  started=utc(ctx["t0"]),
                  assembled="" if ctx["commit"] == ctx["commit_now"] else
                  " (the benches; assembled at %s)" % ctx["commit_now"],
                  reused=" (with --reuse: the steps already in the work folder were not rerun; "
                  "each section's \"Run:\" line says when it ran)" if ctx["reuse"] else "")
    names = ["header", "quick", "machine"] if ctx["mode"] == "quick" else ["header", "machine"]
    return "".join(string.Template(prose[n]).safe_substitute(fields) for n in names)


def document(ctx, prose=None):
    prose = prose or load_prose()
    w = Work(ctx["work"])
    fill = dict(ctx, long_synth=config.LONG_SYNTH, long_run=config.LONG_RUN,
                abl_scenario=config.ABL_SCENARIO)
    text = {k: string.Template(v).safe_substitute(fill) for k, v in prose.items()}
    doc = header(ctx, prose) + text["summary"] + summary.rows(ctx, w) + "\n"
    doc += sections.render(ctx, w, text) + scenes.render(ctx, w, text)
    return doc + text["not_measured"]


def summary_rows(doc):
    """The data rows of doc's "## Summary" table, keyed by their first cell (the result)."""
    rows, inside = {}, False
    for line in doc.splitlines(keepends=True):
        if line.startswith("## "):
            inside = line.startswith("## Summary")
        cells = line.split("|")
        if inside and len(cells) > 2 and cells[1].strip() not in ("result (paper table)", "---"):
            rows[cells[1].strip()] = line
    return rows


def splice(old, new, note):
    """old with each "## " section that new also has (except the summary and
    "Not yet measured") replaced by new's; new's other sections go before
    "## Not yet measured"; note goes before "## Summary". In the summary
    table, each row new has (those of the sections it ran) replaces old's row
    of the same result; a result old lacks is added at the table's end."""
    body, order, head = {}, [], ""
    for line in new.splitlines(keepends=True):
        if line.startswith("## "):
            head = line.rstrip("\n")
            order.append(head)
        if head not in ("", "## Summary", "## Not yet measured"):
            body[head] = body.get(head, "") + line
    fresh = summary_rows(new)
    pending = [k for k in fresh if k not in summary_rows(old)]
    out, done, noted, skip, cur = [], set(), False, False, ""
    for line in old.splitlines(keepends=True):
        if line.startswith("## "):
            cur = line.rstrip("\n")
            skip = cur in body
            if skip:
                out.append(body[cur])
                done.add(cur)
        if line.startswith("## Not yet measured"):
            for h in order:
                if h in body and h not in done:
                    out.append(body[h] + "\n")
                    done.add(h)
        if line.startswith("## Summary") and not noted:
            out.append(note + "\n\n")
            noted = True
        if cur == "## Summary" and line.startswith("|"):
            key = line.split("|")[1].strip()
            line = fresh.get(key, line)
        elif cur == "## Summary" and pending and out and out[-1].startswith("|"):
            out.extend(fresh[k] for k in pending)
            pending = []
        if not skip:
            out.append(line)
    return "".join(out)


def write(ctx, out, doc):
    if ctx["update"] and ctx["only"] and os.path.isfile(out):
        note = ("Regenerated later, at commit %s on %s by `scripts/results.sh --only %s --update`: "
                "the sections named by that run (their own provenance lines say how) and the "
                "summary's rows from them; the other rows and sections are those of the run "
                "above." % (ctx["commit"], ctx["today"], ctx["only"]))
        with open(out) as f:
            doc = splice(f.read(), doc, note)
    with open(out, "w") as f:
        f.write(doc)
