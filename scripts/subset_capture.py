#!/usr/bin/env python3
"""A capture of some frames of another, which records them as far apart.

    scripts/subset_capture.py SRC DST F0,F1,...

Writes DST with the frames F0, F1, ... of the capture SRC (u4d synth's
layout, docs/formats.md) renumbered 0, 1, ...: images, masks, poses and
ground truth hard-linked, capture.json with `source_frames` = F0, F1, ...
(so that frames further apart than `max_frame_gap_s` are cuts in time), the
moving views' per-frame cameras and the ground truth's per-frame lists kept
for those frames only. The ground-truth flow of a kept frame is still to
its next frame in SRC. It builds worlds with cuts from synthetic sequences,
e.g. for the identity across cuts (docs/pipeline.md, "Cuts in time")."""
import json
import os
import shutil
import sys


def subset_json(name, data, keep):
    if name == "capture.json":
        data["num_frames"] = len(keep)
        data["source_frames"] = sorted(keep, key=keep.get)
    elif name == "calibration.json":
        for cam in data.get("cameras", []):
            if isinstance(cam.get("per_frame"), list) and len(cam["per_frame"]) > 1:
                cam["per_frame"] = [cam["per_frame"][f] for f in sorted(keep, key=keep.get)]
    else:  # the ground truth's per-frame lists (contacts, degradation events)
        for key in ("frames", "events"):
            if isinstance(data.get(key), list):
                data[key] = [dict(e, frame=keep[e["frame"]]) for e in data[key]
                             if e.get("frame") in keep]
    return data


def main(src, dst, frames):
    keep = {f: j for j, f in enumerate(frames)}
    if os.path.exists(dst):
        sys.exit("subset_capture.py: %s exists" % dst)
    for root, _, files in os.walk(src):
        rel = os.path.relpath(root, src)
        os.makedirs(os.path.join(dst, rel), exist_ok=True)
        for name in files:
            stem, ext = os.path.splitext(name)
            path, out = os.path.join(root, name), os.path.join(dst, rel, name)
            if stem.isdigit():
                if int(stem) in keep:
                    os.link(path, os.path.join(dst, rel, "%0*d%s" % (len(stem), keep[int(stem)], ext)))
            elif ext == ".json":
                with open(path) as f:
                    data = subset_json(name, json.load(f), keep)
                with open(out, "w") as f:
                    json.dump(data, f, indent=1)
            else:
                shutil.copy2(path, out)


if __name__ == "__main__":
    if len(sys.argv) != 4:
        sys.exit(__doc__)
    main(sys.argv[1], sys.argv[2], [int(x) for x in sys.argv[3].split(",")])
