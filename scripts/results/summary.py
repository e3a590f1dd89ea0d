"""The summary table of docs/results.md: headline numbers, each from a section."""
from values import (drift, fusion_chamfer, gb_counter, gb_ms, get, md_cell, peak_mb, per_frame,
                    r3, ratio, rounded, shelf_pcp, stage_sum)


def row(*cells):
    """A Markdown table row; a None cell is left blank ("| |"), "" is an empty value."""
    return "|" + "".join(" |" if c is None else " %s |" % c for c in cells) + "\n"


def joint_rows(w):
    s = ""
    if w.has("joint"):
        j = w.tables("joint")

        def cell(h, r, c):
            return md_cell(j, h, r, c)

        s += row("segmentation: mean instance IoU (Segmentation comparison)",
                 "initial %s, GrabCut %s" % (cell("Segmentation", "initial", 2),
                                             cell("Segmentation", "grabcut", 2)),
                 "full " + cell("Segmentation", "full", 2), "Segmentation")
        s += row("depth on people within 5 % (Reconstruction evaluation)",
                 "WTA plane sweep " + cell("Depth", "wta", 3), "full " + cell("Depth", "full", 3),
                 "Reconstruction / depth")
        s += row("flow EPE on people, px (motion evaluation)",
                 "DIS %s, DeepFlow %s, Farneback %s" % tuple(
                     cell("Flow", m, 2) for m in ("dis", "deepflow", "farneback")),
                 "full " + cell("Flow", "full", 2), "Flow")
    if w.has("recon"):
        r = w.tables("recon")
        wta, sgbm, gt, full = (md_cell(r, "Reconstruction", m, 2)
                               for m in ("wta", "sgbm", "gt", "full"))
        s += row("projection error of the fused surface, GT masks (Reconstruction evaluation)",
                 "WTA %s, SGBM %s (GT depth %s)" % (wta, sgbm, gt), "full " + full,
                 "Reconstruction / depth")
    return s


def walk_row(ctx, w):
    e = w.json("scen_walk.eval.json") if "scen_walk" in ctx["scenarios_ids"] else None
    if e is None:
        return ""
    b = e.get("silhouette_overlap_error_baselines", {})
    base = "DeepFlow %s, DIS %s, Farneback %s" % tuple(
        r3(get(b, m + ".value")) for m in ("deepflow", "dis", "farneback"))
    return row("S_e of the GT masks carried by the flow, two people walking (Silhouette overlap "
               "error)", base, "ours " + r3(get(e, "silhouette_overlap_error.value")), "End to end")


def real_rows(w):
    s = ""
    if w.has("middlebury"):
        m = w.tables("middlebury")
        s += row("Middlebury, depth term alone: mean bad-pixel rate > 1 px (4 pairs)",
                 "SGBM %s, BM %s" % (md_cell(m, "Mean over", "sgbm", 2),
                                     md_cell(m, "Mean over", "bm", 2)),
                 "E_d WTA %s, E_d + E_s %s" % (md_cell(m, "Mean over", "ours-wta", 2),
                                               md_cell(m, "Mean over", "ours-mrf", 2)),
                 "Middlebury")
    if w.has("sintel"):
        t = w.tables("sintel")

        def epe(m):
            return "%s / %s" % (md_cell(t, "All cases", m, 2), md_cell(t, "All cases", m, 3))

        s += row("Sintel flow EPE all / noc, px (3 cases; ours = single-view fusion)",
                 "DeepFlow %s, DIS %s" % (epe("deepflow"), epe("dis")),
                 "from zero %s, from DeepFlow %s" % (epe("ours-fusion"), epe("ours-fusion-df")),
                 "Sintel")
    return s


def module_rows(w):
    s = ""
    if w.has("fusion"):
        s += row("mesh fused from GT depth, Chamfer mm (8x480x270, persons 1 / 2)", None,
                 fusion_chamfer(w.tables("fusion")), "Meshes")
    if w.has("shelf"):
        s += row("Shelf 3D pose, average PCP actors 1-3, %", None, shelf_pcp(w.tables("shelf")),
                 "3D pose on Shelf")
    if w.has("tracks"):
        s += row("temporal tracks: share of steps within 2 px of GT flow", None,
                 gb_counter(w.json("tracks.gbench.json"), "precision"), "Temporal tracks")
    if w.has("mrf"):
        g = w.json("mrf.gbench.json")
        for what, name in [("max-flow 480x270 4-connected, ms", "BM_MaxFlow/%d/4"),
                           ("alpha-expansion 480x270, 32 labels, ms",
                            "BM_AlphaExpansion/%d/iterations:1")]:
            own, boost = gb_ms(g, name % 0), gb_ms(g, name % 1)
            s += row(what, "Boost BK " + boost, "own BK %s (%sx)" % (own, ratio(boost, own)),
                     "Graph cuts")
    return s


def run_rows(ctx, w):
    s = ""
    for sid in ctx["speed_ids"]:
        run, e = w.json(sid + ".run.json"), w.json(sid + ".eval.json")
        if run and e:
            s += row("`u4d run` %s x %s frames: IoU, S_e, total s, peak MB" % (
                sid[len("speed_"):], ctx["speed_frames"]), None, "%s, %s, %s s, %s MB" % (
                r3(get(e, "instances.mean_instance_iou")),
                r3(get(e, "silhouette_overlap_error.value")),
                rounded(stage_sum(run), 1), peak_mb(run)), "Speed")
    goal = ctx["scale_goal"]
    run = w.json("scale_%sv_%s.run.json" % tuple(goal.split(" ", 1))) if goal else None
    if run:
        s += row("speed goal: `u4d run` on %s views at %s, s per frame (2 cores), peak MB"
                 % tuple(goal.split(" ", 1)), "goal 5 s",
                 "%s s, %s MB" % (per_frame(run), peak_mb(run)), "Scaling")
    for sid in ctx["long_ids"]:
        run, e, init = (w.json(sid + x) for x in (".run.json", ".eval.json", ".initial.json"))
        if run and e:
            s += row("`u4d run` on a %s-frame %s: IoU, S_e, vertex drift mm (true motion), "
                     "s per frame, peak MB" % (ctx["long_frames"], sid[len("long_"):]),
                     "initial IoU %s; S_e DeepFlow %s" % (
                         r3(get(init, "instances.mean_instance_iou")),
                         r3(get(e, "silhouette_overlap_error_baselines.deepflow.value"))),
                     "%s, %s, %s, %s s, %s MB" % (
                         r3(get(e, "instances.mean_instance_iou")),
                         r3(get(e, "silhouette_overlap_error.value")), drift(e),
                         per_frame(run), peak_mb(run)), "Long sequences")
    return s


def rows(ctx, w):
    return joint_rows(w) + walk_row(ctx, w) + real_rows(w) + module_rows(w) + run_rows(ctx, w)
