"""Runs the steps of plan.py one at a time, then renders docs/results.md.

  python3 scripts/results/runner.py [the options of scripts/results.sh]

(scripts/results.sh builds, then calls this.) Each step's stdout goes to
<work>/<id>.out, its stderr to <work>/<id>.err and its provenance (command,
start, load average, wall time, peak RSS, exit status) to
<work>/<id>.step.json. A failing step is marked FAILED in the document, the
others still run, and the exit status is 1.
"""
import datetime
import json
import os
import shutil
import subprocess
import sys
import tempfile
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import config  # noqa: E402
import plan  # noqa: E402
import render  # noqa: E402


def log(msg):
    print("[results %s] %s" % (time.strftime("%H:%M:%S"), msg), file=sys.stderr, flush=True)


def quote(arg):
    """arg as bash's printf %q writes it (backslashes before special characters)."""
    if not arg:
        return "''"
    out = ""
    for i, ch in enumerate(arg):
        first = i == 0 or arg[i - 1] in "=:"
        if ch in " \t\n'\"\\|&;()<>!{}*[?]^$`," or (ch == "~" and first) or (ch == "#" and i == 0):
            out += "\\"
        out += ch
    return out


def utc_now():
    return datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%d %H:%M:%S UTC")


def run_step(work, sid, argv, reuse):
    """Runs argv with its provenance in <work>/<sid>.step.json; its exit status."""
    meta_path = os.path.join(work, sid + ".step.json")
    cmd = " ".join(quote(a) for a in argv)
    if reuse and os.path.exists(meta_path):
        log("%s: reusing %s/%s.out" % (sid, work, sid))
        return 0  # its failure, if any, was reported by the run that made it
    log("%s: %s" % (sid, cmd))
    with open("/proc/loadavg") as f:
        load = " ".join(f.read().split()[:3])
    started = utc_now()
    t0 = time.monotonic()
    rss = "?"
    with open(os.path.join(work, sid + ".out"), "wb") as out, \
            open(os.path.join(work, sid + ".err"), "wb") as err:
        try:
            proc = subprocess.Popen(argv, stdout=out, stderr=err)
            _, status, usage = os.wait4(proc.pid, 0)
            proc.returncode = rc = os.waitstatus_to_exitcode(status)
            rc = 128 - rc if rc < 0 else rc  # killed by a signal: as bash reports it
            rss = "%.0f" % (usage.ru_maxrss / 1024)
        except OSError as e:
            err.write(("%s: %s\n" % (argv[0], e.strerror)).encode())
            rc = 127
    wall = "%.1f" % (time.monotonic() - t0)
    meta = {"cmd": cmd, "started": started, "load": load, "wall": wall, "rss": rss, "rc": rc}
    with open(meta_path, "w") as f:
        json.dump(meta, f, indent=1)
    log("%s: done in %s s (rc %d)" % (sid, wall, rc))
    return rc


def execute(c, work):
    """Runs every action of the plan; the ids of the steps that failed."""
    failed = []
    for action in plan.plan(c, work):
        kind = action[0]
        if kind == "rm":
            shutil.rmtree(action[1], ignore_errors=True)
        elif kind == "copy":
            if os.path.isfile(action[1]):
                shutil.copyfile(action[1], action[2])
        elif kind == "plot" and not has_matplotlib():
            log("no matplotlib for /usr/bin/python3 (apt-get install python3-matplotlib): no plot")
        else:
            if kind == "plot":
                os.makedirs(os.path.dirname(c["plot"]) or ".", exist_ok=True)
            if run_step(work, action[1], action[2], bool(c["reuse"])) != 0:
                failed.append(action[1])
    return failed


def has_matplotlib():
    return subprocess.run(["/usr/bin/python3", "-c", "import matplotlib"],
                          stderr=subprocess.DEVNULL).returncode == 0


def git_commit():
    head = subprocess.run(["git", "rev-parse", "--short", "HEAD"], capture_output=True, text=True)
    dirty = subprocess.run(["git", "diff", "--quiet", "HEAD"], capture_output=True).returncode
    return head.stdout.strip() + (" with uncommitted changes" if dirty else "")


def work_folder(c):
    if c["reuse"]:
        return os.path.abspath(c["reuse"])
    return tempfile.mkdtemp(prefix="u4d_results.", dir=os.environ.get("TMPDIR", "/tmp"))


def run_commit(work):
    """The commit the benches ran at: recorded by the first run in the work folder."""
    path = os.path.join(work, "commit")
    now = git_commit()
    if os.path.exists(path) and os.path.getsize(path) > 0:
        with open(path) as f:
            return f.read().strip(), now
    with open(path, "w") as f:
        f.write(now + "\n")
    return now, now


def main(argv):
    c = config.config(argv)
    os.chdir(os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", ".."))
    work = work_folder(c)
    if c["keep"]:
        log("work folder: " + work)
    t0 = int(time.time())
    try:
        commit, commit_now = run_commit(work)
        failed = execute(c, work)
        ctx = render.context(c, work, commit, commit_now, t0, int(time.time()) - t0)
        render.write(ctx, c["out"], render.document(ctx))
    finally:
        if not c["keep"]:
            shutil.rmtree(work, ignore_errors=True)
    log("wrote %s (whole script %d s)" % (c["out"], ctx["wall"]))
    if failed:
        log("failed: %s (marked FAILED in %s)" % (" ".join(failed), c["out"]))
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
