"""Numeric judges for the 22 sentence-level motion tasks in tasks.json.

Each judge takes the array loaded from the .npy ((N,22,3) for one person, (P,N,22,3)
for P people, world metres, Y up, 20 fps) and returns (right: bool, reason: str).
People are taken in the order the sentence names them (index 0 = "the first person").
Written from the sentences alone; start positions are never assumed unless the sentence
states them.

Common checks applied to every task (see _prep):
  * shape matches the number of people, all values finite;
  * duration within max(0.75 s, 15 %) of the seconds asked for;
  * nobody below the floor by more than 5 cm (min joint y >= -0.05);
  * multi-person: pelvises >= 0.3 m apart horizontally at every frame (task-specific
    stricter/looser rules where the sentence implies them, e.g. a hug uses torsos >= 0.15 m).
"""
import math
import numpy as np

FPS = 20.0
(PELVIS, LHIP, RHIP, SPINE1, LKNEE, RKNEE, SPINE2, LANKLE, RANKLE, SPINE3, LFOOT, RFOOT,
 NECK, LCOLLAR, RCOLLAR, HEAD, LSH, RSH, LELB, RELB, LWR, RWR) = range(22)
FEET = [LANKLE, RANKLE, LFOOT, RFOOT]
TORSO = [PELVIS, SPINE1, SPINE2, SPINE3, NECK]

JUDGES = {}   # task id -> judge(j) -> (bool, str)   (with common checks, never raises)
RAW = {}      # task id -> task-specific function on the prepared array (may raise; for tests)
TASKS = {}    # task id -> (people, seconds)


# ----------------------------------------------------------------------------- helpers
def xz(a):
    """horizontal part (x, z) of (..., 3) vectors"""
    return np.asarray(a)[..., [0, 2]]


def unit(v, eps=1e-9):
    n = np.linalg.norm(v, axis=-1, keepdims=True)
    return v / np.maximum(n, eps)


def smooth(x, w):
    """centred moving average along axis 0, edges padded with the end values"""
    x = np.asarray(x, float)
    if w <= 1 or len(x) == 0:
        return x.copy()
    pad = w // 2
    xp = np.concatenate([np.repeat(x[:1], pad, 0), x, np.repeat(x[-1:], w - 1 - pad, 0)], 0)
    c = np.cumsum(np.concatenate([np.zeros_like(x[:1]), xp], 0), 0)
    return (c[w:] - c[:-w]) / w


def left_xz(j, which="both"):
    """unit horizontal 'left' of the body: (l_hip - r_hip) + (l_shoulder - r_shoulder)"""
    l = np.zeros(j.shape[:-2] + (3,))
    if which in ("both", "hips"):
        l = l + (j[..., LHIP, :] - j[..., RHIP, :])
    if which in ("both", "shoulders"):
        l = l + (j[..., LSH, :] - j[..., RSH, :])
    return unit(xz(l))


def facing_xz(j, which="both"):
    """unit horizontal facing (x, z) = cross(left, up) = (-l_z, l_x).
    Check: left = +X  ->  facing = +Z."""
    l = left_xz(j, which)
    return unit(np.stack([-l[..., 1], l[..., 0]], -1))


def yaw_of(f):
    """yaw = atan2(f_x, f_z): 0 when facing +Z, +90 deg when facing +X.
    Turning LEFT (counter-clockwise seen from above) = yaw increasing."""
    return np.arctan2(f[..., 0], f[..., 1])


def yaw_unwrapped(j, which="both"):
    return np.unwrap(yaw_of(facing_xz(j, which)))


def wrapdeg(a):
    return (np.asarray(a) + 180.0) % 360.0 - 180.0


def pelvis_xz(j):
    return xz(j[:, PELVIS])


def hvel(j, w=7):
    """horizontal pelvis velocity (m/s) from a smoothed path, and its norm"""
    p = smooth(pelvis_xz(j), w)
    v = np.gradient(p, axis=0) * FPS
    return v, np.linalg.norm(v, axis=1)


def facing_travel_agreement(j, min_speed=0.4, max_deg=45.0, frames=None):
    """fraction of moving frames whose facing is within max_deg of the travel direction"""
    v, s = hvel(j)
    m = s > min_speed
    if frames is not None:
        mm = np.zeros_like(m)
        mm[frames] = True
        m = m & mm
    if m.sum() == 0:
        return 0.0, 0
    f = facing_xz(j)
    c = np.sum(unit(v[m]) * f[m], axis=1)
    return float(np.mean(c >= math.cos(math.radians(max_deg)))), int(m.sum())


def max_disp(j):
    p = pelvis_xz(j)
    return float(np.max(np.linalg.norm(p - p[0], axis=1)))


def min_pair_pelvis(a):
    P = a.shape[0]
    m = np.inf
    for i in range(P):
        for k in range(i + 1, P):
            d = np.linalg.norm(pelvis_xz(a[i]) - pelvis_xz(a[k]), axis=1).min()
            m = min(m, float(d))
    return m


def episodes(x, enter, exit_, above=True):
    """hysteresis episodes: enter when x >= enter (or <= if not above), leave at exit_"""
    eps, inside, s = [], False, 0
    for i, v in enumerate(x):
        if not inside and (v >= enter if above else v <= enter):
            inside, s = True, i
        elif inside and (v <= exit_ if above else v >= exit_):
            inside = False
            eps.append((s, i))
    if inside:
        eps.append((s, len(x)))
    return eps


def runs(mask):
    m = np.concatenate([[0], np.asarray(mask).astype(int), [0]])
    d = np.diff(m)
    return list(zip(np.where(d == 1)[0], np.where(d == -1)[0]))


def longest_run(mask):
    r = runs(mask)
    return max([e - s for s, e in r], default=0)


def towards(a, i, k, t, max_deg):
    """person i at frame t faces person k within max_deg"""
    f = facing_xz(a[i][t:t + 1])[0]
    d = unit(pelvis_xz(a[k])[t] - pelvis_xz(a[i])[t])
    c = float(np.dot(f, d))
    return c >= math.cos(math.radians(max_deg)), math.degrees(math.acos(max(-1, min(1, c))))


class Checks:
    def __init__(self):
        self.items = []

    def add(self, name, ok, val):
        self.items.append((name, bool(ok), val))
        return bool(ok)

    def result(self):
        ok = all(o for _, o, _ in self.items)
        body = "; ".join(f"{n} {v}{'' if o else ' [FAIL]'}" for n, o, v in self.items)
        return ok, ("PASS: " if ok else "FAIL: ") + body


def _prep(j, people, seconds, pelvis_rule=True):
    a = np.asarray(j, dtype=float)
    if people == 1:
        if a.ndim == 4 and a.shape[0] == 1:
            a = a[0]
        if a.ndim != 3 or a.shape[1:] != (22, 3):
            return None, f"bad shape {a.shape}, expected (N,22,3)"
        n = a.shape[0]
    else:
        if a.ndim != 4 or a.shape[0] != people or a.shape[2:] != (22, 3):
            return None, f"bad shape {a.shape}, expected ({people},N,22,3)"
        n = a.shape[1]
    if n < 10:
        return None, f"only {n} frames"
    if not np.all(np.isfinite(a)):
        return None, "non-finite values"
    dur = n / FPS
    tol = max(0.75, 0.15 * seconds)           # duration tolerance
    if abs(dur - seconds) > tol:
        return None, f"duration {dur:.2f}s vs asked {seconds}s (tol +-{tol:.2f}s)"
    miny = float(a[..., 1].min())
    if miny < -0.05:                           # floor penetration tolerance 5 cm
        return None, f"below the floor: min joint y {miny:.3f} m < -0.05"
    if people > 1 and pelvis_rule:
        mp = min_pair_pelvis(a)
        if mp < 0.3:                           # interpenetration: pelvises >= 0.3 m
            return None, f"people interpenetrate: min pelvis distance {mp:.2f} m < 0.3"
    return a, ""


TASKS_PELVIS_RULE = {}   # task id -> False where the sentence allows closer contact (hug)


def task(tid, people, seconds, pelvis_rule=True):
    def deco(fn):
        TASKS[tid] = (people, seconds)
        TASKS_PELVIS_RULE[tid] = pelvis_rule
        RAW[tid] = fn

        def judge(j, _fn=fn, _tid=tid):
            try:
                a, why = _prep(j, people, seconds, pelvis_rule)
                if a is None:
                    return False, "FAIL: " + why
                ok, msg = _fn(a)
                return bool(ok), msg
            except Exception as e:  # a judge must answer, never crash
                return False, f"FAIL: judge error {type(e).__name__}: {e}"
        JUDGES[tid] = judge
        return fn
    return deco


LAST = lambda n, s: slice(max(0, n - int(round(s * FPS))), n)   # last s seconds


# ----------------------------------------------------------------------------- judges
@task("t01", 1, 8)
def t01(j):
    """sits down on the floor, stays sitting for the last 2 s"""
    c = Checks()
    n = len(j)
    w = LAST(n, 2.0)
    py = j[:, PELVIS, 1]
    c.add("starts standing (pelvis y0>=0.75)", py[0] >= 0.75, f"{py[0]:.2f}")
    # sitting ON THE FLOOR: pelvis joint <= 0.30 m (chair ~0.5, squat >= ~0.35)
    c.add("last 2s pelvis y max<=0.30", py[w].max() <= 0.30, f"{py[w].max():.2f}")
    # sitting upright, not lying: head >= 0.35 m above pelvis
    hp = (j[w, HEAD, 1] - py[w]).min()
    c.add("head-pelvis min>=0.35", hp >= 0.35, f"{hp:.2f}")
    # held: pelvis height range <= 8 cm, pelvis drift <= 15 cm in the window
    pys = smooth(py, 3)[w]                     # 3-frame smoothing against joint jitter
    c.add("pelvis y range<=0.08", np.ptp(pys) <= 0.08, f"{np.ptp(pys):.3f}")
    pw = pelvis_xz(j)[w]
    dr = np.linalg.norm(pw - pw.mean(0), axis=1).max()
    c.add("pelvis drift<=0.15", dr <= 0.15, f"{dr:.3f}")
    return c.result()


@task("t02", 1, 5)
def t02(j):
    """raises both hands above the head and keeps them there until the end"""
    c = Checks()
    n = len(j)
    hy = j[:, HEAD, 1]
    lw, rw = j[:, LWR, 1] - hy, j[:, RWR, 1] - hy
    c.add("hands start below head", (lw[0] < 0) and (rw[0] < 0), f"L{lw[0]:+.2f} R{rw[0]:+.2f}")
    # above the head: wrist >= 10 cm above the head joint, every frame of the last 2 s
    w = LAST(n, 2.0)
    m = min(lw[w].min(), rw[w].min())
    c.add("last 2s min(wrist-head)>=0.10", m >= 0.10, f"{m:+.2f}")
    return c.result()


@task("t03", 1, 8)
def t03(j):
    """one full clockwise circle ~2 m across, ends at the start"""
    c = Checks()
    p = smooth(pelvis_xz(j), 5)
    x, z = p[:, 0], p[:, 1]
    A = np.stack([x, z, np.ones_like(x)], 1)
    sol = np.linalg.lstsq(A, -(x ** 2 + z ** 2), rcond=None)[0]
    cx, cz = -sol[0] / 2, -sol[1] / 2
    r = math.sqrt(max(cx ** 2 + cz ** 2 - sol[2], 0.0))
    # diameter about 2 m: radius 0.65..1.5 m
    c.add("radius 0.65..1.5", 0.65 <= r <= 1.5, f"{r:.2f}")
    res = np.sqrt(np.mean((np.hypot(x - cx, z - cz) - r) ** 2))
    # round: rms distance from the fitted circle <= 25 % of the radius
    c.add("rms off-circle<=0.25r", res <= 0.25 * max(r, 1e-6), f"{res:.2f}")
    phi = np.unwrap(np.arctan2(x - cx, z - cz))
    sweep = math.degrees(phi[-1] - phi[0])
    # clockwise seen from above = angle decreasing; one full circle: -300..-480 deg
    c.add("sweep -480..-300deg", -480 <= sweep <= -300, f"{sweep:.0f}")
    end = np.linalg.norm(pelvis_xz(j)[-1] - pelvis_xz(j)[0])
    c.add("end-start<=0.6", end <= 0.6, f"{end:.2f}")
    fr, nm = facing_travel_agreement(j)
    c.add("facing along travel>=80%", fr >= 0.8 and nm >= 20, f"{fr:.2f} (n={nm})")
    return c.result()


@task("t04", 1, 8)
def t04(j):
    """square with ~1.5 m sides, left turns, back to the start"""
    c = Checks()
    p = smooth(pelvis_xz(j), 5)
    k = 10                                    # headings over 0.5 s windows
    v = (p[k:] - p[:-k]) / (k / FPS)
    s = np.linalg.norm(v, axis=1)
    m = s > 0.3
    cz = p[:, 1] + 1j * p[:, 0]               # complex (z + i x): arg = atan2(x, z) = yaw
    if m.sum() < 10:
        c.add("moving", False, f"{int(m.sum())} moving windows")
        return c.result()
    th = np.arctan2(v[m, 0], v[m, 1])
    z4 = np.sum(s[m] * np.exp(4j * th)) / np.sum(s[m])
    R4 = abs(z4)
    # straight sides at right angles: headings cluster 90 deg apart (R4 >= 0.5; circle ~0)
    c.add("4-fold heading R>=0.5", R4 >= 0.5, f"{R4:.2f}")
    q = cz * np.exp(-1j * np.angle(z4) / 4)
    re, im = q.real, q.imag
    sides = (np.ptp(re), np.ptp(im))
    c.add("sides 1.0..2.2", all(1.0 <= sd <= 2.2 for sd in sides), f"{sides[0]:.2f}x{sides[1]:.2f}")
    de = np.min(np.stack([re - re.min(), re.max() - re, im - im.min(), im.max() - im]), 0)
    fe = float(np.mean(de <= 0.25))
    c.add("on box edges(<=0.25m)>=85%", fe >= 0.85, f"{fe:.2f}")
    corners = [complex(a, b) for a in (re.min(), re.max()) for b in (im.min(), im.max())]
    cd = max(float(np.min(np.abs(q - cc))) for cc in corners)
    c.add("each corner visited<=0.35m", cd <= 0.35, f"worst {cd:.2f}")
    end = np.linalg.norm(pelvis_xz(j)[-1] - pelvis_xz(j)[0])
    c.add("end-start<=0.5", end <= 0.5, f"{end:.2f}")
    yw = yaw_unwrapped(j)
    dy = math.degrees(np.mean(yw[-5:]) - np.mean(yw[:5]))
    # left turns = yaw increasing; 3 or 4 corners turned: +200..+450 deg
    c.add("turned left +200..+450deg", 200 <= dy <= 450, f"{dy:.0f}")
    fr, nm = facing_travel_agreement(j)
    c.add("facing along travel>=75%", fr >= 0.75, f"{fr:.2f}")
    return c.result()


@task("t05", 1, 7)
def t05(j):
    """walk forward ~3 m, turn around, walk back to the start"""
    c = Checks()
    p = pelvis_xz(j) - pelvis_xz(j)[0]
    d = np.linalg.norm(p, axis=1)
    k = int(np.argmax(d))
    c.add("far point 2.2..4.0 m", 2.2 <= d[k] <= 4.0, f"{d[k]:.2f}")
    f0 = unit(facing_xz(j[:5]).mean(0))
    ang = math.degrees(math.acos(np.clip(np.dot(unit(p[k]), f0), -1, 1)))
    c.add("went forward (<=30deg)", ang <= 30, f"{ang:.0f}deg")
    c.add("back at start<=0.5", d[-1] <= 0.5, f"{d[-1]:.2f}")
    fo, no = facing_travel_agreement(j, frames=np.arange(0, k))
    fb, nb = facing_travel_agreement(j, frames=np.arange(k, len(j)))
    # walks forwards both ways (turns around, no backward walking)
    c.add("facing travel out>=75%", fo >= 0.75 and no >= 10, f"{fo:.2f}")
    c.add("facing travel back>=75%", fb >= 0.75 and nb >= 10, f"{fb:.2f}")
    return c.result()


@task("t06", 1, 6)
def t06(j):
    """jog forward straight at ~2 m/s"""
    c = Checks()
    n = len(j)
    p = smooth(pelvis_xz(j), 5)
    s0, e = int(FPS * 1.0), n - 5             # skip the first second (speeding up)
    sp = np.linalg.norm(p[e] - p[s0]) / ((e - s0) / FPS)
    # about 2 m/s: 1.6..2.5 m/s average after the first second
    c.add("avg speed 1.6..2.5", 1.6 <= sp <= 2.5, f"{sp:.2f} m/s")
    win = [np.linalg.norm(p[t + 20] - p[t]) for t in range(s0, e - 19, 10)]
    # steady: every 1-s window 1.3..2.8 m/s
    c.add("1s windows 1.3..2.8", len(win) > 0 and min(win) >= 1.3 and max(win) <= 2.8,
          f"{min(win):.2f}..{max(win):.2f}" if win else "none")
    d = p[-1] - p[0]
    u = unit(d)
    lat = np.abs((p - p[0]) @ np.array([-u[1], u[0]])).max()
    c.add("straight: lateral<=0.5", lat <= 0.5, f"{lat:.2f}")
    f0 = unit(facing_xz(j[:5]).mean(0))
    ang = math.degrees(math.acos(np.clip(np.dot(u, f0), -1, 1)))
    c.add("forward (<=30deg)", ang <= 30, f"{ang:.0f}deg")
    fr, _ = facing_travel_agreement(j)
    c.add("facing along travel>=80%", fr >= 0.8, f"{fr:.2f}")
    return c.result()


@task("t07", 1, 4)
def t07(j):
    """turn around to the left in place"""
    c = Checks()
    y = np.degrees(yaw_unwrapped(j))
    y = y - y[0]
    dy = float(np.mean(y[-10:]))
    # left = yaw increasing (+Z towards +X); half turn 150..210 deg
    c.add("yaw change +150..+210", 150 <= dy <= 210, f"{dy:+.0f}deg")
    c.add("never turned right>30", y.min() >= -30, f"min {y.min():+.0f}")
    md = max_disp(j)
    c.add("in place<=0.6m", md <= 0.6, f"{md:.2f}")
    return c.result()


@task("t08", 1, 7)
def t08(j):
    """three squats to thighs ~level, standing up each time"""
    c = Checks()
    py = j[:, PELVIS, 1]
    ky = 0.5 * (j[:, LKNEE, 1] + j[:, RKNEE, 1])
    h0 = float(np.percentile(py, 95))
    c.add("stands (pelvis p95>=0.8)", h0 >= 0.8, f"{h0:.2f}")
    eps = episodes(py, h0 - 0.30, h0 - 0.10, above=False)
    c.add("3 squats", len(eps) == 3, f"{len(eps)}")
    # thighs about level: pelvis at most 15 cm above the knees; not sitting (>=0.3 m)
    deep = [float((py[s:e] - ky[s:e]).min()) for s, e in eps]
    low = [float(py[s:e].min()) for s, e in eps]
    c.add("each deep (pelvis-knee<=0.15)", len(deep) > 0 and max(deep) <= 0.15,
          "[" + ",".join(f"{d:.2f}" for d in deep) + "]")
    c.add("not on floor (pelvis>=0.3)", len(low) > 0 and min(low) >= 0.3,
          f"{min(low):.2f}" if low else "-")
    c.add("ends standing (>=h0-0.15)", py[-1] >= h0 - 0.15, f"{py[-1]:.2f}")
    md = max_disp(j)
    c.add("in place<=0.4", md <= 0.4, f"{md:.2f}")
    return c.result()


@task("t09", 1, 5)
def t09(j):
    """three claps above the head"""
    c = Checks()
    d = np.linalg.norm(j[:, LWR] - j[:, RWR], axis=1)
    # a clap: wrists closer than 15 cm, then apart again beyond 22 cm
    eps = episodes(d, 0.15, 0.22, above=False)
    above = 0
    for s, e in eps:
        t = s + int(np.argmin(d[s:e]))
        if min(j[t, LWR, 1], j[t, RWR, 1]) >= j[t, HEAD, 1] + 0.10:   # 10 cm above head
            above += 1
    c.add("claps total==3", len(eps) == 3, f"{len(eps)}")
    c.add("claps above head==3", above == 3, f"{above}")
    return c.result()


@task("t10", 2, 6)
def t10(a):
    """facing each other; A's right hand on B's left shoulder for the last 2 s"""
    c = Checks()
    A, B = a[0], a[1]
    n = A.shape[0]
    okA, angA = towards(a, 0, 1, 0, 45)
    okB, angB = towards(a, 1, 0, 0, 45)
    c.add("face each other at start(<=45)", okA and okB, f"{angA:.0f}/{angB:.0f}deg")
    w = LAST(n, 2.0)
    d = np.linalg.norm(A[w, RWR] - B[w, LSH], axis=1)
    # resting hand: wrist joint within 20 cm of the shoulder joint in every frame
    c.add("last 2s A.rhand-B.lshoulder max<=0.20", d.max() <= 0.20, f"{d.max():.2f}")
    dl = np.linalg.norm(A[w, LWR] - B[w, LSH], axis=1).min()
    c.add("info A.lhand-B.lsh", True, f"{dl:.2f}")
    c.add("min pelvis dist>=0.3", min_pair_pelvis(a) >= 0.3, f"{min_pair_pelvis(a):.2f}")
    return c.result()


@task("t11", 2, 7, pelvis_rule=False)
def t11(a):
    """walk up to each other, hug, hold the last 2 s"""
    c = Checks()
    A, B = a[0], a[1]
    n = A.shape[0]
    pA, pB = pelvis_xz(A), pelvis_xz(B)
    d0 = np.linalg.norm(pB[0] - pA[0])
    c.add("start apart>=1.0", d0 >= 1.0, f"{d0:.2f}")
    u = unit(pB[0] - pA[0])
    wA = float(np.dot(pA[-1] - pA[0], u))
    wB = float(np.dot(pB[-1] - pB[0], -u))
    c.add("both walk towards>=0.2", wA >= 0.2 and wB >= 0.2, f"{wA:.2f}/{wB:.2f}")
    w = LAST(n, 2.0)
    cc = np.linalg.norm(xz(A[w, SPINE3]) - xz(B[w, SPINE3]), axis=1)
    # chests together: <= 0.5 m horizontally
    f1 = float(np.mean(cc <= 0.5))

    def arms_around(X, Y):
        tor = Y[:, [SPINE1, SPINE2, SPINE3, NECK]]
        dl = np.linalg.norm(X[:, LWR][:, None] - tor, axis=2).min(1)
        dr = np.linalg.norm(X[:, RWR][:, None] - tor, axis=2).min(1)
        return (dl <= 0.4) & (dr <= 0.4)      # both hands around the other (<= 0.4 m of spine)
    f2 = float(np.mean(arms_around(A[w], B[w])))
    f3 = float(np.mean(arms_around(B[w], A[w])))
    # held: >= 90 % of the last 2 s frames
    c.add("chests<=0.5 (>=90%)", f1 >= 0.9, f"{f1:.2f} (median {np.median(cc):.2f})")
    c.add("A arms round B (>=90%)", f2 >= 0.9, f"{f2:.2f}")
    c.add("B arms round A (>=90%)", f3 >= 0.9, f"{f3:.2f}")
    fa, fb = facing_xz(A[w]), facing_xz(B[w])
    fd = float(np.median(np.sum(fa * fb, 1)))
    c.add("face each other (dot<=-0.5)", fd <= -0.5, f"{fd:.2f}")
    # no interpenetration for a hug: torso joints >= 0.15 m apart at every frame
    td = np.linalg.norm(A[:, TORSO][:, :, None] - B[:, TORSO][:, None, :], axis=3).min()
    c.add("torsos>=0.15", td >= 0.15, f"{td:.2f}")
    return c.result()


@task("t12", 2, 7)
def t12(a):
    """6 m apart facing each other, walk towards, pass without touching, keep walking"""
    c = Checks()
    A, B = a[0], a[1]
    pA, pB = pelvis_xz(A), pelvis_xz(B)
    d0 = np.linalg.norm(pB[0] - pA[0])
    c.add("start 5..7 m apart", 5.0 <= d0 <= 7.0, f"{d0:.2f}")
    okA, angA = towards(a, 0, 1, 0, 30)
    okB, angB = towards(a, 1, 0, 0, 30)
    c.add("face each other (<=30)", okA and okB, f"{angA:.0f}/{angB:.0f}deg")
    u = unit(pB[0] - pA[0])
    sA, sB = (pA - pA[0]) @ u, (pB - pA[0]) @ u
    gap = float(sA[-1] - sB[-1])
    # passed and walked on: A ends >= 1 m beyond B along the line
    c.add("passed by>=1.0 m", gap >= 1.0, f"{gap:.2f}")
    tA, tB = float(sA[-1]), float(d0 - sB[-1])
    c.add("each travelled>=3.5", tA >= 3.5 and tB >= 3.5, f"{tA:.2f}/{tB:.2f}")
    nrm = np.array([-u[1], u[0]])
    lA = np.abs((pA - pA[0]) @ nrm).max()
    lB = np.abs((pB - pB[0]) @ nrm).max()
    c.add("roughly straight (lateral<=1.0)", lA <= 1.0 and lB <= 1.0, f"{lA:.2f}/{lB:.2f}")
    # without touching: every joint pair >= 12 cm apart (joints sit inside ~5 cm of flesh)
    jd = np.linalg.norm(A[:, :, None] - B[:, None, :], axis=3).min()
    c.add("no touch (joints>=0.12)", jd >= 0.12, f"{jd:.2f}")
    c.add("pelvis>=0.3", min_pair_pelvis(a) >= 0.3, f"{min_pair_pelvis(a):.2f}")
    fa, _ = facing_travel_agreement(A)
    fb, _ = facing_travel_agreement(B)
    c.add("walk facing travel>=75%", fa >= 0.75 and fb >= 0.75, f"{fa:.2f}/{fb:.2f}")
    return c.result()


@task("t13", 2, 5)
def t13(a):
    """side by side ~1 m apart, same facing, walk forward together ~3 m"""
    c = Checks()
    A, B = a[0], a[1]
    pA, pB = pelvis_xz(A), pelvis_xz(B)
    fA0, fB0 = unit(facing_xz(A[:5]).mean(0)), unit(facing_xz(B[:5]).mean(0))
    c.add("same facing at start(<=30)", np.dot(fA0, fB0) >= math.cos(math.radians(30)),
          f"{math.degrees(math.acos(np.clip(np.dot(fA0, fB0), -1, 1))):.0f}deg")
    f = unit(fA0 + fB0)
    off = pB - pA
    d0 = np.linalg.norm(off[0])
    c.add("start 0.7..1.3 apart", 0.7 <= d0 <= 1.3, f"{d0:.2f}")
    along = np.abs(off @ f)
    c.add("side by side at start(|along|<=0.3)", along[0] <= 0.3, f"{along[0]:.2f}")
    fwdA, fwdB = float((pA[-1] - pA[0]) @ f), float((pB[-1] - pB[0]) @ f)
    c.add("each forward 2.2..4.0", all(2.2 <= x <= 4.0 for x in (fwdA, fwdB)), f"{fwdA:.2f}/{fwdB:.2f}")
    dist = np.linalg.norm(off, axis=1)
    # together throughout: 0.5..1.6 m apart and neither >0.5 m ahead
    c.add("apart 0.5..1.6 always", dist.min() >= 0.5 and dist.max() <= 1.6,
          f"{dist.min():.2f}..{dist.max():.2f}")
    c.add("abreast (|along|<=0.5)", along.max() <= 0.5, f"{along.max():.2f}")
    fa, _ = facing_travel_agreement(A)
    fb, _ = facing_travel_agreement(B)
    c.add("facing travel>=75%", fa >= 0.75 and fb >= 0.75, f"{fa:.2f}/{fb:.2f}")
    return c.result()


@task("t14", 3, 6)
def t14(a):
    """three in single file ~1 m apart, same facing, walk forward together"""
    c = Checks()
    P = a.shape[0]
    fs = [unit(facing_xz(a[i][:5]).mean(0)) for i in range(P)]
    mind = min(float(np.dot(fs[i], fs[k])) for i in range(P) for k in range(i + 1, P))
    c.add("same facing(<=30)", mind >= math.cos(math.radians(30)),
          f"max {math.degrees(math.acos(np.clip(mind, -1, 1))):.0f}deg")
    f = unit(sum(fs))
    nrm = np.array([-f[1], f[0]])
    p = np.stack([pelvis_xz(a[i]) for i in range(P)])       # (P,N,2)
    s = p @ f                                               # along facing
    l = p @ nrm                                             # sideways
    order = np.argsort(s[:, 0])
    gaps0 = np.diff(s[order, 0])
    c.add("start gaps 0.6..1.5", gaps0.min() >= 0.6 and gaps0.max() <= 1.5,
          ",".join(f"{g:.2f}" for g in gaps0))
    lat0 = np.ptp(l[:, 0])
    c.add("start in line (lat spread<=0.3)", lat0 <= 0.3, f"{lat0:.2f}")
    fwd = s[:, -1] - s[:, 0]
    c.add("each forward>=2.5", fwd.min() >= 2.5, ",".join(f"{x:.1f}" for x in fwd))
    gaps = np.diff(s[order], axis=0)                        # keeps start order
    c.add("order kept, gaps 0.4..2.2", gaps.min() >= 0.4 and gaps.max() <= 2.2,
          f"{gaps.min():.2f}..{gaps.max():.2f}")
    lat = np.ptp(l, axis=0).max()
    c.add("single file (lat spread<=0.6)", lat <= 0.6, f"{lat:.2f}")
    fr = [facing_travel_agreement(a[i])[0] for i in range(P)]
    c.add("facing travel>=75%", min(fr) >= 0.75, ",".join(f"{x:.2f}" for x in fr))
    return c.result()


@task("t15", 1, 5)
def t15(j):
    """arms straight out to the sides at shoulder height, held the last 2 s"""
    c = Checks()
    n = len(j)
    w = LAST(n, 2.0)
    L = left_xz(j)
    for name, sh, el, wr, sign in (("L", LSH, LELB, LWR, 1.0), ("R", RSH, RELB, RWR, -1.0)):
        arm = j[w, wr] - j[w, sh]
        dy = np.abs(arm[:, 1]).max()
        c.add(f"{name} wrist at shoulder height(<=0.15)", dy <= 0.15, f"{dy:.2f}")
        full = np.median(np.linalg.norm(j[:, el] - j[:, sh], axis=1)
                         + np.linalg.norm(j[:, wr] - j[:, el], axis=1))
        st = (np.linalg.norm(arm, axis=1) / full).min()
        c.add(f"{name} straight(>=0.9)", st >= 0.9, f"{st:.2f}")
        # out to the side: within ~30 deg of the body's left/right axis
        cs = (np.sum(xz(arm) * L[w], 1) * sign / np.linalg.norm(arm, axis=1)).min()
        c.add(f"{name} sideways(cos>=0.85)", cs >= 0.85, f"{cs:.2f}")
        hold = np.linalg.norm(j[w, wr] - j[w, wr].mean(0), axis=1).max()
        c.add(f"{name} held(<=0.15)", hold <= 0.15, f"{hold:.2f}")
    md = max_disp(j)
    c.add("stands still(<=0.3)", md <= 0.3, f"{md:.2f}")
    return c.result()


@task("t16", 1, 8)
def t16(j):
    """lies down on the back, stays lying the last 2 s"""
    c = Checks()
    n = len(j)
    w = LAST(n, 2.0)
    c.add("starts upright(pelvis>=0.7)", j[0, PELVIS, 1] >= 0.7, f"{j[0, PELVIS, 1]:.2f}")
    mx = max(j[w, PELVIS, 1].max(), j[w, SPINE3, 1].max(), j[w, HEAD, 1].max())
    c.add("on floor: pelvis/chest/head<=0.35", j[w, PELVIS, 1].max() <= 0.30 and mx <= 0.35,
          f"pelvis {j[w, PELVIS, 1].max():.2f} max {mx:.2f}")
    hd = np.linalg.norm(xz(j[w, HEAD] - j[w, PELVIS]), axis=1).min()
    c.add("stretched out(head-pelvis horiz>=0.4)", hd >= 0.4, f"{hd:.2f}")
    left = (j[w, LHIP] - j[w, RHIP]) + (j[w, LSH] - j[w, RSH])
    spine = j[w, NECK] - j[w, PELVIS]
    front = unit(np.cross(left, spine))       # standing: cross(+X, +Y) = +Z = front
    up = front[:, 1]
    # on the back: chest faces up (within ~45 deg in median, never worse than 60 deg)
    c.add("supine(front.y med>=0.7,min>=0.5)", np.median(up) >= 0.7 and up.min() >= 0.5,
          f"{np.median(up):.2f}/{up.min():.2f}")
    hold = max(np.linalg.norm(j[w, k] - j[w, k].mean(0), axis=1).max() for k in (PELVIS, HEAD))
    c.add("held(<=0.15)", hold <= 0.15, f"{hold:.2f}")
    return c.result()


@task("t17", 1, 8)
def t17(j):
    """right hand circles in front of the chest, one every 2 s"""
    c = Checks()
    s0 = int(FPS)                             # ignore the first second (raising the hand)
    rel = j[:, RWR].copy()
    rel[:, [0, 2]] -= j[:, PELVIS][:, [0, 2]]
    X = rel[s0:] - rel[s0:].mean(0)
    _, S, Vt = np.linalg.svd(X, full_matrices=False)
    cc = X @ Vt[:2].T
    rad = float(np.median(np.linalg.norm(cc, axis=1)))
    c.add("big (radius>=0.15)", rad >= 0.15, f"{rad:.2f}")
    ratio = S[1] / max(S[0], 1e-9)
    c.add("round (sv ratio>=0.4)", ratio >= 0.4, f"{ratio:.2f}")
    phi = np.unwrap(np.arctan2(cc[:, 1], cc[:, 0]))
    tot = phi[-1] - phi[0]
    revs = abs(tot) / (2 * math.pi)
    # 7 s analysed at one circle per 2 s = 3.5; tolerance: period 1.55..2.7 s
    c.add("revolutions 2.6..4.5", 2.6 <= revs <= 4.5, f"{revs:.2f}")
    dphi = np.diff(phi) * np.sign(tot if tot != 0 else 1)
    cons = float(np.mean(dphi > 0))
    c.add("one direction (>=75%)", cons >= 0.75, f"{cons:.2f}")
    prog = np.abs(phi - phi[0])
    times = [int(np.argmax(prog >= 2 * math.pi * k)) for k in range(1, int(revs) + 1)]
    iv = np.diff(times) / FPS
    c.add("each circle 1.4..2.8 s", len(iv) >= 1 and iv.min() >= 1.4 and iv.max() <= 2.8,
          ",".join(f"{x:.1f}" for x in iv) if len(iv) else "none")
    fwd = float(np.mean(np.sum(xz(j[s0:, RWR] - j[s0:, SPINE3]) * facing_xz(j[s0:]), 1)))
    c.add("in front of chest(>=0.15)", fwd >= 0.15, f"{fwd:.2f}")
    md = max_disp(j)
    c.add("in place(<=0.4)", md <= 0.4, f"{md:.2f}")
    return c.result()


@task("t18", 1, 6)
def t18(j):
    """step left and back, twice"""
    c = Checks()
    p = smooth(pelvis_xz(j), 3) - pelvis_xz(j)[0]
    f0 = unit(facing_xz(j[:5]).mean(0))
    l0 = np.array([f0[1], -f0[0]])            # left = facing rotated: facing +Z -> left +X
    lat, fwd = p @ l0, p @ f0
    eps = episodes(lat, 0.15, 0.07, above=True)
    c.add("left steps==2", len(eps) == 2, f"{len(eps)}")
    c.add("step size 0.2..0.9", 0.2 <= lat.max() <= 0.9, f"{lat.max():.2f}")
    c.add("not right of start(>=-0.2)", lat.min() >= -0.2, f"{lat.min():.2f}")
    c.add("ends at start(|lat|<=0.15)", abs(lat[-1]) <= 0.15, f"{lat[-1]:.2f}")
    c.add("no forward drift(<=0.35)", np.abs(fwd).max() <= 0.35, f"{np.abs(fwd).max():.2f}")
    y = np.degrees(yaw_unwrapped(j))
    ty = np.abs(y - y[0]).max()
    c.add("keeps facing(<=30deg)", ty <= 30, f"{ty:.0f}")
    return c.result()


@task("t19", 1, 5)
def t19(j):
    """looks back over the left shoulder, held ~2 s"""
    c = Checks()
    yh = smooth(yaw_unwrapped(j, "hips"), 5)        # 0.25 s smoothing against joint jitter
    ys = smooth(yaw_unwrapped(j, "shoulders"), 5)
    tw = wrapdeg(np.degrees(ys - yh))         # + = shoulders turned left of the hips
    hv = smooth(xz(j[:, HEAD] - j[:, NECK]), 5)
    hl = np.linalg.norm(hv, axis=1)
    hrel = wrapdeg(np.degrees(yaw_of(unit(hv)) - yh))
    # looking back left: shoulders >= 60 deg left of hips, or >= 30 deg with the head
    # displaced >= 75 deg to the left of the hips' facing (>= 3 cm horizontally)
    look = (tw >= 60) | ((tw >= 30) & (hrel >= 75) & (hl >= 0.03))
    lr = longest_run(look) / FPS
    c.add("look-back held>=1.5s", lr >= 1.5, f"{lr:.2f}s (max twist {tw.max():.0f}, "
          f"min {tw.min():.0f})")
    md = max_disp(j)
    c.add("stands still(<=0.4)", md <= 0.4, f"{md:.2f}")
    return c.result()


@task("t20", 1, 3)
def t20(j):
    """one two-footed jump forward ~1 m"""
    c = Checks()
    mf = j[:, FEET, 1].min(1)
    base = float(np.percentile(mf, 5))
    air = mf > base + 0.06                   # both feet >= 6 cm above the usual ground level
    a2 = air.copy()
    a2[1:-1] |= air[:-2] & air[2:]           # close 1-frame gaps
    rr = [(s, e) for s, e in runs(a2) if e - s >= 2]   # flights of >= 0.1 s
    c.add("one flight", len(rr) == 1, f"{len(rr)} ({','.join(str(e - s) for s, e in rr)} frames)")
    f0 = unit(facing_xz(j[:5]).mean(0))
    p = pelvis_xz(j) - pelvis_xz(j)[0]
    fw, lt = float(p[-1] @ f0), float(abs(p[-1] @ np.array([f0[1], -f0[0]])))
    c.add("forward 0.6..1.6", 0.6 <= fw <= 1.6, f"{fw:.2f}")
    c.add("lateral<=0.4", lt <= 0.4, f"{lt:.2f}")
    if rr:
        s, e = rr[0]
        ad = float((p[min(e, len(p) - 1)] - p[max(s - 1, 0)]) @ f0)
        c.add("forward in the air>=0.3", ad >= 0.3, f"{ad:.2f}")
    c.add("lands upright(pelvis end>=0.6)", j[-1, PELVIS, 1] >= 0.6, f"{j[-1, PELVIS, 1]:.2f}")
    return c.result()


@task("t21", 1, 3)
def t21(j):
    """one front kick with the right foot"""
    c = Checks()
    ry, ly = j[:, RANKLE, 1], j[:, LANKLE, 1]
    br, bl = float(np.percentile(ry, 10)), float(np.percentile(ly, 10))
    k = int(np.argmax(ry))
    c.add("right foot rises>=0.35", ry[k] - br >= 0.35, f"{ry[k] - br:.2f}")
    f0 = unit(facing_xz(j[:5]).mean(0))
    fw = float(xz(j[k, RANKLE] - j[k, PELVIS]) @ f0)
    c.add("kick forward(>=0.3 ahead of pelvis)", fw >= 0.3, f"{fw:.2f}")
    c.add("left foot supports at kick(<=0.15)", ly[k] - bl <= 0.15, f"{ly[k] - bl:.2f}")
    eps = episodes(ry - br, 0.25, 0.12, above=True)
    c.add("once", len(eps) == 1, f"{len(eps)}")
    c.add("left foot stays low(<=0.3)", (ly - bl).max() <= 0.3, f"{(ly - bl).max():.2f}")
    md = max_disp(j)
    c.add("roughly in place(<=1.0)", md <= 1.0, f"{md:.2f}")
    return c.result()


@task("t22", 2, 5)
def t22(a):
    """3 m apart facing each other, both wave with the right hand ~4 s"""
    c = Checks()
    A, B = a[0], a[1]
    n = A.shape[0]
    d0 = np.linalg.norm(pelvis_xz(B)[0] - pelvis_xz(A)[0])
    c.add("start 2.4..3.6 apart", 2.4 <= d0 <= 3.6, f"{d0:.2f}")
    for t in (0, n // 2):
        okA, angA = towards(a, 0, 1, t, 45)
        okB, angB = towards(a, 1, 0, t, 45)
        c.add(f"face each other f{t}(<=45)", okA and okB, f"{angA:.0f}/{angB:.0f}deg")
    for name, X in (("A", A), ("B", B)):
        raised = X[:, RWR, 1] >= X[:, RSH, 1]            # hand up at/above the shoulder
        c.add(f"{name} hand up>=2.5s", raised.sum() / FPS >= 2.5, f"{raised.sum() / FPS:.1f}s")
        lat = np.sum(xz(X[:, RWR] - X[:, RSH]) * left_xz(X), 1)
        hp = lat - smooth(lat, 15)
        flips, state = 0, 0
        for t in np.where(raised)[0]:
            if hp[t] > 0.03 and state != 1:
                flips += state != 0
                state = 1
            elif hp[t] < -0.03 and state != -1:
                flips += state != 0
                state = -1
        # waving: the raised hand swings side to side, >= 4 direction changes (2 waves)
        c.add(f"{name} side-to-side swings>=4", flips >= 4, f"{flips}")
        md = max_disp(X)
        c.add(f"{name} stays(<=0.5)", md <= 0.5, f"{md:.2f}")
    return c.result()


# ----------------------------------------------------------------------------- self-test
def _base_pose():
    """standing pose at the origin, facing +Z, left at +X"""
    P = np.zeros((22, 3))
    P[PELVIS] = (0, 0.92, 0)
    P[LHIP], P[RHIP] = (0.08, 0.85, 0), (-0.08, 0.85, 0)
    P[SPINE1] = (0, 1.02, 0)
    P[LKNEE], P[RKNEE] = (0.09, 0.50, 0.01), (-0.09, 0.50, 0.01)
    P[SPINE2] = (0, 1.15, 0)
    P[LANKLE], P[RANKLE] = (0.10, 0.08, -0.02), (-0.10, 0.08, -0.02)
    P[SPINE3] = (0, 1.20, 0.02)
    P[LFOOT], P[RFOOT] = (0.11, 0.02, 0.10), (-0.11, 0.02, 0.10)
    P[NECK] = (0, 1.40, 0)
    P[LCOLLAR], P[RCOLLAR] = (0.08, 1.33, 0), (-0.08, 1.33, 0)
    P[HEAD] = (0, 1.48, 0.03)
    P[LSH], P[RSH] = (0.20, 1.38, 0), (-0.20, 1.38, 0)
    P[LELB], P[RELB] = (0.22, 1.10, 0), (-0.22, 1.10, 0)
    P[LWR], P[RWR] = (0.24, 0.88, 0.02), (-0.24, 0.88, 0.02)
    return P


def _rot_y(pts, ang):
    """rotate about +Y by ang (rad); positive = counter-clockwise from above (+Z -> +X)"""
    c, s = math.cos(ang), math.sin(ang)
    out = np.array(pts, float).copy()
    x, z = out[..., 0].copy(), out[..., 2].copy()
    out[..., 0] = x * c + z * s
    out[..., 2] = -x * s + z * c
    return out


def _place(pose, pos_xz, yaw):
    q = _rot_y(pose, yaw)
    q[:, 0] += pos_xz[0]
    q[:, 2] += pos_xz[1]
    return q


def _motion(path, yaws, pose=None):
    pose = _base_pose() if pose is None else pose
    return np.stack([_place(pose, p, y) for p, y in zip(path, yaws)])


def _path_yaws(path):
    v = np.gradient(np.asarray(path, float), axis=0)
    y = np.arctan2(v[:, 0], v[:, 1])
    sp = np.linalg.norm(v, axis=1)
    for i in range(len(y)):                  # standing frames keep the previous heading
        if sp[i] < 1e-6:
            y[i] = y[i - 1] if i else 0.0
    return y


def _polyline(pts, speed, n):
    pts = np.asarray(pts, float)
    seg = np.linalg.norm(np.diff(pts, axis=0), axis=1)
    cum = np.concatenate([[0], np.cumsum(seg)])
    dist = np.minimum(np.arange(n) / FPS * speed, cum[-1])
    return np.stack([np.interp(dist, cum, pts[:, 0]), np.interp(dist, cum, pts[:, 1])], 1)


def _selftest():
    fails = []

    def check(name, cond, info=""):
        print(("ok   " if cond else "FAIL ") + name + (f"  ({info})" if info else ""))
        if not cond:
            fails.append(name)

    base = _base_pose()
    st = np.repeat(base[None], 40, 0)
    f = facing_xz(st)[0]
    check("standing faces +Z", np.allclose(f, [0, 1], atol=1e-6), f"{f}")
    check("standing left is +X", np.allclose(left_xz(st)[0], [1, 0], atol=1e-6))
    check("yaw 0 at +Z", abs(yaw_of(f)) < 1e-6)
    r90 = _place(base, (0, 0), math.pi / 2)[None]
    f90 = facing_xz(r90)[0]
    check("rotated +90 (left turn) faces +X, yaw +90", np.allclose(f90, [1, 0], atol=1e-6)
          and abs(math.degrees(yaw_of(f90)) - 90) < 1e-6, f"{f90}")
    turnL = _motion(np.zeros((80, 2)), np.linspace(0, math.pi, 80))
    turnR = _motion(np.zeros((80, 2)), np.linspace(0, -math.pi, 80))
    dl = math.degrees(yaw_unwrapped(turnL)[-1] - yaw_unwrapped(turnL)[0])
    dr = math.degrees(yaw_unwrapped(turnR)[-1] - yaw_unwrapped(turnR)[0])
    check("left turn -> yaw +180", abs(dl - 180) < 1, f"{dl:.1f}")
    check("right turn -> yaw -180", abs(dr + 180) < 1, f"{dr:.1f}")
    n = 120
    walk = _motion(np.stack([np.zeros(n), np.arange(n) / FPS * 1.3], 1), np.zeros(n))
    _, sp = hvel(walk)
    check("walk speed 1.3", abs(np.median(sp) - 1.3) < 0.02, f"{np.median(sp):.3f}")
    fr, _ = facing_travel_agreement(walk)
    check("walk faces travel", fr > 0.99)
    bw = _motion(np.stack([np.zeros(n), -np.arange(n) / FPS * 1.3], 1), np.zeros(n))
    check("backward walk does not face travel", facing_travel_agreement(bw)[0] < 0.01)
    # circle direction convention: clockwise from above = position angle decreasing
    th = np.radians(np.linspace(90, -270, 160))
    circ = np.stack([-1 + np.sin(th), np.cos(th)], 1)
    check("cw circle turns right (yaw decreasing)", np.diff(np.unwrap(_path_yaws(circ))).sum() < 0)

    # every judge runs on standing-still motions of the right shape
    for tid, (P, secs) in TASKS.items():
        N = int(round(secs * FPS))
        if P == 1:
            arr = np.repeat(base[None], N, 0)
        else:
            arr = np.stack([np.repeat(_place(base, (0, 2.0 * i), math.pi * (i % 2))[None], N, 0)
                            for i in range(P)])
        try:
            RAW[tid](arr)
            raw_ok = True
        except Exception as e:
            raw_ok = False
            print("   raw error", tid, type(e).__name__, e)
        res = JUDGES[tid](arr)
        check(f"{tid} runs on standing still", raw_ok and isinstance(res[0], bool)
              and isinstance(res[1], str), f"{res[0]}: {res[1][:110]}")

    # synthetic positives and negatives (coarse, rigid-body motions)
    rng = np.random.default_rng(0)
    noise = float(__import__("os").environ.get("JUDGE_SELFTEST_NOISE", "0"))   # optional jitter (m)

    def expect(tid, arr, want):
        if noise > 0 and want:                 # robustness: jitter + 2 cm lateral sway on positives
            arr = arr + rng.normal(0, noise, arr.shape)
            nfr = arr.shape[-3]
            sway = 0.02 * np.sin(2 * math.pi * np.arange(nfr) / FPS)
            arr[..., 0] += sway[:, None]
            arr[..., 1] = np.maximum(arr[..., 1], -0.04)
        ok, why = JUDGES[tid](arr)
        check(f"{tid} synthetic -> {want}", ok == want, why[:300])

    N = 140
    y = np.radians(np.concatenate([np.linspace(0, 180, 50), np.full(30, 180)]))
    expect("t07", _motion(np.zeros((80, 2)), y), True)
    expect("t07", _motion(np.zeros((80, 2)), -y), False)
    # t03 clockwise circle r=1 in 8 s, centre to the right (-X)
    th = np.radians(np.linspace(90, -270, 160))
    circ = np.stack([-1 + np.sin(th), np.cos(th)], 1)
    expect("t03", _motion(circ, _path_yaws(circ)), True)
    th2 = np.radians(np.linspace(-90, 270, 160))
    circ2 = np.stack([1 + np.sin(th2), np.cos(th2)], 1)            # counter-clockwise
    expect("t03", _motion(circ2, _path_yaws(circ2)), False)
    # t04 square with left turns
    sq = _polyline([(0, 0), (0, 1.5), (1.5, 1.5), (1.5, 0), (0, 0)], 0.9, 160)
    expect("t04", _motion(sq, np.unwrap(_path_yaws(sq))), True)
    expect("t04", _motion(circ, _path_yaws(circ)), False)
    sqr = _polyline([(0, 0), (0, 1.5), (-1.5, 1.5), (-1.5, 0), (0, 0)], 0.9, 160)   # right turns
    expect("t04", _motion(sqr, np.unwrap(_path_yaws(sqr))), False)
    # t05 there and back
    n5 = 140
    out = np.linspace(0, 3, 46)
    zz = np.concatenate([out, np.full(20, 3.0), out[::-1], np.zeros(n5 - 112)])
    yw = np.concatenate([np.zeros(46), np.linspace(0, math.pi, 20), np.full(n5 - 66, math.pi)])
    expect("t05", _motion(np.stack([np.zeros(n5), zz], 1), yw), True)
    expect("t05", _motion(np.stack([np.zeros(n5), zz], 1), np.zeros(n5)), False)  # walks back backwards
    # t06 jog at 2 m/s
    expect("t06", _motion(np.stack([np.zeros(120), np.arange(120) / FPS * 2.0], 1), np.zeros(120)), True)
    expect("t06", _motion(np.stack([np.zeros(120), np.arange(120) / FPS * 1.3], 1), np.zeros(120)), False)
    # t02 hands above head, t15 arms to sides
    up = base.copy()
    up[LELB], up[RELB] = (0.22, 1.65, 0), (-0.22, 1.65, 0)
    up[LWR], up[RWR] = (0.18, 1.92, 0), (-0.18, 1.92, 0)
    expect("t02", np.concatenate([np.repeat(base[None], 30, 0), np.repeat(up[None], 70, 0)]), True)
    expect("t02", np.concatenate([np.repeat(up[None], 70, 0), np.repeat(base[None], 30, 0)]), False)
    tp = base.copy()
    tp[LELB], tp[RELB] = (0.48, 1.38, 0), (-0.48, 1.38, 0)
    tp[LWR], tp[RWR] = (0.74, 1.38, 0), (-0.74, 1.38, 0)
    expect("t15", np.concatenate([np.repeat(base[None], 40, 0), np.repeat(tp[None], 60, 0)]), True)
    expect("t15", np.concatenate([np.repeat(base[None], 40, 0), np.repeat(up[None], 60, 0)]), False)
    # t01 sitting on the floor
    sit = base.copy()
    sit[[PELVIS, SPINE1, SPINE2, SPINE3, NECK, LCOLLAR, RCOLLAR, HEAD, LSH, RSH, LELB, RELB,
         LWR, RWR, LHIP, RHIP], 1] -= 0.75
    sit[[LKNEE, RKNEE], 1] = 0.12
    sit[[LKNEE, RKNEE], 2] = 0.4
    sit[[LANKLE, RANKLE], 2] = 0.8
    sit[[LFOOT, RFOOT], 2] = 0.9
    expect("t01", np.concatenate([np.repeat(base[None], 80, 0), np.repeat(sit[None], 80, 0)]), True)
    expect("t01", np.concatenate([np.repeat(base[None], 150, 0), np.repeat(sit[None], 10, 0)]), False)
    # t16 lying on the back: rotate about X so the head goes to -Z, the chest faces up
    ly = base.copy()
    yy, zz2 = ly[:, 1] - 0.92, ly[:, 2].copy()
    ly[:, 1], ly[:, 2] = zz2 + 0.15, -yy
    expect("t16", np.concatenate([np.repeat(base[None], 80, 0), np.repeat(ly[None], 80, 0)]), True)
    lyp = base.copy()                         # rotated the other way: head +Z, chest down (prone)
    lyp[:, 1], lyp[:, 2] = -zz2 + 0.15, yy
    expect("t16", np.concatenate([np.repeat(base[None], 80, 0), np.repeat(lyp[None], 80, 0)]), False)
    # t19 upper body twisted 70 deg left for 2 s
    def twist(ang):
        q = base.copy()
        upper = [SPINE3, NECK, LCOLLAR, RCOLLAR, HEAD, LSH, RSH, LELB, RELB, LWR, RWR]
        q[upper] = _rot_y(base[upper], math.radians(ang))
        return q
    seq = [base] * 30 + [twist(70)] * 45 + [base] * 25
    expect("t19", np.stack(seq), True)
    expect("t19", np.stack([base] * 30 + [twist(-70)] * 45 + [base] * 25), False)
    # t08 three squats
    n8 = 140
    dep = 0.42 * (0.5 - 0.5 * np.cos(np.linspace(0, 3 * 2 * math.pi, n8)))
    sq8 = np.repeat(base[None], n8, 0)
    moved = [PELVIS, LHIP, RHIP, SPINE1, SPINE2, SPINE3, NECK, LCOLLAR, RCOLLAR, HEAD, LSH, RSH,
             LELB, RELB, LWR, RWR]
    sq8[:, moved, 1] -= dep[:, None]
    expect("t08", sq8, True)
    sq8b = np.repeat(base[None], n8, 0)
    sq8b[:, moved, 1] -= 0.2 * (0.5 - 0.5 * np.cos(np.linspace(0, 6 * math.pi, n8)))[:, None]
    expect("t08", sq8b, False)                 # too shallow
    # t09 three claps above the head
    cl = np.repeat(up[None], 100, 0)
    sep = 0.05 + 0.35 * (0.5 + 0.5 * np.cos(np.linspace(0, 3 * 2 * math.pi, 100)))
    cl[:, LWR, 0], cl[:, RWR, 0] = sep / 2, -sep / 2
    expect("t09", cl, True)
    cl2 = np.repeat(base[None], 100, 0)
    cl2[:, LWR, 0], cl2[:, RWR, 0] = sep / 2, -sep / 2
    cl2[:, [LWR, RWR], 2] = 0.3
    expect("t09", cl2, False)                  # claps at waist height
    # t17 right-hand circles, period 2 s
    n17 = 160
    tt = np.arange(n17) / FPS
    hc = np.repeat(base[None], n17, 0)
    hc[:, RWR] = np.stack([-0.25 + 0.25 * np.cos(math.pi * tt), 1.3 + 0.25 * np.sin(math.pi * tt),
                           np.full(n17, 0.4)], 1)
    expect("t17", hc, True)
    hc2 = hc.copy()
    hc2[:, RWR] = np.stack([-0.25 + 0.25 * np.cos(2 * math.pi * tt), 1.3 + 0.25 * np.sin(2 * math.pi * tt),
                            np.full(n17, 0.4)], 1)
    expect("t17", hc2, False)                  # one circle per second: too fast
    # t18 two side steps to the left
    n18 = 120
    lx = 0.4 * np.clip(1.5 * np.sin(np.linspace(0, 2 * math.pi, n18)) ** 2, 0, 1)
    expect("t18", _motion(np.stack([lx, np.zeros(n18)], 1), np.zeros(n18)), True)
    expect("t18", _motion(np.stack([-lx, np.zeros(n18)], 1), np.zeros(n18)), False)
    # t20 a jump forward 1 m
    n20 = 60
    zj = np.clip((np.arange(n20) - 20) / 8, 0, 1) * 1.0
    jp = _motion(np.stack([np.zeros(n20), zj], 1), np.zeros(n20))
    hop = np.where((np.arange(n20) > 20) & (np.arange(n20) < 28), 0.2, 0.0)
    jp[:, :, 1] += hop[:, None]
    expect("t20", jp, True)
    expect("t20", _motion(np.stack([np.zeros(n20), zj], 1), np.zeros(n20)), False)   # no flight
    # t21 right front kick
    kk = np.repeat(base[None], 60, 0)
    kk[25:33, RANKLE] = (-0.1, 0.6, 0.5)
    kk[25:33, RFOOT] = (-0.1, 0.65, 0.6)
    expect("t21", kk, True)
    kl = np.repeat(base[None], 60, 0)
    kl[25:33, LANKLE] = (0.1, 0.6, 0.5)
    expect("t21", kl, False)                   # left-foot kick
    # two-person scenes
    def two(mA, mB):
        return np.stack([mA, mB])
    n13 = 100
    zz13 = np.minimum(np.arange(n13) / FPS * 1.2, 3.0)
    A = _motion(np.stack([np.zeros(n13), zz13], 1), np.zeros(n13))
    B = _motion(np.stack([-np.ones(n13), zz13], 1), np.zeros(n13))
    expect("t13", two(A, B), True)
    B2 = _motion(np.stack([-np.ones(n13), zz13 * 0.5], 1), np.zeros(n13))
    expect("t13", two(A, B2), False)           # one falls behind
    n14 = 120
    zz14 = np.minimum(np.arange(n14) / FPS * 1.2, 5.0)
    three = np.stack([_motion(np.stack([np.zeros(n14), zz14 - k], 1), np.zeros(n14)) for k in range(3)])
    expect("t14", three, True)
    three2 = np.stack([_motion(np.stack([np.full(n14, -1.0 * k), zz14], 1), np.zeros(n14)) for k in range(3)])
    expect("t14", three2, False)               # side by side, not single file
    n12 = 140
    s12 = np.arange(n12) / FPS * 1.3
    side = np.minimum(np.arange(n12) / 40, 1) * 0.35
    A = _motion(np.stack([-side, s12], 1), np.zeros(n12))
    B = _motion(np.stack([side, 6 - s12], 1), np.full(n12, math.pi))
    expect("t12", two(A, B), True)
    A0 = _motion(np.stack([np.zeros(n12), s12], 1), np.zeros(n12))
    B0 = _motion(np.stack([np.zeros(n12), 6 - s12], 1), np.full(n12, math.pi))
    expect("t12", two(A0, B0), False)          # walk straight through each other
    n10 = 120
    A = np.repeat(base[None], n10, 0)
    B = np.repeat(_place(base, (0, 0.7), math.pi)[None], n10, 0)
    A[50:, RWR] = (-0.2, 1.45, 0.62)
    expect("t10", two(A, B), True)
    A2 = np.repeat(base[None], n10, 0)
    A2[50:, LWR] = (0.2, 1.45, 0.62)
    expect("t10", two(A2, B), False)           # wrong shoulder / hand
    n11 = 140
    zA = np.minimum(np.arange(n11) / FPS * 0.8, 0.8)
    A = _motion(np.stack([np.zeros(n11), zA], 1), np.zeros(n11))
    B = _motion(np.stack([np.zeros(n11), 2 - zA * (0.85 / 0.8)], 1), np.full(n11, math.pi))
    A[70:, LWR], A[70:, RWR] = (0.15, 1.2, 1.3), (-0.15, 1.2, 1.3)
    B[70:, LWR], B[70:, RWR] = (-0.15, 1.2, 0.65), (0.15, 1.2, 0.65)
    expect("t11", two(A, B), True)
    A3 = _motion(np.stack([np.zeros(n11), zA], 1), np.zeros(n11))
    expect("t11", two(A3, B), False)           # A does not hold B
    n22 = 100
    tt = np.arange(n22) / FPS
    def waver(pos, yaw):
        m = np.repeat(base[None], n22, 0)
        m[10:90, RWR] = np.stack([-0.3 + 0.12 * np.sin(2 * math.pi * 1.5 * tt[10:90]),
                                  np.full(80, 1.6), np.full(80, 0.1)], 1)
        m[10:90, RELB] = (-0.3, 1.3, 0.05)
        return np.stack([_place(q, pos, yaw) for q in m])
    expect("t22", two(waver((0, 0), 0), waver((0, 3), math.pi)), True)
    expect("t22", two(waver((0, 0), 0), np.stack([_place(base, (0, 3), math.pi)] * n22)), False)
    # common checks
    expect("t07", _motion(np.zeros((80, 2)), y) - np.array([0, 0.2, 0]), False)   # under floor
    expect("t07", _motion(np.zeros((200, 2)), np.radians(np.linspace(0, 180, 200))), False)  # too long

    print(f"\n{len(JUDGES)} judges; self-test {'PASSED' if not fails else 'FAILED: ' + ', '.join(fails)}")
    return not fails


if __name__ == "__main__":
    import sys
    sys.exit(0 if _selftest() else 1)
