#!/usr/bin/env python3
"""A picture of a 4D scene written by `u4d run`, for docs: one row per view
with the input image, the initial masks, the refined instances and the depth
of one frame. Usage: scene_montage.py <scene> <frame> <out.png> [row height]"""
import json
import sys
from pathlib import Path

import cv2
import numpy as np


def colour_ids(ids):
    palette = np.array([[0, 0, 0], [180, 119, 31], [14, 127, 255], [44, 160, 44], [40, 39, 214],
                        [189, 103, 148], [75, 86, 140], [194, 119, 227], [127, 127, 127]], np.uint8)
    return palette[np.minimum(ids, len(palette) - 1)]


def main():
    scene, frame, out = Path(sys.argv[1]), int(sys.argv[2]), sys.argv[3]
    height = int(sys.argv[4]) if len(sys.argv) > 4 else 240
    index = json.loads((scene / "scene.json").read_text())
    name = f"{frame:06d}.png"
    rows = []
    for view in index["views"]:
        v = view["name"]
        tiles = [cv2.imread(str(scene / "pictures/image" / v / name))]
        initial = cv2.imread(str(scene / "initial/masks" / v / name), cv2.IMREAD_UNCHANGED)
        tiles.append(colour_ids(initial) if initial is not None else np.zeros_like(tiles[0]))
        tiles.append(cv2.imread(str(scene / "pictures/instances" / v / name)))
        tiles.append(cv2.imread(str(scene / "pictures/depth" / v / name)))
        tiles = [cv2.resize(t, (int(t.shape[1] * height / t.shape[0]), height),
                            interpolation=cv2.INTER_AREA) for t in tiles]
        rows.append(np.hstack(tiles))
    width = max(r.shape[1] for r in rows)
    rows = [np.pad(r, ((0, 0), (0, width - r.shape[1]), (0, 0))) for r in rows]
    picture = np.vstack(rows) if len(rows) <= 3 else np.hstack(
        [np.vstack(rows[i::2]) for i in range(2)] if len(rows) % 2 == 0 else [np.vstack(rows)])
    cv2.imwrite(out, picture, [cv2.IMWRITE_PNG_COMPRESSION, 9])


if __name__ == "__main__":
    main()
