"""The sections of docs/results.md on the benches of bench/ (their tables, from
the JSON they write with --json, and outputs verbatim), in the document's order."""
from values import md_table


def table(w, sid, heading):
    """The step's table whose title starts with heading, from <sid>.json (a note where a
    step of an older run has none)."""
    tables = w.tables(sid)
    if tables is None:
        return "(no %s.json: this step ran before the benches wrote their tables as JSON)\n" % sid
    return "".join(line + "\n" for line in md_table(tables, heading))


def joint_section(w, heading):
    """A table of the joint_bench run and its provenance."""
    return table(w, "joint", heading) + w.provenance("joint") if w.has("joint") else ""


def verbatim(w, *sids):
    """Each step's stdout in a text block and its provenance, if it ran."""
    return "".join(w.raw(sid) + w.provenance(sid) for sid in sids if w.has(sid))


def depth(w, text):
    s = text["depth"] + joint_section(w, "Depth")
    if w.has("recon"):
        s += text["recon"] + table(w, "recon", "Reconstruction") + w.provenance("recon")
    if w.has("depth_cost"):
        s += text["depth_cost"] + verbatim(w, "depth_cost")
    return s


def flow(w, text):
    s = text["flow"] + joint_section(w, "Flow")
    if w.has("joint"):
        s += "### Time per view and energy trace (same joint_bench run)\n\n"
        s += table(w, "joint", "Time per view") + "\n" + table(w, "joint", "Energy trace") + "\n"
    if w.has("flow_cost"):
        s += text["flow_cost"] + verbatim(w, "flow_cost")
    return s


# Sections that are their prose and the outputs of their steps verbatim.
VERBATIM = [("camera_flow", ["camera_flow"]), ("middlebury", ["middlebury"]),
            ("sintel", ["sintel"]), ("fusion", ["fusion"]),
            ("pose", ["shelf"]), ("sparse", ["sparse"]), ("tracks", ["tracks"]),
            ("keyframes", ["keyframes"]), ("mrf", ["mrf"]),
            ("kernels", ["kernels", "joint_phases"]), ("synth", ["synth_render", "synth"])]


def render(ctx, w, text):
    want = ctx["want"]
    s = ""
    if want("seg"):
        s += text["seg"] + joint_section(w, "Segmentation")
    if want("depth"):
        s += depth(w, text)
    if want("flow"):
        s += flow(w, text)
    for section, sids in VERBATIM:
        if want(section):
            s += text[section] + verbatim(w, *sids)
    if want("realistic") and w.has("joint_realistic"):
        s += text["realistic"] + verbatim(w, "joint_realistic")
    return s
