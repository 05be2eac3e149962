//! What the sentence judges measure on a motion: the body's facing and yaw, the start's
//! own frame (forward and left), speeds over the ground, tilts, holds and episodes, the
//! common checks every judge applies, and the list of checks a verdict is made of.
//!
//! A port of the helpers of `scripts/llm-trial/judges.py` (same conventions: the body's
//! left is (l_hip − r_hip) + (l_shoulder − r_shoulder) on the ground, its facing that left
//! turned a quarter clockwise seen from above, so a person whose left is +X faces +Z; yaw
//! grows when turning left).

use super::Verdict;
use crate::motion::{Motion, Pose};
use crate::skeleton::FPS;
use glam::{Vec2, Vec3};
use std::ops::Range;

/// HumanML3D joint indices.
pub const PELVIS: usize = 0;
/// Left hip.
pub const L_HIP: usize = 1;
/// Right hip.
pub const R_HIP: usize = 2;
/// Lower back.
pub const SPINE1: usize = 3;
/// Left knee.
pub const L_KNEE: usize = 4;
/// Right knee.
pub const R_KNEE: usize = 5;
/// Middle of the back.
pub const SPINE2: usize = 6;
/// Left ankle.
pub const L_ANKLE: usize = 7;
/// Right ankle.
pub const R_ANKLE: usize = 8;
/// Chest.
pub const SPINE3: usize = 9;
/// Left toe joint (ball of the foot).
pub const L_FOOT: usize = 10;
/// Right toe joint.
pub const R_FOOT: usize = 11;
/// Neck.
pub const NECK: usize = 12;
/// Left collar.
pub const L_COLLAR: usize = 13;
/// Right collar.
pub const R_COLLAR: usize = 14;
/// Head (its centre).
pub const HEAD: usize = 15;
/// Left shoulder.
pub const L_SHOULDER: usize = 16;
/// Right shoulder.
pub const R_SHOULDER: usize = 17;
/// Left elbow.
pub const L_ELBOW: usize = 18;
/// Right elbow.
pub const R_ELBOW: usize = 19;
/// Left wrist.
pub const L_WRIST: usize = 20;
/// Right wrist.
pub const R_WRIST: usize = 21;
/// The four foot joints (ankles and toes).
pub const FEET: [usize; 4] = [L_ANKLE, R_ANKLE, L_FOOT, R_FOOT];
/// The torso's joints, pelvis to head.
pub const TORSO: [usize; 6] = [PELVIS, SPINE1, SPINE2, SPINE3, NECK, HEAD];

/// The ground part (x, z) of a point.
pub fn xz(v: Vec3) -> Vec2 {
    Vec2::new(v.x, v.z)
}

/// `v` of unit length, or zero for a (near) zero vector.
pub fn unit2(v: Vec2) -> Vec2 {
    let n = v.length();
    if n > 1e-9 { v / n } else { Vec2::ZERO }
}

/// `v` of unit length, or zero for a (near) zero vector.
pub fn unit3(v: Vec3) -> Vec3 {
    let n = v.length();
    if n > 1e-9 { v / n } else { Vec3::ZERO }
}

/// The body's left on the ground, from the hips and the shoulders (unit).
pub fn left_xz(p: &Pose) -> Vec2 {
    unit2(xz((p[L_HIP] - p[R_HIP]) + (p[L_SHOULDER] - p[R_SHOULDER])))
}

/// The hips' left on the ground (unit): the lower body's own side, which a lean or a twist
/// of the upper body does not turn.
pub fn hips_left_xz(p: &Pose) -> Vec2 {
    unit2(xz(p[L_HIP] - p[R_HIP]))
}

/// The left `l` turned a quarter clockwise seen from above: left +X faces +Z.
pub fn facing_of_left(l: Vec2) -> Vec2 {
    unit2(Vec2::new(-l.y, l.x))
}

/// Where the body faces on the ground (unit), as `facing()` in the language.
pub fn facing_xz(p: &Pose) -> Vec2 {
    facing_of_left(left_xz(p))
}

/// Yaw of a ground direction (x, z), in degrees: 0 facing +Z, +90 facing +X (a left turn
/// from the start).
pub fn yaw_deg(f: Vec2) -> f32 {
    f.x.atan2(f.y).to_degrees()
}

/// Angles in degrees made continuous (no jumps of more than 180° between frames).
pub fn unwrap_deg(a: &[f32]) -> Vec<f32> {
    let mut out: Vec<f32> = Vec::with_capacity(a.len());
    let mut offset = 0.0f32;
    for (i, &v) in a.iter().enumerate() {
        if i > 0 {
            let d = v + offset - out[i - 1];
            offset -= 360.0 * (d / 360.0).round();
        }
        out.push(v + offset);
    }
    out
}

/// The body's yaw at every frame, unwrapped, relative to the mean facing of the first five
/// frames (degrees, + = turned left).
pub fn yaw_track(m: &Motion) -> Vec<f32> {
    let f0 = StartFrame::of(m).fwd;
    let raw: Vec<f32> = m
        .frames
        .iter()
        .map(|p| {
            let f = facing_xz(p);
            // Angle from f0 to f, counter-clockwise seen from above = to the left.
            let cross = f0.y * f.x - f0.x * f.y;
            cross.atan2(f0.dot(f)).to_degrees()
        })
        .collect();
    unwrap_deg(&raw)
}

/// Centred moving average over `w` frames, the ends padded with the end values.
pub fn smooth<T>(xs: &[T], w: usize) -> Vec<T>
where
    T: Copy + std::ops::Add<Output = T> + std::ops::Mul<f32, Output = T>,
{
    if w <= 1 || xs.is_empty() {
        return xs.to_vec();
    }
    let n = xs.len() as isize;
    let pad = (w / 2) as isize;
    (0..n)
        .map(|i| {
            let mut acc = xs[(i - pad).clamp(0, n - 1) as usize];
            for k in 1..w as isize {
                acc = acc + xs[(i - pad + k).clamp(0, n - 1) as usize];
            }
            acc * (1.0 / w as f32)
        })
        .collect()
}

/// A joint's positions over time.
pub fn track(m: &Motion, j: usize) -> Vec<Vec3> {
    m.frames.iter().map(|p| p[j]).collect()
}

/// A joint's heights over time.
pub fn heights(m: &Motion, j: usize) -> Vec<f32> {
    m.frames.iter().map(|p| p[j].y).collect()
}

/// The pelvis's ground path.
pub fn pelvis_xz(m: &Motion) -> Vec<Vec2> {
    m.frames.iter().map(|p| xz(p[PELVIS])).collect()
}

/// Frames of the last `secs` seconds (all of them when the motion is shorter).
pub fn last(n: usize, secs: f32) -> Range<usize> {
    n.saturating_sub((secs * FPS).round() as usize)..n
}

/// Frames from `secs` seconds on.
pub fn from(n: usize, secs: f32) -> Range<usize> {
    ((secs * FPS).round() as usize).min(n)..n
}

/// Frames from `a` to `b` seconds (b excluded), clipped to the motion.
pub fn span(n: usize, a: f32, b: f32) -> Range<usize> {
    let s = ((a * FPS).round() as usize).min(n);
    s..((b * FPS).round() as usize).clamp(s, n)
}

/// Smallest value of `f` over `r` (+∞ for an empty range).
pub fn min_over(r: Range<usize>, f: impl Fn(usize) -> f32) -> f32 {
    r.map(f).fold(f32::INFINITY, f32::min)
}

/// Largest value of `f` over `r` (−∞ for an empty range).
pub fn max_over(r: Range<usize>, f: impl Fn(usize) -> f32) -> f32 {
    r.map(f).fold(f32::NEG_INFINITY, f32::max)
}

/// How far a joint wanders on the ground over `r`: the largest distance from its mean.
pub fn drift_xz(m: &Motion, j: usize, r: Range<usize>) -> f32 {
    let pts: Vec<Vec2> = m.frames[r].iter().map(|p| xz(p[j])).collect();
    if pts.is_empty() {
        return 0.0;
    }
    let mean = pts.iter().copied().sum::<Vec2>() / pts.len() as f32;
    pts.iter().map(|p| p.distance(mean)).fold(0.0, f32::max)
}

/// How far a joint wanders in 3-D over `r`: the largest distance from its mean.
pub fn drift_3d(m: &Motion, j: usize, r: Range<usize>) -> f32 {
    let pts: Vec<Vec3> = m.frames[r].iter().map(|p| p[j]).collect();
    if pts.is_empty() {
        return 0.0;
    }
    let mean = pts.iter().copied().sum::<Vec3>() / pts.len() as f32;
    pts.iter().map(|p| p.distance(mean)).fold(0.0, f32::max)
}

/// Range (max − min) of a joint's height over `r`, smoothed over 3 frames against jitter.
pub fn height_range(m: &Motion, j: usize, r: Range<usize>) -> f32 {
    let h = smooth(&heights(m, j), 3);
    let w = &h[r];
    let hi = w.iter().copied().fold(f32::NEG_INFINITY, f32::max);
    let lo = w.iter().copied().fold(f32::INFINITY, f32::min);
    if w.is_empty() { 0.0 } else { hi - lo }
}

/// The farthest the pelvis gets (on the ground) from where it started.
pub fn max_disp(m: &Motion) -> f32 {
    let p = pelvis_xz(m);
    p.iter().map(|q| q.distance(p[0])).fold(0.0, f32::max)
}

/// The person's own frame at the start: the pelvis's ground position on the first frame,
/// the mean facing of the first five frames, and the left that goes with it.
#[derive(Clone, Copy, Debug)]
pub struct StartFrame {
    /// The pelvis on the ground at frame 0.
    pub origin: Vec2,
    /// Forward (unit).
    pub fwd: Vec2,
    /// Left (unit): forward turned a quarter counter-clockwise seen from above.
    pub left: Vec2,
}

impl StartFrame {
    /// The start frame of a motion.
    pub fn of(m: &Motion) -> Self {
        let k = m.len().min(5);
        let sum: Vec2 = m.frames[..k].iter().map(facing_xz).sum();
        let fwd = unit2(sum);
        StartFrame {
            origin: xz(m.frames[0][PELVIS]),
            fwd,
            left: Vec2::new(fwd.y, -fwd.x),
        }
    }

    /// A point as (forward, left) of the start, in metres.
    pub fn local(&self, p: Vec3) -> (f32, f32) {
        let d = xz(p) - self.origin;
        (d.dot(self.fwd), d.dot(self.left))
    }
}

/// The pelvis's ground velocity (m/s) from its path smoothed over `w` frames (central
/// differences, one-sided at the ends).
pub fn ground_velocity(m: &Motion, w: usize) -> Vec<Vec2> {
    let p = smooth(&pelvis_xz(m), w);
    let n = p.len();
    (0..n)
        .map(|i| {
            if n < 2 {
                Vec2::ZERO
            } else if i == 0 {
                (p[1] - p[0]) * FPS
            } else if i == n - 1 {
                (p[n - 1] - p[n - 2]) * FPS
            } else {
                (p[i + 1] - p[i - 1]) * (FPS / 2.0)
            }
        })
        .collect()
}

/// Mean ground speeds of the pelvis over every 1-s window that starts and ends inside `r`
/// (its path smoothed over 5 frames), one window per frame.
pub fn window_speeds(m: &Motion, r: Range<usize>) -> Vec<f32> {
    let p = smooth(&pelvis_xz(m), 5);
    let k = FPS as usize;
    if r.end < r.start + k {
        return Vec::new();
    }
    (r.start..r.end - k)
        .map(|t| p[t + k].distance(p[t]))
        .collect()
}

/// Mean ground speed of the pelvis from frame `a` to frame `b` (straight-line distance
/// over time; 0 for an empty range).
pub fn mean_speed(m: &Motion, a: usize, b: usize) -> f32 {
    let p = smooth(&pelvis_xz(m), 5);
    if b <= a || b >= p.len() {
        return 0.0;
    }
    p[b].distance(p[a]) / ((b - a) as f32 / FPS)
}

/// Cosines between the facing and the direction of travel on the frames of `r` where the
/// pelvis moves faster than `min_speed` (m/s, from its path smoothed over 7 frames).
pub fn travel_cosines(m: &Motion, min_speed: f32, r: Range<usize>) -> Vec<f32> {
    let v = ground_velocity(m, 7);
    r.filter(|&t| v[t].length() > min_speed)
        .map(|t| unit2(v[t]).dot(facing_xz(&m.frames[t])))
        .collect()
}

/// The fraction of moving frames (faster than 0.4 m/s) whose facing is within 45° of the
/// direction of travel, and how many frames moved.
pub fn faces_travel(m: &Motion) -> (f32, usize) {
    fraction_within(&travel_cosines(m, 0.4, 0..m.len()), 45.0)
}

/// The fraction of cosines at least cos(`deg`), and how many there are.
pub fn fraction_within(cos: &[f32], deg: f32) -> (f32, usize) {
    if cos.is_empty() {
        return (0.0, 0);
    }
    let c = deg.to_radians().cos();
    let k = cos.iter().filter(|&&x| x >= c).count();
    (k as f32 / cos.len() as f32, cos.len())
}

/// How far the spine (pelvis to neck) tips forward from vertical, in degrees: positive
/// towards where the body faces, negative backwards.
pub fn forward_tilt_deg(p: &Pose) -> f32 {
    let s = p[NECK] - p[PELVIS];
    xz(s).dot(facing_xz(p)).atan2(s.y).to_degrees()
}

/// How far the spine tips from vertical in any direction, in degrees.
pub fn tilt_deg(p: &Pose) -> f32 {
    let s = unit3(p[NECK] - p[PELVIS]);
    s.y.clamp(-1.0, 1.0).acos().to_degrees()
}

/// The torso's front in 3-D: (left × spine), with left from the hips and shoulders and the
/// spine pelvis to neck; standing it is the facing, lying on the back it points up.
pub fn body_front(p: &Pose) -> Vec3 {
    let left = (p[L_HIP] - p[R_HIP]) + (p[L_SHOULDER] - p[R_SHOULDER]);
    unit3(left.cross(p[NECK] - p[PELVIS]))
}

/// Hysteresis episodes: entered when `x` reaches `enter` (at or above it, or at or below it
/// when `above` is false), left when it gets back past `exit`. Half-open frame ranges.
pub fn episodes(x: &[f32], enter: f32, exit: f32, above: bool) -> Vec<(usize, usize)> {
    let mut eps = Vec::new();
    let mut start = None;
    for (i, &v) in x.iter().enumerate() {
        match start {
            None if (above && v >= enter) || (!above && v <= enter) => start = Some(i),
            Some(s) if (above && v <= exit) || (!above && v >= exit) => {
                eps.push((s, i));
                start = None;
            }
            _ => {}
        }
    }
    if let Some(s) = start {
        eps.push((s, x.len()));
    }
    eps
}

/// Runs of true values, as half-open frame ranges.
pub fn runs(mask: &[bool]) -> Vec<(usize, usize)> {
    let mut out = Vec::new();
    let mut start = None;
    for (i, &b) in mask.iter().enumerate() {
        match (b, start) {
            (true, None) => start = Some(i),
            (false, Some(s)) => {
                out.push((s, i));
                start = None;
            }
            _ => {}
        }
    }
    if let Some(s) = start {
        out.push((s, mask.len()));
    }
    out
}

/// The longest run of true values, in frames.
pub fn longest_run(mask: &[bool]) -> usize {
    runs(mask).iter().map(|(s, e)| e - s).max().unwrap_or(0)
}

/// The angle (degrees) between where `a` faces at frame `t` and the direction to `b`.
pub fn towards_deg(a: &Motion, b: &Motion, t: usize) -> f32 {
    let f = facing_xz(&a.frames[t]);
    let d = unit2(xz(b.frames[t][PELVIS]) - xz(a.frames[t][PELVIS]));
    f.dot(d).clamp(-1.0, 1.0).acos().to_degrees()
}

/// Ground distance between two people's pelvises at frame `t`.
pub fn pelvis_gap(a: &Motion, b: &Motion, t: usize) -> f32 {
    xz(a.frames[t][PELVIS]).distance(xz(b.frames[t][PELVIS]))
}

/// Side-to-side swings of a raised right hand (a wave): the wrist's offset from the right
/// shoulder along the body's left, less its 0.75-s moving average, counted as changes of
/// direction past ±3 cm on the frames where the wrist is at or above the shoulder. Also
/// returns those frames' count.
pub fn right_hand_swings(m: &Motion) -> (usize, usize) {
    let lat: Vec<f32> = m
        .frames
        .iter()
        .map(|p| xz(p[R_WRIST] - p[R_SHOULDER]).dot(left_xz(p)))
        .collect();
    let base = smooth(&lat, 15);
    let (mut flips, mut state, mut raised) = (0, 0i8, 0);
    for (t, p) in m.frames.iter().enumerate() {
        if p[R_WRIST].y < p[R_SHOULDER].y {
            continue;
        }
        raised += 1;
        let hp = lat[t] - base[t];
        let now = if hp > 0.03 {
            1
        } else if hp < -0.03 {
            -1
        } else {
            state
        };
        if now != state {
            if state != 0 {
                flips += 1;
            }
            state = now;
        }
    }
    (flips, raised)
}

/// The checks one judge made, each with its figures, in the order made.
#[derive(Default)]
pub struct Checks {
    items: Vec<(bool, String)>,
}

impl Checks {
    /// A new, empty list.
    pub fn new() -> Self {
        Checks::default()
    }

    /// Records one check: whether it held, and what it measured against what rule
    /// ("pelvis max 0.42 m over the last 2.0 s (≤ 0.60)").
    pub fn add(&mut self, ok: bool, what: impl Into<String>) -> bool {
        self.items.push((ok, what.into()));
        ok
    }

    /// Whether every check so far held.
    pub fn all_ok(&self) -> bool {
        self.items.iter().all(|(ok, _)| *ok)
    }

    /// The verdict: right when every check held; the reason lists the failed checks first
    /// (marked), then the ones that held.
    pub fn verdict(self) -> Verdict {
        let ok = self.all_ok();
        let failed: Vec<String> = self
            .items
            .iter()
            .filter(|(o, _)| !o)
            .map(|(_, w)| format!("{w} [fails]"))
            .collect();
        let held: Vec<&str> = self
            .items
            .iter()
            .filter(|(o, _)| *o)
            .map(|(_, w)| w.as_str())
            .collect();
        let mut parts = failed;
        parts.extend(held.iter().map(|s| s.to_string()));
        let reason = parts.join("; ");
        if ok {
            Verdict::right(reason)
        } else {
            Verdict::wrong(reason)
        }
    }
}

/// The checks every judge applies before its own, as `judges.py` does: the number of
/// people, at least 10 frames each and the same count for all, finite values, a duration
/// within max(0.75 s, 15 %) of the seconds asked, no joint more than 5 cm under the floor,
/// and with several people pelvises at least 0.3 m apart on the ground at every frame.
/// Motions at another frame rate are resampled to 20 fps first.
pub fn common(people: &[Motion], want: usize, seconds: f32) -> Result<Vec<Motion>, String> {
    if people.len() != want {
        return Err(format!("{} people, the sentence has {want}", people.len()));
    }
    let ms: Vec<Motion> = people
        .iter()
        .map(|m| {
            if (m.fps - FPS).abs() > 1e-3 && m.fps > 0.0 {
                m.resample(FPS)
            } else {
                Motion::new(m.frames.clone())
            }
        })
        .collect();
    let n = ms[0].len();
    if let Some(m) = ms.iter().find(|m| m.len() != n) {
        return Err(format!("people of {n} and {} frames", m.len()));
    }
    if n < 10 {
        return Err(format!("only {n} frames"));
    }
    if !ms.iter().all(Motion::is_finite) {
        return Err("non-finite joint positions".into());
    }
    let dur = n as f32 / FPS;
    // Duration: the length asked, within max(0.75 s, 15 %) (as judges.py).
    let tol = (0.15 * seconds).max(0.75);
    if (dur - seconds).abs() > tol {
        return Err(format!(
            "duration {dur:.2} s vs {seconds:.2} s asked (± {tol:.2})"
        ));
    }
    // The floor: no joint more than 5 cm under it.
    let low = ms
        .iter()
        .flat_map(|m| m.frames.iter().flatten())
        .map(|p| p.y)
        .fold(f32::INFINITY, f32::min);
    if low < -0.05 {
        return Err(format!("a joint {low:.3} m under the floor (≥ -0.05)"));
    }
    // People must not overlap: pelvises at least 0.3 m apart on the ground.
    let mut closest = f32::INFINITY;
    for i in 0..ms.len() {
        for k in i + 1..ms.len() {
            for t in 0..n {
                closest = closest.min(pelvis_gap(&ms[i], &ms[k], t));
            }
        }
    }
    if closest < 0.3 {
        return Err(format!(
            "people overlap: pelvises {closest:.2} m apart (≥ 0.30)"
        ));
    }
    Ok(ms)
}
