"""The options of scripts/results.sh and the sizes each mode runs at.

config(argv) returns a dict: the options as given plus, per mode, the
arguments of every bench and the step ids of the end-to-end sections. The
planner (plan.py) and the renderer (render.py) both read it, so a section's
prose names the sizes its steps ran at.
"""
import argparse
import os

# Per option: (quick, full). Full: the commands docs/*.md quote. Quick: the same
# benches on smaller inputs where the bench takes sizes; benches with fixed
# sizes run as they are.
SIZES = {
    "joint": ("--views 4 --width 320 --height 180 --working-width 320 --frames 3 --max-views 2",
              "--frames 3 --max-views 4"),
    "sparse": ("2 2.0", "10 2.0"),
    "keyframes": ("32 8 4", "64 8 4"),
    "depth": ("1", "1"),
    "mrf": ("--benchmark_min_time=0.01", ""),
    "kernels": ("--benchmark_min_time=0.01", ""),
    "phases": ("--views 4 --width 320 --height 180 --working-width 320 --frames 3 --max-views 2",
               "--max-views 1"),
    "render": ("--benchmark_min_time=0.01", ""),
    "scen": ("--frames 3 --views 4 --width 320 --height 180",
             "--frames 10 --views 8 --width 480 --height 270"),
    "detector": ("--frames 6 --views 4 --width 480 --height 270",
                 "--views 8 --width 960 --height 540"),  # full: the preset's 50 frames
    "recon": ("--views 8 --width 320 --height 180 --working-width 320 --frames 3"
              " --methods full,P_P",
              "--views 8 --frames 3 --methods full,P_M,P_P,P_S"),
    # The ablations' own short capture of ABL_SCENARIO, each run whole (so
    # each writes its eval.json).
    "abl_synth": ("--frames 3 --views 4 --width 320 --height 180",
                  "--frames 4 --views 8 --width 480 --height 270"),
    "abl_run": ("--working-width 160", ""),
    "speed_views": ("4", "4 8"),
    "speed_sizes": ("320x180", "480x270"),
    "speed_frames": ("3", "4"),
    "length_frames": ("10 30", "30 100 300"),
    "scale_views": ("4 8 16", "4 8 16"),
    "scale_view_size": ("160x90", "480x270"),
    "scale_frames": ("2", "2"),
    "scale_sizes": ("160x90 640x360", "480x270 960x540 1920x1080"),
    "true_masks": ("--frames 3 --views 4 --width 320 --height 180",
                   "--frames 6 --views 8 --width 960 --height 540"),
}
# Scenarios: walk is the handshake script's first frames, the two walking
# towards each other (centimetres per frame); the others are centred on the
# first handshake (people nearly still).
SCENARIOS = ["handshake", "walk", "meetup", "moving-cameras", "realistic", "realistic-moving"]
ABL_SCENARIO = "walk"
ABLATIONS = ["full", "P_M", "P_P", "P_PM", "P_S", "P_PS"]
# The realistic preset's detector was tuned on seeds 1-5 (20-frame captures;
# 6-9 were looked at too): these are held out.
DETECTOR_SEEDS = ["10", "11", "12", "13"]
# Long sequences: the scenarios as whole 100+ frame captures, 4 views at
# 320x180 solved at width 160 so that three of them fit in about an hour.
LONG_SYNTH = "--views 4 --width 320 --height 180"
LONG_RUN = "--working-width 160"
# True masks given (`u4d synth --degrade none`): the refined masks must stay
# true. The realistic seed is not the one the trusted-mask settings were
# chosen on (2).
TRUE_MASK_WORLDS = {"realistic": ["--preset", "realistic", "--seed", "3"],
                    "handshake": ["--preset", "handshake"]}
# The run options of each row: the defaults, and those docs/formats.md gives
# for masks the capture trusts.
TRUE_MASK_SETTINGS = [("default", []),
                      ("trusted", ["--set", "frame_setup.hull.confirm=true",
                                   "--set", "joint.labels.appearance_inset_px=0"])]
SIZE_OPTIONS = ["speed_views", "speed_sizes", "speed_frames", "length_frames", "scale_sizes"]


def parse(argv):
    p = argparse.ArgumentParser(prog="results.sh", add_help=False)
    p.add_argument("--quick", action="store_true")
    p.add_argument("--only", default="")
    p.add_argument("--out", default="docs/results.md")
    p.add_argument("--no-build", action="store_true")
    p.add_argument("--update", action="store_true")
    p.add_argument("--keep", action="store_true")
    p.add_argument("--reuse", default="")
    for name in SIZE_OPTIONS + ["long_frames"]:
        p.add_argument("--" + name.replace("_", "-"), dest=name)
    return p.parse_args(argv)


def scen_synth_args(scen):
    if scen == "walk":
        return ["--preset", "handshake", "--start-frame", "10"]
    return ["--preset", scen]


def scale_points(c):
    """The (views, size) points of the scaling section, the goal last."""
    points = [(v, c["scale_view_size"]) for v in c["scale_views"].split()]
    for s in c["scale_sizes"].split():
        if ("4", s) not in points:
            points.append(("4", s))
    if c["scale_goal"]:
        v, s = c["scale_goal"].split(" ", 1)
        points.append((v, s))
    return points


def config(argv, env=None):
    env = os.environ if env is None else env
    a = parse(argv)
    c = {k: v[0 if a.quick else 1] for k, v in SIZES.items()}
    c.update(mode="quick" if a.quick else "full", only=a.only, out=a.out, update=a.update,
             keep=a.keep or bool(a.reuse), reuse=a.reuse, build=env.get("BUILD", "build"))
    for name in SIZE_OPTIONS:
        if getattr(a, name):  # an empty value keeps the mode's default
            c[name] = getattr(a, name)
    c["long_frames"] = a.long_frames or "100"
    c["long_scenarios"] = env.get("LONG_SCENARIOS", "handshake meetup moving-cameras").split()
    c["scale_goal"] = env.get("SCALE_GOAL", "8 960x540")
    want = set(a.only.split(",")) if a.only else None
    c["want"] = lambda section: want is None or section in want
    # The steps of each end-to-end section; none where the section is not run.
    ids = {
        "speed": ["speed_%sv_%s" % (v, s) for v in c["speed_views"].split()
                  for s in c["speed_sizes"].split()],
        "length": ["length_" + n for n in c["length_frames"].split()],
        "scenarios": ["scen_" + s for s in SCENARIOS],
        "ablations": ["abl_" + a for a in ABLATIONS],
        "scaling": ["scale_%sv_%s" % p for p in scale_points(c)],
        "long": ["long_" + s for s in c["long_scenarios"]],
        "true_masks": ["tm_" + world for world in TRUE_MASK_WORLDS],
    }
    for section, section_ids in ids.items():
        c[section + "_ids"] = section_ids if c["want"](section) else []
    c["plot"] = os.path.join(os.path.dirname(a.out), "images", "results_scaling.png")
    return c
