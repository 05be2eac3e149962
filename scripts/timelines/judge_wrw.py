#!/usr/bin/env python3
"""Judge of programs/walk_run_wave.mprog, written from its sentence before running:
0–8 s walks (pelvis ground speed 0.6–1.8 m/s), 8–14 s runs (speed > 1.5× the walk's and
> 1.8 m/s), 14–20 s waves both hands (both wrists above the shoulders on ≥ 30% of the
span's frames, pelvis speed < 0.6 m/s), pelvis within 0.5 m of (0, 0, 4) on the ground at
5 s, left wrist above the head at 18 s; torso acceleration ≤ 0.08 m/frame² at the seams.

    python3 scripts/timelines/judge_wrw.py out.npy
"""
import sys

import numpy as np

j = np.load(sys.argv[1])
if j.ndim == 4:
    j = j[0]
F = 20


def speed(a, b):
    p = j[a * F : b * F, 0][:, [0, 2]]
    return np.linalg.norm(np.diff(p, axis=0), axis=1).sum() / (b - a)


walk, run, wave = speed(0, 8), speed(8, 14), speed(14, 20)
span = j[14 * F : 20 * F]
up = ((span[:, 20, 1] > span[:, 16, 1]) & (span[:, 21, 1] > span[:, 17, 1])).mean()
at5 = np.linalg.norm(j[5 * F, 0, [0, 2]] - np.array([0.0, 4.0]))
at18 = j[18 * F, 20, 1] - j[18 * F, 15, 1]
checks = {
    f"walks 0-8 s ({walk:.2f} m/s)": 0.6 <= walk <= 1.8,
    f"runs 8-14 s ({run:.2f} m/s)": run > 1.5 * walk and run > 1.8,
    f"waves 14-20 s (both wrists up {up:.0%}, {wave:.2f} m/s)": up >= 0.3 and wave < 0.6,
    f"pelvis near (0,0,4) at 5 s ({at5:.2f} m)": at5 < 0.5,
    f"left wrist above head at 18 s ({at18:+.2f} m)": at18 > 0,
}
for k, v in checks.items():
    print(("PASS " if v else "FAIL ") + k)
print("right" if all(checks.values()) else "wrong")
