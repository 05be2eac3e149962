"""Judges of bench actions' 13 prompts, mirrored in numpy (thresholds from `mprog bench actions`)."""
import sys, numpy as np
P = [
 ("a person jumps up and down in place", "jump"), ("a man kicks forward with his right leg", "kick"),
 ("a person crouches down low and stands back up", "crouch"), ("a person picks something up from the floor", "pick"),
 ("a person lies down on the floor", "lie"), ("a person runs forward", "run"), ("a person walks forward", "walk"),
 ("a person walks and turns left", "left"), ("a person walks and turns right", "right"), ("a person strolls", "stroll"),
 ("a person hurries", "hurry"), ("a person raises both hands", "raise"), ("a person elevates both arms", "elevate")]
def heading(v): return np.degrees(np.arctan2(v[0], v[1]))
def judge(kind, a):
    y = a[..., 1]; T = len(a) / 20.0
    if kind == "jump":
        v = float(np.minimum(a[:, [7, 10], 1].min(1), a[:, [8, 11], 1].min(1)).max()); return v, v >= 0.15
    if kind == "kick": v = float(y[:, 8].max()); return v, v >= 0.6
    if kind == "crouch": v = float(y[:, 15].min()); return v, v <= 1.15
    if kind == "pick": v = float(y[:, [20, 21]].min()); return v, v <= 0.25
    if kind == "lie": v = float(y[-1, 0]); return v, v <= 0.3
    d = a[-1, 0, [0, 2]] - a[0, 0, [0, 2]]; sp = float(np.linalg.norm(d) / T)
    if kind == "run": return sp, sp >= 2.2
    if kind in ("walk", "stroll", "hurry"): return sp, sp >= 0.34
    if kind in ("left", "right"):
        v0 = a[20, 0, [0, 2]] - a[0, 0, [0, 2]]; v1 = a[-1, 0, [0, 2]] - a[-21, 0, [0, 2]]
        t = (heading(v1) - heading(v0) + 180) % 360 - 180
        return float(t), (t >= 45) if kind == "left" else (t <= -45)
    v = float((a[:, [20, 21], 1].min(1) - y[:, 15].min()).max()); return v, v > 0
out = sys.argv[1]; ok = 0; n = 0
for text, kind in P:
    row = []
    for s in (1, 2):
        a = np.load(f"{out}/{kind}_s{s}.npy"); v, good = judge(kind, a); ok += good; n += 1
        row.append(f"{v:.2f}{'' if good else ' ✗'}")
    print(f"| {text} | {' | '.join(row)} |")
print(f"passed {ok}/{n}")
