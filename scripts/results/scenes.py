"""The end-to-end sections of docs/results.md: tables of the JSON files that
`u4d run`, `u4d eval` and `u4d consistency` write, one row per capture."""
import os

from config import DETECTOR_SEEDS, TRUE_MASK_SETTINGS
from summary import row
from values import drift, get, mm, num, peak_mb, per_frame, r3, rounded, stage_sum, synth_fps


def accuracy(e):
    """The eval.json cells the scenario, ablation and long tables share."""
    return [r3(get(e, "instances.mean_instance_iou")), r3(get(e, "depth_people.delta_5pct")),
            r3(get(e, "flow_people.epe_px")), r3(get(e, "silhouette_overlap_error.value"))]


def se_baselines(e):
    b = e.get("silhouette_overlap_error_baselines") or {}
    return [r3(get(b, m + ".value")) for m in ("deepflow", "dis", "farneback")]


def surface(e):
    return [r3(get(e, "projection_error.value")), mm(get(e, "meshes.chamfer_m")), drift(e)]


def provenances(w, sids, suffixes):
    return "".join(w.provenance(sid + x) for sid in sids for x in suffixes)


def touching(i):
    return "%s (%s of %s)" % (r3(i.get("merge_rate_where_touching")),
                              num(i.get("merged_touching_images")), num(i.get("touching_images")))


def detector(w, text):
    s, found = text["detector"], []
    for seed in DETECTOR_SEEDS:
        d = w.json("detector_%s.json" % seed)
        if d is None:
            continue
        i = d.get("instances") or {}
        found.append(i)
        s += row(seed, r3(i.get("mean_instance_iou")), r3(i.get("mean_class_iou")), touching(i),
                 " / ".join(num(i.get(k)) for k in ("missed", "false_positives", "merged")),
                 synth_fps(w.out("detector_synth_" + seed)))
    if found:
        def total(key):
            return sum(i.get(key) or 0 for i in found)

        merged, touch = total("merged_touching_images"), total("touching_images")
        s += row("mean", r3(total("mean_instance_iou") / len(found)),
                 r3(total("mean_class_iou") / len(found)),
                 "%s (%s of %s)" % (r3(merged / touch) if touch else "", num(merged), num(touch)),
                 None, None)
    return s + "\n" + "".join(w.provenance(p + seed) for seed in DETECTOR_SEEDS
                               for p in ("detector_synth_", "detector_"))


def scenarios(ctx, w, text):
    s = text["scenarios"]
    for sid in ctx["scenarios_ids"]:
        name, e = sid[len("scen_"):], w.json(sid + ".eval.json")
        if e is None:
            s += row(name, "(no eval.json: the run failed)", *[None] * 11)
            continue
        init = r3(get(w.json(sid + ".initial.json"), "instances.mean_instance_iou"))
        s += row(name, init, *accuracy(e), *se_baselines(e), *surface(e),
                 per_frame(w.json(sid + ".run.json")))
    s += text["identity"]  # it opens with a blank line
    for sid in ctx["scenarios_ids"]:
        e = w.json(sid + ".eval.json")
        if e is None:
            continue
        init, d = w.json(sid + ".initial.json") or {}, e.get("identity") or {}
        def pair(*keys):
            return " / ".join(num(d.get(k)) for k in keys)

        s += row(sid[len("scen_"):], r3(get(init, "identity.mean_ids_per_person")),
                 r3(d.get("mean_ids_per_person")),
                 pair("switches_in_view", "cross_view_disagreements"),
                 pair("no_mesh_frames", "visible_frames"),
                 touching(init.get("instances") or {}) if init else "")
    return s + "\n" + provenances(w, ctx["scenarios_ids"], ["_synth", "", "_eval"])


def ablations(ctx, w, text):
    s = text["ablations"]
    for sid in ctx["ablations_ids"]:
        e = w.json(sid + ".eval.json")
        if e is None:
            s += row(sid[len("abl_"):], "(no eval.json: the run failed)", *[None] * 7)
            continue
        s += row(sid[len("abl_"):], *accuracy(e), *surface(e), per_frame(w.json(sid + ".run.json")))
    synth = w.provenance("abl_synth") if ctx["ablations_ids"] else ""
    return s + "\n" + synth + provenances(w, ctx["ablations_ids"], [""])


def speed_stages(ctx, w):
    s = "| capture | stage | seconds | peak memory MB | items |\n|---|---|---|---|---|\n"
    for sid in ctx["speed_ids"]:
        cfg, run = sid[len("speed_"):], w.json(sid + ".run.json")
        if run is None:
            s += row(cfg, "(no run.json: the run failed)", None, None, None)
            continue
        for st in run.get("stages", []):
            s += row(cfg, num(st.get("name")), rounded(st.get("seconds"), 10),
                     rounded(st.get("peak_rss_mb"), 1), num(st.get("items")))
        s += row(cfg, "**total**", rounded(stage_sum(run), 10), peak_mb(run), None)
    return s + "\n"


def speed(ctx, w, text):
    s = text["speed"]
    if not ctx["speed_ids"]:
        return s
    s += speed_stages(ctx, w) + text["speed_eval"]
    for sid in ctx["speed_ids"]:
        cfg, e = sid[len("speed_"):], w.json(sid + ".eval.json")
        s += row(cfg, *accuracy(e), *surface(e)) if e else row(cfg, "(no eval.json)", *[None] * 6)
    s += "\n" + text["speed_consistency"]
    for sid in ctx["speed_ids"]:
        cfg, k = sid[len("speed_"):], w.json(sid + ".consistency.json")
        if k is None:
            s += row(cfg, "(no consistency.json)", *[None] * 6)
            continue
        s += row(cfg, *[r3(get(k, "silhouette_overlap_error." + m))
                        for m in ("own_flow", "deepflow", "dis", "farneback")],
                 r3(get(k, "cross_view.depth_agreement")), r3(get(k, "cross_view.label_agreement")),
                 r3(get(k, "projection_error.value")))
    s += "\n"
    for sid in ctx["speed_ids"]:
        s += "### %s\n" % sid[len("speed_"):] + w.provenance(sid + "_synth")
        s += "`u4d run` printed (evaluation, then the stage table):\n\n"
        s += w.raw(sid, hide=True) + w.provenance(sid)
    return s


def scaling_row(run, v, size):
    n = stage_sum(run, "segments", "items")

    def per(x):
        return rounded(x or 0, 100, n)

    def part(name):
        if "segment_parts" not in run:
            return "–"
        return per(sum(p["seconds"] for p in run["segment_parts"] if p.get("name") == name))

    stages = [per(stage_sum(run, x)) for x in ("poses", "initial", "tracks", "segments")]
    return row(v, size, *stages, part("solve"), part("fusion"), per(stage_sum(run, "consistency")),
               per(stage_sum(run)), peak_mb(run))


def scaling(ctx, w, text):
    s = text["scaling"]
    for sid in ctx["scaling_ids"]:
        v, size = sid[len("scale_"):].split("v_", 1)
        run = w.json(sid + ".run.json")
        s += scaling_row(run, v, size) if run else row(
            v, size, "(no run.json: the run failed)", *[None] * 8)
    s += "\n"
    if w.has("scale_plot") and os.path.isfile(ctx["plot"]):
        s += "![u4d run: seconds per frame by stage and peak memory, against views and image " \
             "size](images/results_scaling.png)\n\n" + w.provenance("scale_plot")
    return s + provenances(w, ctx["scaling_ids"], [""])


def length(ctx, w, text):
    s = text["length"]
    for sid in ctx["length_ids"]:
        n, run = sid[len("length_"):], w.json(sid + ".run.json")
        if run is None:
            s += row(n, "(no run.json: the run failed)", None, None, None)
            continue
        seg = stage_sum(run, "segments")
        s += row(n, rounded(seg, 1), rounded(seg, 100, float(n)),
                 rounded(stage_sum(run), 1), peak_mb(run))
    return s + "\n" + w.provenance("length_synth") + provenances(w, ctx["length_ids"], [""])


def long_sequences(ctx, w, text):
    s = text["long"]
    for sid in ctx["long_ids"]:
        name, e = sid[len("long_"):], w.json(sid + ".eval.json")
        if e is None:
            s += row(name, ctx["long_frames"], "(no eval.json: the run failed)", *[None] * 13)
            continue
        init = r3(get(w.json(sid + ".initial.json"), "instances.mean_instance_iou"))
        kf = w.json(sid + ".keyframes.json")
        run = w.json(sid + ".run.json")
        s += row(name, ctx["long_frames"], num(len(kf.get("keyframes") or [])) if kf else "", init,
                 *accuracy(e), *se_baselines(e), *surface(e), per_frame(run), peak_mb(run))
    return s + "\n" + provenances(w, ctx["long_ids"], ["_synth", "", "_eval"])


def true_masks(ctx, w, text):
    s = text["true_masks"]
    for sid in ctx["true_masks_ids"]:
        for name, _ in TRUE_MASK_SETTINGS:
            rid = "%s_%s" % (sid, name)
            e = w.json(rid + ".eval.json")
            if e is None:
                s += row(sid[len("tm_"):], name, "(no eval.json: the run failed)", None, None, None)
                continue
            s += row(sid[len("tm_"):], name, r3(get(e, "instances.mean_instance_iou")),
                     r3(get(e, "instances.mean_class_iou")), mm(get(e, "meshes.chamfer_m")),
                     per_frame(w.json(rid + ".run.json")))
    suffixes = ["_synth"] + ["_" + name for name, _ in TRUE_MASK_SETTINGS]
    return s + "\n" + provenances(w, ctx["true_masks_ids"], suffixes)


def render(ctx, w, text):
    want, s = ctx["want"], ""
    if want("detector"):
        s += detector(w, text)
    for section, fn in [("scenarios", scenarios), ("ablations", ablations),
                        ("true_masks", true_masks)]:
        if ctx[section + "_ids"]:
            s += fn(ctx, w, text)
    if want("speed"):
        s += speed(ctx, w, text)
    for section, fn in [("scaling", scaling), ("length", length), ("long", long_sequences)]:
        if ctx[section + "_ids"]:
            s += fn(ctx, w, text)
    return s
