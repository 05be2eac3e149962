//! The sentence judges: paths and speeds (s10–s16).

use super::*;

/// "A person walks slowly straight ahead, covering about 2 metres in 6 seconds."
pub(super) fn s10(p: &[Motion]) -> Checks {
    let (m, mut c) = (&p[0], Checks::new());
    let n = m.len();
    let (fwd, left) = StartFrame::of(m).local(m.frames[n - 1][PELVIS]);
    // "about 2 metres": 1.5–2.5 m; "straight ahead": at most 0.5 m aside.
    c.add(
        (1.5..=2.5).contains(&fwd),
        format!("ends {fwd:.2} m ahead (1.5–2.5)"),
    );
    c.add(
        left.abs() <= 0.5,
        format!("ends {left:+.2} m aside (|·| ≤ 0.5)"),
    );
    // "slowly": no second faster than 0.8 m/s (walking is ≈ 1.3 m/s).
    let v = window_speeds(m, 0..n);
    let top = v.iter().copied().fold(0.0, f32::max);
    c.add(
        top <= 0.8,
        format!("fastest second {top:.2} m/s (≤ 0.80, slow)"),
    );
    // "walks … ahead": facing the way it goes (moving frames: faster than 0.15 m/s).
    let (f, k) = fraction_within(&travel_cosines(m, 0.15, 0..n), 45.0);
    c.add(
        f >= 0.75 && k >= 20,
        format!(
            "faces the way it goes on {:.0} % of {k} moving frames (≥ 75 %)",
            100.0 * f
        ),
    );
    c
}

/// Angle (degrees) between the pelvis's net displacement and the start's forward.
fn heading_off_deg(m: &Motion) -> f32 {
    let s = StartFrame::of(m);
    let d = unit2(xz(m.frames[m.len() - 1][PELVIS]) - s.origin);
    d.dot(s.fwd).clamp(-1.0, 1.0).acos().to_degrees()
}

/// "A person runs forward at about 3 metres per second, then stops and stands still for
/// the last 1.5 seconds, in 5 seconds."
pub(super) fn s11(p: &[Motion]) -> Checks {
    let (m, mut c) = (&p[0], Checks::new());
    let n = m.len();
    // "about 3 metres per second": the fastest second 2.3–3.7 m/s.
    let top = window_speeds(m, 0..n).into_iter().fold(0.0, f32::max);
    c.add(
        (2.3..=3.7).contains(&top),
        format!("fastest second {top:.2} m/s (2.3–3.7)"),
    );
    // "forward": the net path within 30° of the start's forward.
    let off = heading_off_deg(m);
    c.add(off <= 30.0, format!("goes {off:.0}° off forward (≤ 30)"));
    let w = last(n, 1.5); // "for the last 1.5 seconds"
    let d = drift_xz(m, PELVIS, w.clone());
    // "stands still" after a run: the pelvis within 0.2 m (a stop from 3 m/s sways).
    c.add(
        d <= 0.20,
        format!("last 1.5 s: pelvis wanders {d:.2} m (≤ 0.20, still)"),
    );
    stands(&mut c, m, w, 0.75);
    walks_facing(&mut c, m, "");
    c
}

/// "A person walks backwards about 2 metres in a straight line, facing the same way the
/// whole time, in 5 seconds."
pub(super) fn s12(p: &[Motion]) -> Checks {
    let (m, mut c) = (&p[0], Checks::new());
    let n = m.len();
    let (fwd, left) = StartFrame::of(m).local(m.frames[n - 1][PELVIS]);
    // "about 2 metres" backwards: 1.4–2.6 m behind; "a straight line": ≤ 0.5 m aside.
    c.add(
        (1.4..=2.6).contains(&-fwd),
        format!("ends {:.2} m behind (1.4–2.6)", -fwd),
    );
    c.add(
        left.abs() <= 0.5,
        format!("ends {left:+.2} m aside (|·| ≤ 0.5)"),
    );
    // "facing the same way the whole time": within 30° of the start's facing.
    let turn = yaw_track(m).iter().map(|a| a.abs()).fold(0.0, f32::max);
    c.add(turn <= 30.0, format!("turns up to {turn:.0}° (≤ 30)"));
    // "backwards": 75 % of moving frames (> 0.3 m/s) face within 45° of away from travel.
    let back: Vec<f32> = travel_cosines(m, 0.3, 0..n).iter().map(|c| -c).collect();
    let (f, k) = fraction_within(&back, 45.0);
    c.add(
        f >= 0.75 && k >= 10,
        format!(
            "faces away from the way it goes on {:.0} % of {k} moving frames (≥ 75 %)",
            100.0 * f
        ),
    );
    c
}

/// "A person walks forward and stops right before a line on the floor 3 metres ahead,
/// without stepping over it, and stands there for the last 2 seconds, in 6 seconds."
pub(super) fn s13(p: &[Motion]) -> Checks {
    let (m, mut c) = (&p[0], Checks::new());
    let n = m.len();
    let s = StartFrame::of(m);
    // "without stepping over it": no foot joint past 2.95 m (the toes reach ≈ 5 cm past
    // the toe joint, the line is at 3 m).
    let far = max_over(0..n, |t| {
        FEET.iter()
            .map(|&j| s.local(m.frames[t][j]).0)
            .fold(f32::NEG_INFINITY, f32::max)
    });
    c.add(
        far <= 2.95,
        format!("feet reach {far:.2} m ahead (≤ 2.95, line at 3 m)"),
    );
    let w = last(n, 2.0); // "for the last 2 seconds"
    // "right before" it: the leading toe joint within 0.45 m of the line, every frame.
    let lead = min_over(w.clone(), |t| {
        s.local(m.frames[t][L_FOOT])
            .0
            .max(s.local(m.frames[t][R_FOOT]).0)
    });
    c.add(
        lead >= 2.55,
        format!("leading toe at least {lead:.2} m ahead over the last 2 s (≥ 2.55)"),
    );
    still(&mut c, m, w, "last 2 s: ");
    c
}

/// "A person walks forward about 2 metres, turns left and walks about 2 more metres in the
/// new direction, in 7 seconds."
pub(super) fn s14(p: &[Motion]) -> Checks {
    let (m, mut c) = (&p[0], Checks::new());
    let n = m.len();
    let s = StartFrame::of(m);
    let path: Vec<(f32, f32)> = (0..n).map(|t| s.local(m.frames[t][PELVIS])).collect();
    // "forward about 2 metres" before turning: at some frame ≥ 1.4 m ahead and still
    // within 0.5 m of the first line.
    let corner = path.iter().any(|&(f, l)| f >= 1.4 && l.abs() <= 0.5);
    let ahead = path
        .iter()
        .filter(|(_, l)| l.abs() <= 0.5)
        .map(|&(f, _)| f)
        .fold(f32::NEG_INFINITY, f32::max);
    c.add(
        corner,
        format!("{ahead:.2} m ahead before leaving the first line (≥ 1.4)"),
    );
    // "about 2 more metres" to the left: the end 1.3–2.7 m ahead and 1.3–2.7 m left.
    let (f, l) = path[n - 1];
    c.add(
        (1.3..=2.7).contains(&f) && (1.3..=2.7).contains(&l),
        format!("ends {f:.2} m ahead, {l:.2} m left (1.3–2.7 each)"),
    );
    // "turns left": facing 60–120° left at the end, never more than 30° right.
    let yaw = end_yaw(m);
    c.add(
        (60.0..=120.0).contains(&yaw),
        format!("ends turned {yaw:+.0}° (+60…+120, left)"),
    );
    let right = yaw_track(m).into_iter().fold(f32::INFINITY, f32::min);
    c.add(
        right >= -30.0,
        format!("turns right at most {right:+.0}° (≥ -30)"),
    );
    walks_facing(&mut c, m, "");
    c
}

/// "A person walks along a smooth curve bending to the right, ending about 2.5 metres ahead
/// and 2.5 metres to the right of the start and facing right, in 5 seconds."
pub(super) fn s15(p: &[Motion]) -> Checks {
    let (m, mut c) = (&p[0], Checks::new());
    let n = m.len();
    let s = StartFrame::of(m);
    let (f, l) = s.local(m.frames[n - 1][PELVIS]);
    // "about 2.5 metres ahead and 2.5 metres to the right": 1.8–3.2 m each.
    c.add(
        (1.8..=3.2).contains(&f) && (1.8..=3.2).contains(&-l),
        format!("ends {f:.2} m ahead, {:.2} m right (1.8–3.2 each)", -l),
    );
    // "facing right": 60–120° right at the end; "bending to the right": never more than
    // 20° left.
    let yaw = end_yaw(m);
    c.add(
        (-120.0..=-60.0).contains(&yaw),
        format!("ends turned {yaw:+.0}° (-120…-60, right)"),
    );
    let ys = yaw_track(m);
    let left = ys.iter().copied().fold(f32::NEG_INFINITY, f32::max);
    c.add(
        left <= 20.0,
        format!("turns left at most {left:+.0}° (≤ 20)"),
    );
    // "smooth curve": half-way through, half-turned (−45° ± 30°), not straight then a pivot.
    let mid = ys[n / 2];
    c.add(
        (-75.0..=-15.0).contains(&mid),
        format!("turned {mid:+.0}° half-way (-75…-15)"),
    );
    // A curve, not a straight diagonal: the path bulges ≥ 0.3 m to the left of the chord
    // from start to end (a quarter circle of 2.5 m bulges 0.73 m).
    let end = xz(m.frames[n - 1][PELVIS]);
    let d = unit2(end - s.origin);
    let normal = glam::Vec2::new(d.y, -d.x);
    let bulge = max_over(0..n, |t| (xz(m.frames[t][PELVIS]) - s.origin).dot(normal));
    c.add(
        bulge >= 0.30,
        format!("path bulges {bulge:.2} m from the straight line (≥ 0.30)"),
    );
    walks_facing(&mut c, m, "");
    c
}

/// "A person walks forward for the first 3 seconds and then runs forward for the last 3
/// seconds, in 6 seconds."
pub(super) fn s16(p: &[Motion]) -> Checks {
    let (m, mut c) = (&p[0], Checks::new());
    let n = m.len();
    // The walk, 0.5–2.8 s (after starting, before changing gait): 0.6–1.9 m/s on average
    // and no second faster than 2 m/s (walking ≈ 1.3 m/s).
    let (a, b) = (10, 56.min(n - 1));
    let walk = mean_speed(m, a, b);
    c.add(
        (0.6..=1.9).contains(&walk),
        format!("walks at {walk:.2} m/s in 0.5–2.8 s (0.6–1.9)"),
    );
    let top = window_speeds(m, span(n, 0.0, 3.0))
        .into_iter()
        .fold(0.0, f32::max);
    c.add(
        top <= 2.0,
        format!("fastest second of the first 3 s {top:.2} m/s (≤ 2.0, walking)"),
    );
    // The run, "for the last 3 seconds": every second from 3.6 s (0.6 s to change gait) at
    // least 2 m/s, and at least 1.5 times the walk.
    let run_w = window_speeds(m, from(n, 3.6));
    let slow = run_w.iter().copied().fold(f32::INFINITY, f32::min);
    c.add(
        !run_w.is_empty() && slow >= 2.0,
        format!("slowest second from 3.6 s {slow:.2} m/s (≥ 2.0, running)"),
    );
    let run = mean_speed(m, from(n, 3.6).start, n - 1);
    c.add(
        run >= 1.5 * walk,
        format!(
            "runs at {run:.2} m/s, {:.1} times the walk (≥ 1.5)",
            run / walk.max(1e-6)
        ),
    );
    let off = heading_off_deg(m);
    c.add(off <= 30.0, format!("goes {off:.0}° off forward (≤ 30)"));
    walks_facing(&mut c, m, "");
    c
}
