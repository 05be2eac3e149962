//! The sentence judges: two or three people (s23–s28).

use super::*;

/// How far `a` and `b` each walked towards the other (from their start positions).
fn approaches(a: &Motion, b: &Motion) -> (f32, f32) {
    let (a0, b0) = (xz(a.frames[0][PELVIS]), xz(b.frames[0][PELVIS]));
    let u = unit2(b0 - a0);
    let (an, bn) = (
        xz(a.frames[a.len() - 1][PELVIS]),
        xz(b.frames[b.len() - 1][PELVIS]),
    );
    ((an - a0).dot(u), (bn - b0).dot(-u))
}

/// "Two people start about 4 metres apart facing each other, walk towards each other and
/// stop about 1 metre apart, standing still for the last 2 seconds, in 6 seconds."
pub(super) fn s23(p: &[Motion]) -> Checks {
    let (a, b, mut c) = (&p[0], &p[1], Checks::new());
    let n = a.len();
    // "about 4 metres apart": 3.4–4.6 m; "facing each other": each within 45° of the other.
    let d0 = pelvis_gap(a, b, 0);
    c.add(
        (3.4..=4.6).contains(&d0),
        format!("start {d0:.2} m apart (3.4–4.6)"),
    );
    let (fa, fb) = (towards_deg(a, b, 0), towards_deg(b, a, 0));
    c.add(
        fa <= 45.0 && fb <= 45.0,
        format!("start facing each other within {fa:.0}°/{fb:.0}° (≤ 45)"),
    );
    // "walk towards each other": each at least 0.75 m.
    let (wa, wb) = approaches(a, b);
    c.add(
        wa >= 0.75 && wb >= 0.75,
        format!("walk {wa:.2}/{wb:.2} m towards each other (≥ 0.75 each)"),
    );
    let w = last(n, 2.0); // "for the last 2 seconds"
    // "about 1 metre apart": 0.6–1.5 m, every frame.
    let lo = min_over(w.clone(), |t| pelvis_gap(a, b, t));
    let hi = max_over(w.clone(), |t| pelvis_gap(a, b, t));
    c.add(
        lo >= 0.6 && hi <= 1.5,
        format!("{lo:.2}–{hi:.2} m apart over the last 2 s (0.6–1.5)"),
    );
    still(&mut c, a, w.clone(), "first person, last 2 s: ");
    still(&mut c, b, w, "second person, last 2 s: ");
    let (ea, eb) = (towards_deg(a, b, n - 1), towards_deg(b, a, n - 1));
    c.add(
        ea <= 45.0 && eb <= 45.0,
        format!("end facing each other within {ea:.0}°/{eb:.0}° (≤ 45)"),
    );
    c
}

/// "Two people walk up to each other from about 3 metres apart and shake right hands,
/// holding the handshake for the last 1.5 seconds, in 6 seconds."
pub(super) fn s24(p: &[Motion]) -> Checks {
    let (a, b, mut c) = (&p[0], &p[1], Checks::new());
    let d0 = pelvis_gap(a, b, 0);
    c.add(
        (2.4..=3.6).contains(&d0),
        format!("start {d0:.2} m apart (2.4–3.6)"),
    );
    // "walk up to each other": both move, at least 0.4 m each.
    let (wa, wb) = approaches(a, b);
    c.add(
        wa >= 0.4 && wb >= 0.4,
        format!("walk {wa:.2}/{wb:.2} m towards each other (≥ 0.40 each)"),
    );
    let w = last(a.len(), 1.5); // "for the last 1.5 seconds"
    // "shake right hands": the right wrists at most 0.18 m apart (clasped hands hold them
    // ≈ 0.1–0.15 m apart), between waist and chest height (0.75–1.3 m).
    let d = max_over(w.clone(), |t| {
        a.frames[t][R_WRIST].distance(b.frames[t][R_WRIST])
    });
    c.add(
        d <= 0.18,
        format!("right wrists up to {d:.2} m apart over the last 1.5 s (≤ 0.18)"),
    );
    let mid = |t: usize| (a.frames[t][R_WRIST].y + b.frames[t][R_WRIST].y) * 0.5;
    let (lo, hi) = (min_over(w.clone(), mid), max_over(w.clone(), mid));
    c.add(
        lo >= 0.75 && hi <= 1.30,
        format!("hands {lo:.2}–{hi:.2} m up (0.75–1.30)"),
    );
    // A handshake faces the other person: within 45°.
    let fa = max_over(w.clone(), |t| towards_deg(a, b, t));
    let fb = max_over(w, |t| towards_deg(b, a, t));
    c.add(
        fa <= 45.0 && fb <= 45.0,
        format!("facing each other within {fa:.0}°/{fb:.0}° (≤ 45)"),
    );
    c
}

/// "Two people start side by side about 3 metres apart, facing the same way, and walk
/// forward about 3 metres while drawing together, ending side by side about 1 metre apart,
/// in 6 seconds."
pub(super) fn s25(p: &[Motion]) -> Checks {
    let (a, b, mut c) = (&p[0], &p[1], Checks::new());
    let n = a.len();
    let (fa, fb) = (StartFrame::of(a).fwd, StartFrame::of(b).fwd);
    // "facing the same way": within 30°.
    let same = fa.dot(fb).clamp(-1.0, 1.0).acos().to_degrees();
    c.add(
        same <= 30.0,
        format!("start facings {same:.0}° apart (≤ 30)"),
    );
    let f = unit2(fa + fb);
    let off = |t: usize| xz(b.frames[t][PELVIS]) - xz(a.frames[t][PELVIS]);
    // "side by side about 3 metres apart": 2.4–3.6 m, at most 0.5 m ahead of the other.
    let (g0, s0) = (off(0).length(), off(0).dot(f).abs());
    c.add(
        (2.4..=3.6).contains(&g0) && s0 <= 0.5,
        format!("start {g0:.2} m apart, {s0:.2} m ahead of the other (2.4–3.6, ≤ 0.5)"),
    );
    // "ending side by side about 1 metre apart": 0.6–1.4 m, at most 0.5 m ahead.
    let (g1, s1) = (off(n - 1).length(), off(n - 1).dot(f).abs());
    c.add(
        (0.6..=1.4).contains(&g1) && s1 <= 0.5,
        format!("end {g1:.2} m apart, {s1:.2} m ahead of the other (0.6–1.4, ≤ 0.5)"),
    );
    // "walk forward about 3 metres": 2.2–3.8 m each along the shared facing.
    let go = |m: &Motion| (xz(m.frames[n - 1][PELVIS]) - xz(m.frames[0][PELVIS])).dot(f);
    let (ga, gb) = (go(a), go(b));
    c.add(
        (2.2..=3.8).contains(&ga) && (2.2..=3.8).contains(&gb),
        format!("walk {ga:.2}/{gb:.2} m forward (2.2–3.8 each)"),
    );
    walks_facing(&mut c, a, "first person ");
    walks_facing(&mut c, b, "second person ");
    c
}

/// "One person walks forward and turns left, and a second person starting about 1.5 metres
/// behind them follows along the same path, staying between 1 and 2.5 metres behind, in 7
/// seconds."
pub(super) fn s26(p: &[Motion]) -> Checks {
    let (a, b, mut c) = (&p[0], &p[1], Checks::new());
    let n = a.len();
    let sa = StartFrame::of(a);
    // The leader "turns left": 45–135° to the left at the end, and has gone ≥ 0.8 m left.
    let yaw = end_yaw(a);
    c.add(
        (45.0..=135.0).contains(&yaw),
        format!("leader ends turned {yaw:+.0}° (+45…+135, left)"),
    );
    let (_, left) = sa.local(a.frames[n - 1][PELVIS]);
    c.add(
        left >= 0.8,
        format!("leader ends {left:.2} m to the left (≥ 0.8)"),
    );
    // "starting about 1.5 metres behind them": 1.1–1.9 m apart, ≥ 1 m behind.
    let d0 = pelvis_gap(a, b, 0);
    let (behind, _) = sa.local(b.frames[0][PELVIS]);
    c.add(
        (1.1..=1.9).contains(&d0) && behind <= -1.0,
        format!(
            "follower starts {d0:.2} m away, {:.2} m behind (1.1–1.9, ≥ 1.0)",
            -behind
        ),
    );
    // "staying between 1 and 2.5 metres behind": every frame, 0.1–0.2 m for measuring.
    let lo = min_over(0..n, |t| pelvis_gap(a, b, t));
    let hi = max_over(0..n, |t| pelvis_gap(a, b, t));
    c.add(
        lo >= 0.9 && hi <= 2.7,
        format!("{lo:.2}–{hi:.2} m apart (0.9–2.7)"),
    );
    // "follows along the same path": from 1.5 s on, the follower within 0.5 m of a place
    // the leader has already been.
    let pa = pelvis_xz(a);
    let off = max_over(from(n, 1.5), |t| {
        let q = xz(b.frames[t][PELVIS]);
        pa[..=t]
            .iter()
            .map(|x| x.distance(q))
            .fold(f32::INFINITY, f32::min)
    });
    c.add(
        off <= 0.5,
        format!("follower up to {off:.2} m off the leader's path (≤ 0.50)"),
    );
    walks_facing(&mut c, a, "leader ");
    walks_facing(&mut c, b, "follower ");
    c
}

/// "One person stands in place and waves the right hand while a second person walks past
/// in front of them, from their left to their right, about 2 metres in front of them, in 6
/// seconds."
pub(super) fn s27(p: &[Motion]) -> Checks {
    let (a, b, mut c) = (&p[0], &p[1], Checks::new());
    let n = a.len();
    in_place(&mut c, a, 0.4);
    // "waves the right hand": raised to the shoulder or above for at least 3 s in all
    // (most of the passing) and swung side to side (≥ 4 changes of direction: two waves).
    let (flips, raised) = right_hand_swings(a);
    let secs = raised as f32 / a.fps;
    c.add(
        secs >= 3.0,
        format!("waver's right hand up for {secs:.1} s (≥ 3.0)"),
    );
    c.add(flips >= 4, format!("{flips} side-to-side swings (≥ 4)"));
    // The walker in the waver's own frame: from its left (≥ 1 m) to its right (≥ 1 m).
    let s = StartFrame::of(a);
    let at = |t: usize| s.local(b.frames[t][PELVIS]);
    let (l0, l1) = (at(0).1, at(n - 1).1);
    c.add(
        l0 >= 1.0 && l1 <= -1.0,
        format!("walker from {l0:+.2} to {l1:+.2} m to the waver's left (≥ +1.0 → ≤ -1.0)"),
    );
    // "about 2 metres in front of them" where it passes (1.4–2.6 m), and in front all along.
    match (0..n).find(|&t| at(t).1 <= 0.0) {
        Some(t) => {
            let f = at(t).0;
            c.add(
                (1.4..=2.6).contains(&f),
                format!("passes {f:.2} m in front (1.4–2.6)"),
            );
            // "while": the waver's hand up as the walker passes.
            let up = a.frames[t][R_WRIST].y >= a.frames[t][R_SHOULDER].y;
            c.add(
                up,
                format!(
                    "waver's hand {} as the walker passes",
                    if up { "up" } else { "down" }
                ),
            );
        }
        None => {
            c.add(false, "the walker never passes in front");
        }
    }
    let front = min_over(0..n, |t| at(t).0);
    c.add(
        front >= 1.0,
        format!("walker at least {front:.2} m in front (≥ 1.0)"),
    );
    walks_facing(&mut c, b, "walker ");
    c
}

/// "Three people stand in a triangle about 2 metres apart, facing its centre; each walks a
/// step or two towards the centre and they end about 1 metre from one another, never closer
/// than 0.6 metres, standing still for the last 2 seconds, in 5 seconds."
pub(super) fn s28(p: &[Motion]) -> Checks {
    let mut c = Checks::new();
    let n = p[0].len();
    let pairs = [(0, 1), (1, 2), (0, 2)];
    let gaps = |t: usize| pairs.map(|(i, k)| pelvis_gap(&p[i], &p[k], t));
    // "about 2 metres apart": 1.6–2.4 m each pair.
    let g0 = gaps(0);
    c.add(
        g0.iter().all(|g| (1.6..=2.4).contains(g)),
        format!(
            "start {:.2}/{:.2}/{:.2} m apart (1.6–2.4)",
            g0[0], g0[1], g0[2]
        ),
    );
    // "facing its centre": each within 45°.
    let centre = p
        .iter()
        .map(|m| xz(m.frames[0][PELVIS]))
        .sum::<glam::Vec2>()
        / 3.0;
    let face: Vec<f32> = p
        .iter()
        .map(|m| {
            let to = unit2(centre - xz(m.frames[0][PELVIS]));
            facing_xz(&m.frames[0])
                .dot(to)
                .clamp(-1.0, 1.0)
                .acos()
                .to_degrees()
        })
        .collect();
    let worst = face.iter().copied().fold(0.0, f32::max);
    c.add(
        worst <= 45.0,
        format!("start facing the centre within {worst:.0}° (≤ 45)"),
    );
    // "each walks a step or two towards the centre": each ≥ 0.3 m closer to it.
    let closer: Vec<f32> = p
        .iter()
        .map(|m| {
            xz(m.frames[0][PELVIS]).distance(centre) - xz(m.frames[n - 1][PELVIS]).distance(centre)
        })
        .collect();
    let least = closer.iter().copied().fold(f32::INFINITY, f32::min);
    c.add(
        least >= 0.3,
        format!("each at least {least:.2} m closer to the centre (≥ 0.30)"),
    );
    let w = last(n, 2.0); // "for the last 2 seconds"
    // "about 1 metre from one another": 0.7–1.4 m every pair, every frame.
    let lo = min_over(w.clone(), |t| {
        gaps(t).into_iter().fold(f32::INFINITY, f32::min)
    });
    let hi = max_over(w.clone(), |t| {
        gaps(t).into_iter().fold(f32::NEG_INFINITY, f32::max)
    });
    c.add(
        lo >= 0.7 && hi <= 1.4,
        format!("{lo:.2}–{hi:.2} m apart over the last 2 s (0.7–1.4)"),
    );
    // "never closer than 0.6 metres".
    let ever = min_over(0..n, |t| gaps(t).into_iter().fold(f32::INFINITY, f32::min));
    c.add(
        ever >= 0.6,
        format!("never closer than {ever:.2} m (≥ 0.60)"),
    );
    for (i, m) in p.iter().enumerate() {
        still(
            &mut c,
            m,
            w.clone(),
            &format!("person {}, last 2 s: ", i + 1),
        );
    }
    c
}
