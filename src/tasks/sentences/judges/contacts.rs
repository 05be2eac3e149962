//! The sentence judges: contacts and reaching (s17–s22).

use super::*;

/// "A person puts the right hand on top of the head by 2 seconds and keeps it there until
/// the end, in 5 seconds."
pub(super) fn s17(p: &[Motion]) -> Checks {
    let (m, mut c) = (&p[0], Checks::new());
    let f0 = &m.frames[0];
    // "puts": the hand starts down, under its shoulder.
    let d0 = f0[R_WRIST].y - f0[R_SHOULDER].y;
    c.add(
        d0 < 0.0,
        format!("right wrist {d0:+.2} m from its shoulder at the start (< 0)"),
    );
    let w = from(m.len(), 2.0); // "by 2 seconds … until the end"
    // "on top of the head": a palm on the crown (≈ 0.12 m over the head's centre) puts the
    // wrist within 0.22 m of the centre, and not under it (−2 cm for jitter).
    let d = max_over(w.clone(), |t| {
        m.frames[t][R_WRIST].distance(m.frames[t][HEAD])
    });
    c.add(
        d <= 0.22,
        format!("right wrist up to {d:.2} m from the head from 2 s (≤ 0.22)"),
    );
    let h = min_over(w, |t| m.frames[t][R_WRIST].y - m.frames[t][HEAD].y);
    c.add(
        h >= -0.02,
        format!("right wrist at least {h:+.2} m over the head (≥ -0.02, on top)"),
    );
    in_place(&mut c, m, 0.4);
    c
}

/// "A person bends down and touches the left knee with the right hand once, then stands
/// upright again for the last second, in 4 seconds."
pub(super) fn s18(p: &[Motion]) -> Checks {
    let (m, mut c) = (&p[0], Checks::new());
    let d: Vec<f32> = m
        .frames
        .iter()
        .map(|q| q[R_WRIST].distance(q[L_KNEE]))
        .collect();
    // "touches … once": one episode of the wrist within 0.15 m of the knee joint (the
    // palm ≈ 0.08 m past the wrist, the knee's surface ≈ 0.05 m from its joint), over by
    // 0.25 m.
    let touches = episodes(&d, 0.15, 0.25, false).len();
    let closest = d.iter().copied().fold(f32::INFINITY, f32::min);
    c.add(
        touches == 1,
        format!("{touches} touches (1); closest {closest:.2} m (≤ 0.15)"),
    );
    let w = last(m.len(), 1.0); // "for the last second"
    let tilt = max_over(w.clone(), |t| tilt_deg(&m.frames[t]));
    // "upright": spine within 20° of vertical, the pelvis high, the hand off the knee.
    c.add(
        tilt <= 20.0,
        format!("spine tilts up to {tilt:.0}° over the last 1 s (≤ 20)"),
    );
    stands(&mut c, m, w.clone(), 0.80);
    let off = min_over(w, |t| d[t]);
    c.add(
        off >= 0.25,
        format!("hand at least {off:.2} m from the knee (≥ 0.25)"),
    );
    in_place(&mut c, m, 0.4);
    c
}

/// "A person bends down and puts something on the floor with the right hand at a spot about
/// half a metre in front of their feet, then stands back up, in 5 seconds."
pub(super) fn s19(p: &[Motion]) -> Checks {
    let (m, mut c) = (&p[0], Checks::new());
    let n = m.len();
    let s = StartFrame::of(m);
    let f0 = &m.frames[0];
    // The spot: half a metre ahead of the toes' midpoint at the start.
    let spot = xz(f0[L_FOOT] + f0[R_FOOT]) * 0.5 + s.fwd * 0.5;
    // "on the floor": the wrist at most 0.15 m up (≈ 0.08 m over a palm on the floor);
    // "about half a metre": there, within 0.25 m of the spot.
    let low = min_over(0..n, |t| m.frames[t][R_WRIST].y);
    c.add(
        low <= 0.15,
        format!("right wrist down to {low:.2} m (≤ 0.15, on the floor)"),
    );
    let near = min_over(0..n, |t| {
        let q = m.frames[t][R_WRIST];
        if q.y <= 0.15 {
            xz(q).distance(spot)
        } else {
            f32::INFINITY
        }
    });
    c.add(
        near <= 0.25,
        format!("on the floor {near:.2} m from the spot (≤ 0.25)"),
    );
    // "stands back up": over the last half second.
    let w = last(n, 0.5);
    let lo = min_over(w.clone(), |t| m.frames[t][PELVIS].y);
    let head = min_over(w, |t| m.frames[t][HEAD].y);
    c.add(
        lo >= 0.80 && head >= 1.30,
        format!("last 0.5 s: pelvis ≥ {lo:.2} m, head ≥ {head:.2} m (0.80, 1.30: standing)"),
    );
    c
}

/// "A person walks up to a wall 2 metres ahead and touches it with the right hand at about
/// shoulder height, without any part of the body going through the wall, in 5 seconds."
pub(super) fn s20(p: &[Motion]) -> Checks {
    let (m, mut c) = (&p[0], Checks::new());
    let n = m.len();
    let s = StartFrame::of(m);
    let ahead = |t: usize, j: usize| s.local(m.frames[t][j]).0;
    // The wall 2 m ahead of the start. "without … going through": no joint past it (2 cm
    // for jitter), and the torso's joints 0.1 m short of it (the body's front is ≈ 0.1 m
    // in front of them).
    let far = max_over(0..n, |t| {
        (0..22)
            .map(|j| ahead(t, j))
            .fold(f32::NEG_INFINITY, f32::max)
    });
    c.add(
        far <= 2.02,
        format!("joints reach {far:.2} m ahead (≤ 2.02, wall at 2 m)"),
    );
    let torso = max_over(0..n, |t| {
        TORSO
            .iter()
            .map(|&j| ahead(t, j))
            .fold(f32::NEG_INFINITY, f32::max)
    });
    c.add(
        torso <= 1.90,
        format!("torso joints reach {torso:.2} m ahead (≤ 1.90)"),
    );
    // "touches it with the right hand": the wrist within 0.2 m of the wall (the palm
    // ≈ 0.08 m and the fingertips ≈ 0.18 m past it) "at about shoulder height" (± 0.2 m),
    // for at least 0.2 s in one go.
    let touch: Vec<bool> = (0..n)
        .map(|t| {
            let q = &m.frames[t];
            ahead(t, R_WRIST) >= 1.80 && (q[R_WRIST].y - q[R_SHOULDER].y).abs() <= 0.20
        })
        .collect();
    let k = longest_run(&touch);
    let best = max_over(0..n, |t| ahead(t, R_WRIST));
    c.add(
        k >= 4,
        format!(
            "hand on the wall at shoulder height for {:.2} s (≥ 0.20); wrist reaches {best:.2} m",
            k as f32 / m.fps
        ),
    );
    c
}

/// "A person reaches up with the right hand to a point 1.9 metres above the floor, about
/// 30 cm in front of them, and holds it there from 1.5 to 2.5 seconds, in 4 seconds."
pub(super) fn s21(p: &[Motion]) -> Checks {
    let (m, mut c) = (&p[0], Checks::new());
    let s = StartFrame::of(m);
    let spot = s.origin + s.fwd * 0.3; // "about 30 cm in front of them"
    let w = span(m.len(), 1.5, 2.5); // "from 1.5 to 2.5 seconds"
    // "a point 1.9 metres above the floor": the hand there puts the wrist ≈ 0.08 m lower;
    // 1.72–1.98 m allows 0.1 m either way.
    let lo = min_over(w.clone(), |t| m.frames[t][R_WRIST].y);
    let hi = max_over(w.clone(), |t| m.frames[t][R_WRIST].y);
    c.add(
        lo >= 1.72 && hi <= 1.98,
        format!("right wrist {lo:.2}–{hi:.2} m up in 1.5–2.5 s (1.72–1.98)"),
    );
    // "about 30 cm in front": within 0.3 m of that spot on the ground.
    let d = max_over(w, |t| xz(m.frames[t][R_WRIST]).distance(spot));
    c.add(
        d <= 0.30,
        format!("right wrist up to {d:.2} m from the spot on the ground (≤ 0.30)"),
    );
    in_place(&mut c, m, 0.4);
    c
}

/// "A person stands still and holds both hands together, palms touching, in front of the
/// chest for the last 1.5 seconds, in 5 seconds."
pub(super) fn s22(p: &[Motion]) -> Checks {
    let (m, mut c) = (&p[0], Checks::new());
    let w = last(m.len(), 1.5); // "for the last 1.5 seconds"
    // "palms touching": the wrists at most 0.12 m apart.
    let d = max_over(w.clone(), |t| {
        m.frames[t][L_WRIST].distance(m.frames[t][R_WRIST])
    });
    c.add(
        d <= 0.12,
        format!("wrists up to {d:.2} m apart over the last 1.5 s (≤ 0.12)"),
    );
    // "in front of the chest": their midpoint 0.1–0.5 m in front of the chest joint, from
    // 0.3 m under it to 5 cm over the neck.
    let grip = |t: usize| (m.frames[t][L_WRIST] + m.frames[t][R_WRIST]) * 0.5;
    let front = |t: usize| xz(grip(t) - m.frames[t][SPINE3]).dot(facing_xz(&m.frames[t]));
    let (f_lo, f_hi) = (min_over(w.clone(), front), max_over(w.clone(), front));
    c.add(
        f_lo >= 0.10 && f_hi <= 0.50,
        format!("hands {f_lo:.2}–{f_hi:.2} m in front of the chest (0.10–0.50)"),
    );
    let under = min_over(w.clone(), |t| grip(t).y - m.frames[t][SPINE3].y);
    let over = max_over(w.clone(), |t| grip(t).y - m.frames[t][NECK].y);
    c.add(
        under >= -0.30 && over <= 0.05,
        format!("hands {under:+.2} m from the chest, {over:+.2} m from the neck in height (≥ -0.30, ≤ +0.05)"),
    );
    // "stands still".
    stands(&mut c, m, w.clone(), 0.80);
    still(&mut c, m, w, "last 1.5 s: ");
    c
}
