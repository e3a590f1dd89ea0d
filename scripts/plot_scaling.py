#!/usr/bin/python3
"""Scaling curves of `u4d run` for docs/results.md (scripts/results.sh).

Usage: plot_scaling.py OUT.png RUN_JSON...

Each RUN_JSON is the run.json of one `u4d run`, named
scale_<views>v_<width>x<height>.run.json (results.sh names them so). Left:
seconds per frame by stage against the number of views, at the one image
size most runs share; right: the same against the image size (megapixels)
at 4 views. Peak memory (max over stages) is drawn on a second axis.
"""
import json
import os
import re
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

NAME = re.compile(r"scale_(\d+)v_(\d+)x(\d+)\.run\.json$")
# One colour per stage in both panels.
COLOURS = {"poses": "tab:purple", "initial": "tab:brown", "tracks": "tab:green",
           "keyframes": "tab:gray", "segments": "tab:blue", "consistency": "tab:olive",
           "eval": "tab:pink"}


def load(paths):
    runs = []
    for path in paths:
        m = NAME.search(os.path.basename(path))
        if not m:
            sys.exit(f"plot_scaling.py: {path}: name is not scale_<v>v_<w>x<h>.run.json")
        try:
            with open(path) as f:
                j = json.load(f)
            stages = {s["name"]: s for s in j["stages"]}
            frames = max(s["items"] for s in j["stages"] if s["name"] == "segments")
        except (OSError, ValueError, KeyError) as e:
            sys.exit(f"plot_scaling.py: {path}: not a readable run.json ({e})")
        views, w, h = (int(g) for g in m.groups())
        runs.append({"views": views, "w": w, "h": h, "stages": stages, "frames": frames})
    return runs


def panel(ax, runs, x_of, xlabel, title, tick_label):
    runs = sorted(runs, key=x_of)
    xs = [x_of(r) for r in runs]
    names = [n for n in runs[0]["stages"]]
    bottom = [0.0] * len(runs)
    for name in names:
        ys = [r["stages"].get(name, {}).get("seconds", 0.0) / r["frames"] for r in runs]
        if max(ys) < 0.01 * max(1e-9, max(sum(
                s["seconds"] for s in r["stages"].values()) / r["frames"] for r in runs)):
            bottom = [b + y for b, y in zip(bottom, ys)]
            continue
        ax.fill_between(xs, bottom, [b + y for b, y in zip(bottom, ys)], label=name, alpha=0.7,
                        color=COLOURS.get(name))
        bottom = [b + y for b, y in zip(bottom, ys)]
    ax.plot(xs, bottom, "k.-", label="total")
    ax.set_xlabel(xlabel)
    ax.set_ylabel("seconds per frame (wall)")
    ax.set_title(title)
    ax.set_xticks(xs)
    ax.set_xticklabels([tick_label(r) for r in runs])
    mem = ax.twinx()
    mem.plot(xs, [max(s["peak_rss_mb"] for s in r["stages"].values()) for r in runs], "r--o",
             label="peak memory")
    mem.set_ylabel("peak memory MB", color="r")
    mem.set_ylim(bottom=0)
    ax.legend(loc="upper left", fontsize=7)


def main():
    if len(sys.argv) < 3:
        sys.exit(__doc__)
    runs = load(sys.argv[2:])
    sizes = {}
    for r in runs:
        sizes.setdefault((r["w"], r["h"]), []).append(r)
    view_size = max(sizes, key=lambda k: len(sizes[k]))
    by_views = sizes[view_size]
    by_size = [r for r in runs if r["views"] == 4]
    fig, axes = plt.subplots(1, 2, figsize=(11, 4))
    panel(axes[0], by_views, lambda r: r["views"], "views",
          f"`u4d run` vs views ({view_size[0]}x{view_size[1]})", lambda r: str(r["views"]))
    panel(axes[1], by_size, lambda r: r["w"] * r["h"] / 1e6, "image size (pixels, linear scale)",
          "`u4d run` vs image size (4 views)", lambda r: f"{r['w']}x{r['h']}")
    fig.tight_layout()
    fig.savefig(sys.argv[1], dpi=90)
    print(f"wrote {sys.argv[1]}")


if __name__ == "__main__":
    main()
