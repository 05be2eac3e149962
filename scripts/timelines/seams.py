#!/usr/bin/env python3
"""Seam smoothness of motions made in windows (mprog gen/run longer than the model, or a
prompt timeline): per output, the torso's largest acceleration (pelvis, chest, head;
m/frame² at 20 fps, second difference) around the seams (from each window's first kept
frame to 10 frames after its cut) against inside the windows, plus foot acceleration and
the ground distance travelled. Reads each output's `.npy` and its `.meta.json`
(`windows`). Prints a markdown table.

    python3 scripts/timelines/seams.py out/*.npy
"""
import json
import sys

import numpy as np

TORSO = [0, 9, 15]  # pelvis, chest (spine3), head
FEET = [10, 11]
ENVELOPE = 0.08  # the bar: real torso acceleration stays under it
AFTER = 10


def accel(joints):
    a = joints[2:] - 2 * joints[1:-1] + joints[:-2]
    return np.linalg.norm(a, axis=-1)  # [frames-2, joints]


def measure(path):
    people = np.load(path)
    if people.ndim == 3:
        people = people[None]  # [people, frames, 22, 3]
    meta = json.load(open(path[: -len(".npy")] + ".meta.json"))
    meta = meta.get("meta", meta)
    windows = meta.get("windows") or []
    # Every person's worst joint at each frame (row t: acceleration at frame t+1).
    acc = np.max([accel(j) for j in people], axis=0)
    j = people[0]
    n = acc.shape[0]
    seam = np.zeros(n, bool)
    for start, cut, _end in windows[1:]:
        lo, hi = max(start - 1, 0), min(cut + AFTER, n)
        seam[lo:hi] = True
    torso = acc[:, TORSO].max(axis=1)
    feet = acc[:, FEET].max(axis=1)
    inside = ~seam
    travel = np.linalg.norm(j[-1, 0, [0, 2]] - j[0, 0, [0, 2]])
    # The first person's pelvis path on the ground.
    path_len = np.linalg.norm(np.diff(j[:, 0, [0, 2]], axis=0), axis=1).sum()
    return {
        "file": path.split("/")[-1],
        "seconds": j.shape[0] / 20,
        "windows": len(windows),
        "seam_torso": torso[seam].max() if seam.any() else float("nan"),
        "inside_torso": torso[inside].max(),
        "seam_torso_p95": np.percentile(torso[seam], 95) if seam.any() else float("nan"),
        "inside_torso_p95": np.percentile(torso[inside], 95),
        "seam_feet": feet[seam].max() if seam.any() else float("nan"),
        "inside_feet": feet[inside].max(),
        "path": path_len,
        "travel": travel,
    }


def main(paths):
    rows = [measure(p) for p in paths]
    print(
        "| output | s | windows | torso max at seams | torso max inside | torso p95 seams / inside | feet max seams / inside | path (m) | within 0.08 |"
    )
    print("| --- | --- | --- | --- | --- | --- | --- | --- | --- |")
    for r in rows:
        ok = max(r["seam_torso"], r["inside_torso"]) <= ENVELOPE
        print(
            f"| {r['file']} | {r['seconds']:.0f} | {r['windows']} | {r['seam_torso']:.3f} | {r['inside_torso']:.3f} "
            f"| {r['seam_torso_p95']:.3f} / {r['inside_torso_p95']:.3f} | {r['seam_feet']:.3f} / {r['inside_feet']:.3f} "
            f"| {r['path']:.1f} | {'yes' if ok else 'no'} |"
        )
    s = np.array([r["seam_torso"] for r in rows])
    i = np.array([r["inside_torso"] for r in rows])
    print(
        f"\nmean torso max at seams {np.nanmean(s):.3f}, inside {np.mean(i):.3f}; "
        f"seams worse than inside in {int(np.sum(s > i))} of {len(rows)}"
    )


if __name__ == "__main__":
    main(sys.argv[1:])
