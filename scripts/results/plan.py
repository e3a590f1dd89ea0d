"""The steps of a results run, in order (one at a time).

plan(c, work) yields actions: ("run", id, argv) runs a step whose output the
renderer reads as <work>/<id>.out and <work>/<id>.step.json; ("copy", src,
dst) keeps a file of a scene (when it exists) before ("rm", path) removes the
capture. The Google Benchmark benches (mrf, kernels, tracks, synth) also
write their results as <work>/<id>.gbench.json, the other benches their
tables as <work>/<id>.json (--json; bench/bench_table.h).
"""
import os

from config import (ABL_SCENARIO, DETECTOR_SEEDS, LONG_RUN, LONG_SYNTH, TRUE_MASK_SETTINGS,
                    TRUE_MASK_WORLDS, scale_points, scen_synth_args)

SE_BASELINES = "deepflow,dis,farneback"


def _bench_steps(c, w, b):
    want = c["want"]
    a = {k: c[k].split() for k in ("joint", "depth", "recon", "sparse", "keyframes", "mrf",
                                    "kernels", "phases", "render")}

    def gbench(name, bench, args):
        return ("run", name, [b + bench] + args + [
            "--benchmark_out=%s/%s.gbench.json" % (w, name), "--benchmark_out_format=json"])

    def tables(name, bench, args):
        return ("run", name, [b + bench] + args + ["--json", "%s/%s.json" % (w, name)])

    if want("seg") or want("depth") or want("flow"):
        yield tables("joint", "joint_bench", a["joint"])
    if want("realistic"):
        yield tables("joint_realistic", "joint_bench", ["--preset", "realistic"] + a["joint"])
    if want("depth"):
        yield tables("depth_cost", "depth_cost_bench", a["depth"])
        yield tables("recon", "joint_bench", a["recon"])
    for section, step, bench in [("flow", "flow_cost", "flow_cost_bench"),
                                 ("camera_flow", "camera_flow", "camera_flow_bench"),
                                 ("middlebury", "middlebury", "middlebury_bench"),
                                 ("sintel", "sintel", "sintel_bench"),
                                 ("fusion", "fusion", "fusion_bench"),
                                 ("pose", "shelf", "shelf_pose_bench")]:
        if want(section):
            yield tables(step, bench, [])
    if want("sparse"):
        yield tables("sparse", "sparse_bench", a["sparse"])
    if want("tracks"):
        yield gbench("tracks", "tracks_bench", [])
    if want("keyframes"):
        yield tables("keyframes", "keyframes_bench", a["keyframes"])
    if want("mrf"):
        yield gbench("mrf", "mrf_bench", a["mrf"])
    if want("kernels"):
        yield gbench("kernels", "kernels_bench", a["kernels"])
        yield tables("joint_phases", "joint_phases_bench", a["phases"])
    if want("synth"):
        yield gbench("synth_render", "synth_render_bench", a["render"])
        yield gbench("synth", "synth_bench", [])


def _scene_steps(c, w, u4d):
    """detector, speed, length: captures of `u4d synth` run through u4d."""
    if c["want"]("detector"):
        for seed in DETECTOR_SEEDS:
            cap = "%s/detector_%s" % (w, seed)
            yield ("run", "detector_synth_" + seed,
                   [u4d, "synth", "--preset", "realistic", "--seed", seed]
                   + c["detector"].split() + ["-o", cap])
            yield ("run", "detector_" + seed,
                   [u4d, "eval", cap, "--initial", "-o", "%s/detector_%s.json" % (w, seed)])
            yield ("rm", cap)
    for sid in c["speed_ids"]:
        v, size = sid[len("speed_"):].split("v_")
        width, height = size.split("x")
        cap = "%s/%s" % (w, sid)
        yield ("run", sid + "_synth", [u4d, "synth", "--preset", "handshake", "--frames",
                                       c["speed_frames"], "--views", v, "--width", width,
                                       "--height", height, "-o", cap])
        yield ("run", sid, [u4d, "run", cap, "-o", cap + "/scene", "--no-progress"])
        yield from _keep(cap + "/scene", w, sid, ["run", "eval"])
        yield ("run", sid + "_consistency",
               [u4d, "consistency", cap + "/scene", "--baselines", SE_BASELINES,
                "-o", "%s/%s.consistency.json" % (w, sid)])
        yield ("rm", cap)
    if c["length_ids"]:
        frames = str(max(int(n) for n in c["length_frames"].split()))
        cap = w + "/length_capture"
        yield ("run", "length_synth", [u4d, "synth", "--preset", "handshake", "--frames", frames,
                                       "--views", "4", "--width", "160", "--height", "90",
                                       "--no-meshes", "-o", cap])
        for lid in c["length_ids"]:
            scene = "%s/%s.scene" % (w, lid)
            yield ("run", lid, [u4d, "run", cap, "-o", scene, "--frames", lid[len("length_"):],
                                "--working-width", "160", "--rounds", "1", "--no-eval",
                                "--no-progress"])
            yield from _keep(scene, w, lid, ["run"])
            yield ("rm", scene)
        yield ("rm", cap)


def _keep(scene, w, sid, names):
    for name in names:
        yield ("copy", "%s/%s.json" % (scene, name), "%s/%s.%s.json" % (w, sid, name))


def _eval_steps(u4d, cap, w, sid):
    """The scene of cap evaluated against its GT, and the initial masks."""
    yield ("run", sid + "_eval", [u4d, "eval", cap, "--pred", cap + "/scene", "--se-baselines",
                                  SE_BASELINES, "-o", "%s/%s.eval.json" % (w, sid)])
    yield ("run", sid + "_initial",
           [u4d, "eval", cap, "--initial", "-o", "%s/%s.initial.json" % (w, sid)])


def _scenario_steps(c, w, u4d):
    """scenarios: one capture per scenario."""
    for sid in c["scenarios_ids"]:
        cap = "%s/%s" % (w, sid)
        yield ("run", sid + "_synth", [u4d, "synth"] + scen_synth_args(sid[len("scen_"):])
               + c["scen"].split() + ["-o", cap])
        yield ("run", sid, [u4d, "run", cap, "-o", cap + "/scene", "--no-eval", "--no-progress"])
        yield from _keep(cap + "/scene", w, sid, ["run"])
        yield from _eval_steps(u4d, cap, w, sid)
        yield ("rm", cap)


def _ablation_steps(c, w, u4d):
    """ablations: a short capture of ABL_SCENARIO of their own, each energy run
    on the whole of it (a run of part of a capture writes no eval.json)."""
    if not c["ablations_ids"]:
        return
    cap = "%s/abl_%s" % (w, ABL_SCENARIO)
    yield ("run", "abl_synth", [u4d, "synth"] + scen_synth_args(ABL_SCENARIO)
           + c["abl_synth"].split() + ["-o", cap])
    for aid in c["ablations_ids"]:
        scene = "%s/%s.scene" % (w, aid)
        yield ("run", aid, [u4d, "run", cap, "-o", scene, "--ablation", aid[len("abl_"):],
                            "--no-progress"] + c["abl_run"].split())
        yield from _keep(scene, w, aid, ["run", "eval"])
        yield ("rm", scene)
    yield ("rm", cap)


def _true_mask_steps(c, w, u4d):
    """true_masks: each world with its true masks given, run with each setting."""
    for sid in c["true_masks_ids"]:
        cap = "%s/%s" % (w, sid)
        yield ("run", sid + "_synth", [u4d, "synth"] + TRUE_MASK_WORLDS[sid[len("tm_"):]]
               + c["true_masks"].split() + ["--degrade", "none", "-o", cap])
        for name, options in TRUE_MASK_SETTINGS:
            scene = "%s/%s" % (cap, name)
            yield ("run", "%s_%s" % (sid, name),
                   [u4d, "run", cap, "-o", scene, "--no-progress"] + options)
            yield from _keep(scene, w, "%s_%s" % (sid, name), ["run", "eval"])
        yield ("rm", cap)


def _long_steps(c, w, u4d):
    """scaling (and its plot), long."""
    for (v, size), sid in zip(scale_points(c), c["scaling_ids"]):
        cap = "%s/%s" % (w, sid)
        width, height = size.split("x")
        yield ("run", sid + "_synth", [u4d, "synth", "--preset", "handshake", "--frames",
                                       c["scale_frames"], "--views", v, "--width", width,
                                       "--height", height, "--no-meshes", "-o", cap])
        yield ("run", sid, [u4d, "run", cap, "-o", cap + "/scene", "--no-eval", "--no-progress"])
        yield from _keep(cap + "/scene", w, sid, ["run"])
        yield ("rm", cap)
    if c["scaling_ids"]:
        yield ("plot", "scale_plot", ["/usr/bin/python3", "scripts/plot_scaling.py", c["plot"]]
               + ["%s/%s.run.json" % (w, sid) for sid in c["scaling_ids"]])
    for sid in c["long_ids"]:
        cap = "%s/%s" % (w, sid)
        yield ("run", sid + "_synth", [u4d, "synth", "--preset", sid[len("long_"):], "--frames",
                                       c["long_frames"]] + LONG_SYNTH.split() + ["-o", cap])
        yield ("run", sid, [u4d, "run", cap, "-o", cap + "/scene", "--no-eval", "--no-progress"]
               + LONG_RUN.split())
        yield from _keep(cap + "/scene", w, sid, ["run", "keyframes"])
        yield from _eval_steps(u4d, cap, w, sid)
        yield ("rm", cap)


def plan(c, work):
    b = os.path.join(c["build"], "bench") + "/"
    u4d = os.path.join(c["build"], "apps", "u4d")
    yield from _bench_steps(c, work, b)
    yield from _scene_steps(c, work, u4d)
    yield from _scenario_steps(c, work, u4d)
    yield from _ablation_steps(c, work, u4d)
    yield from _true_mask_steps(c, work, u4d)
    yield from _long_steps(c, work, u4d)
