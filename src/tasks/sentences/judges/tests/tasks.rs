//! One motion each judge must call right and one (or more) it must call wrong, per task.

use super::*;

// ------------------------------------------------------------------ poses

/// Crouched: pelvis and upper body `depth` lower, knees forward.
fn crouch(depth: f32) -> Pose {
    let mut p = rest();
    for j in UPPER.iter().chain([PELVIS].iter()) {
        p[*j].y -= depth;
    }
    p[L_KNEE] += Vec3::new(0.0, -depth * 0.4, depth * 0.6);
    p[R_KNEE] += Vec3::new(0.0, -depth * 0.4, depth * 0.6);
    p
}

/// Lying stretched out, face down (`down`) or on the back, the pelvis 0.15 m up.
fn lying(down: bool) -> Pose {
    let a = if down { PI / 2.0 } else { -PI / 2.0 };
    let p = turn(
        &rest(),
        &(0..22).collect::<Vec<_>>(),
        Quat::from_rotation_x(a),
        rest()[PELVIS],
    );
    let d = 0.15 - p[PELVIS].y;
    shift(&p, Vec3::new(0.0, d, 0.0))
}

/// The upper body bent about the pelvis by `q`.
fn bend(q: Quat) -> Pose {
    let p = rest();
    let upper: Vec<usize> = UPPER
        .iter()
        .copied()
        .filter(|&j| j != L_HIP && j != R_HIP)
        .collect();
    turn(&p, &upper, q, p[PELVIS])
}

#[test]
fn s01_crouch_held() {
    let c = crouch(0.45);
    expect(
        "s01",
        &[motion(&[
            hold(&rest(), 1.0),
            ramp(&rest(), &c, 1.0),
            hold(&c, 3.0),
        ])],
        true,
    );
    // Crouches, then stands back up in the last second: not held.
    expect(
        "s01",
        &[motion(&[
            hold(&rest(), 1.0),
            ramp(&rest(), &c, 1.0),
            hold(&c, 2.0),
            ramp(&c, &rest(), 0.5),
            hold(&rest(), 0.5),
        ])],
        false,
    );
}

#[test]
fn s02_gets_up_from_the_back() {
    let l = lying(false);
    expect(
        "s02",
        &[motion(&[
            hold(&l, 1.5),
            ramp(&l, &rest(), 2.5),
            hold(&rest(), 3.0),
        ])],
        true,
    );
    expect("s02", &[motion(&[hold(&l, 7.0)])], false);
    // Starts face down instead.
    let d = lying(true);
    expect(
        "s02",
        &[motion(&[
            hold(&d, 1.5),
            ramp(&d, &rest(), 2.5),
            hold(&rest(), 3.0),
        ])],
        false,
    );
}

#[test]
fn s03_right_arm_straight_ahead() {
    let mut up = rest();
    up[R_ELBOW] = up[R_SHOULDER] + Vec3::new(0.0, 0.0, 0.26);
    up[R_WRIST] = up[R_SHOULDER] + Vec3::new(0.0, 0.02, 0.52);
    expect(
        "s03",
        &[motion(&[
            hold(&rest(), 1.5),
            ramp(&rest(), &up, 1.0),
            hold(&up, 2.5),
        ])],
        true,
    );
    // Out to the side instead of ahead.
    let mut side = rest();
    side[R_ELBOW] = side[R_SHOULDER] + Vec3::new(-0.26, 0.0, 0.0);
    side[R_WRIST] = side[R_SHOULDER] + Vec3::new(-0.52, 0.0, 0.0);
    expect(
        "s03",
        &[motion(&[
            hold(&rest(), 1.5),
            ramp(&rest(), &side, 1.0),
            hold(&side, 2.5),
        ])],
        false,
    );
}

#[test]
fn s04_left_hand_up_by_two_seconds() {
    let mut up = rest();
    up[L_ELBOW] = Vec3::new(0.22, 1.68, 0.0);
    up[L_WRIST] = Vec3::new(0.20, 1.92, 0.0);
    expect(
        "s04",
        &[motion(&[
            hold(&rest(), 0.5),
            ramp(&rest(), &up, 1.0),
            hold(&up, 3.5),
        ])],
        true,
    );
    // Both hands up: the right does not stay down.
    let mut both = up;
    both[R_ELBOW] = Vec3::new(-0.22, 1.68, 0.0);
    both[R_WRIST] = Vec3::new(-0.20, 1.92, 0.0);
    expect(
        "s04",
        &[motion(&[
            hold(&rest(), 0.5),
            ramp(&rest(), &both, 1.0),
            hold(&both, 3.5),
        ])],
        false,
    );
    // Up only from 3 s.
    expect(
        "s04",
        &[motion(&[
            hold(&rest(), 2.0),
            ramp(&rest(), &up, 1.0),
            hold(&up, 2.0),
        ])],
        false,
    );
}

#[test]
fn s05_bow_about_a_second() {
    let b = bend(Quat::from_rotation_x(55f32.to_radians()));
    let bow = [
        hold(&rest(), 1.3),
        ramp(&rest(), &b, 0.4),
        hold(&b, 1.0),
        ramp(&b, &rest(), 0.4),
        hold(&rest(), 1.9),
    ];
    expect("s05", &[motion(&bow)], true);
    // Still bowed at the end.
    expect(
        "s05",
        &[motion(&[
            hold(&rest(), 1.3),
            ramp(&rest(), &b, 0.4),
            hold(&b, 3.3),
        ])],
        false,
    );
    // Bends backwards.
    let back = bend(Quat::from_rotation_x(-55f32.to_radians()));
    expect(
        "s05",
        &[motion(&[
            hold(&rest(), 1.3),
            ramp(&rest(), &back, 0.4),
            hold(&back, 1.0),
            ramp(&back, &rest(), 0.4),
            hold(&rest(), 1.9),
        ])],
        false,
    );
}

#[test]
fn s06_lean_left_held() {
    // Rotating about −Z tips +Y towards +X, the body's left.
    let l = bend(Quat::from_rotation_z(-25f32.to_radians()));
    expect(
        "s06",
        &[motion(&[
            hold(&rest(), 1.5),
            ramp(&rest(), &l, 1.0),
            hold(&l, 2.5),
        ])],
        true,
    );
    let r = bend(Quat::from_rotation_z(25f32.to_radians()));
    expect(
        "s06",
        &[motion(&[
            hold(&rest(), 1.5),
            ramp(&rest(), &r, 1.0),
            hold(&r, 2.5),
        ])],
        false,
    );
}

#[test]
fn s07_face_down_held() {
    let d = lying(true);
    expect(
        "s07",
        &[motion(&[
            hold(&rest(), 2.0),
            ramp(&rest(), &d, 3.0),
            hold(&d, 3.0),
        ])],
        true,
    );
    let b = lying(false);
    expect(
        "s07",
        &[motion(&[
            hold(&rest(), 2.0),
            ramp(&rest(), &b, 3.0),
            hold(&b, 3.0),
        ])],
        false,
    );
}

#[test]
fn s08_balances_on_the_left_leg() {
    let mut one = rest();
    for j in [R_KNEE, R_ANKLE, R_FOOT] {
        one[j] += Vec3::new(0.0, 0.2, 0.1);
    }
    expect(
        "s08",
        &[motion(&[
            hold(&rest(), 1.5),
            ramp(&rest(), &one, 0.5),
            hold(&one, 2.0),
        ])],
        true,
    );
    // The left foot up instead.
    let mut other = rest();
    for j in [L_KNEE, L_ANKLE, L_FOOT] {
        other[j] += Vec3::new(0.0, 0.2, 0.1);
    }
    expect(
        "s08",
        &[motion(&[
            hold(&rest(), 1.5),
            ramp(&rest(), &other, 0.5),
            hold(&other, 2.0),
        ])],
        false,
    );
}

// ------------------------------------------------------------------ paths

/// Walk `dist` m along +Z in `walk_s`, turn in place to `yaw` over `turn_s`, then stand.
fn walk_then_turn(dist: f32, walk_s: f32, yaw: f32, turn_s: f32, total: f32) -> Motion {
    let k = (walk_s * 20.0) as usize;
    let t = (turn_s * 20.0) as usize;
    let n = (total * 20.0) as usize;
    let path: Vec<Vec2> = (0..n)
        .map(|i| v2(0.0, dist * (i.min(k) as f32 / k as f32)))
        .collect();
    let yaws: Vec<f32> = (0..n)
        .map(|i| yaw * ((i.saturating_sub(k)).min(t) as f32 / t as f32))
        .collect();
    along(&path, &yaws, &rest())
}

#[test]
fn s09_walks_then_faces_right() {
    expect(
        "s09",
        &[walk_then_turn(2.0, 2.0, -PI / 2.0, 1.5, 7.0)],
        true,
    );
    expect(
        "s09",
        &[walk_then_turn(2.0, 2.0, PI / 2.0, 1.5, 7.0)],
        false,
    );
    // The long way round to the left, ending facing right.
    expect(
        "s09",
        &[walk_then_turn(2.0, 2.0, 1.5 * PI, 2.5, 7.0)],
        false,
    );
}

#[test]
fn s10_slow_walk() {
    expect(
        "s10",
        &[walk(&[v2(0.0, 0.0), v2(0.0, 10.0)], 0.34, 6.0)],
        true,
    );
    // Two metres at an ordinary pace, then standing: not slow.
    expect(
        "s10",
        &[walk(&[v2(0.0, 0.0), v2(0.0, 2.0)], 1.3, 6.0)],
        false,
    );
}

#[test]
fn s11_run_then_stop() {
    expect(
        "s11",
        &[walk(&[v2(0.0, 0.0), v2(0.0, 10.0)], 3.0, 5.0)],
        true,
    );
    expect(
        "s11",
        &[walk(&[v2(0.0, 0.0), v2(0.0, 7.0)], 2.0, 5.0)],
        false,
    );
}

#[test]
fn s12_backwards_facing_forward() {
    let path = polyline(&[v2(0.0, 0.0), v2(0.0, -2.0)], 0.6, 100);
    expect("s12", &[along(&path, &vec![0.0; 100], &rest())], true);
    // Turned around, walking forwards to −Z.
    let mut yaws = vec![PI; 100];
    yaws[..5].fill(0.0);
    expect("s12", &[along(&path, &yaws, &rest())], false);
}

#[test]
fn s13_stops_before_the_line() {
    // Pelvis to 2.7 m: the toes (0.10 m ahead of it) at 2.8 m.
    expect(
        "s13",
        &[walk(&[v2(0.0, 0.0), v2(0.0, 2.7)], 1.0, 6.0)],
        true,
    );
    // Over the line.
    expect(
        "s13",
        &[walk(&[v2(0.0, 0.0), v2(0.0, 3.0)], 1.0, 6.0)],
        false,
    );
    // Stops well short of it.
    expect(
        "s13",
        &[walk(&[v2(0.0, 0.0), v2(0.0, 1.5)], 1.0, 6.0)],
        false,
    );
}

#[test]
fn s14_left_turn_corner() {
    expect(
        "s14",
        &[walk(&[v2(0.0, 0.0), v2(0.0, 2.0), v2(2.0, 2.0)], 0.8, 7.0)],
        true,
    );
    expect(
        "s14",
        &[walk(&[v2(0.0, 0.0), v2(0.0, 2.0), v2(-2.0, 2.0)], 0.8, 7.0)],
        false,
    );
}

#[test]
fn s15_curve_to_the_right() {
    let n = 100;
    let arc: Vec<Vec2> = (0..n)
        .map(|i| {
            let a = (i as f32 / (n - 1) as f32) * PI / 2.0;
            v2(-2.5 + 2.5 * a.cos(), 2.5 * a.sin())
        })
        .collect();
    expect("s15", &[along(&arc, &path_yaws(&arc, 0.0), &rest())], true);
    // Straight on, then a pivot to the right at the end.
    let mut yaws = vec![0.0; n];
    let line = polyline(&[v2(0.0, 0.0), v2(0.0, 2.5), v2(-2.5, 2.5)], 1.4, n);
    for (i, y) in yaws.iter_mut().enumerate() {
        *y = if line[i].x < -0.01 { -PI / 2.0 } else { 0.0 };
    }
    expect("s15", &[along(&line, &yaws, &rest())], false);
}

#[test]
fn s16_walk_then_run() {
    let n = 120;
    let mut z = 0.0;
    let path: Vec<Vec2> = (0..n)
        .map(|i| {
            let p = v2(0.0, z);
            z += if i < 62 { 1.3 } else { 3.0 } / 20.0;
            p
        })
        .collect();
    expect("s16", &[along(&path, &vec![0.0; n], &rest())], true);
    expect(
        "s16",
        &[walk(&[v2(0.0, 0.0), v2(0.0, 20.0)], 1.3, 6.0)],
        false,
    );
}

// ------------------------------------------------------------------ contacts

#[test]
fn s17_hand_on_head_by_two_seconds() {
    let mut on = rest();
    on[R_ELBOW] = Vec3::new(-0.30, 1.50, 0.05);
    on[R_WRIST] = on[HEAD] + Vec3::new(-0.07, 0.08, 0.0);
    expect(
        "s17",
        &[motion(&[
            hold(&rest(), 0.8),
            ramp(&rest(), &on, 1.0),
            hold(&on, 3.2),
        ])],
        true,
    );
    // At the side of the face, not on top.
    let mut side = on;
    side[R_WRIST] = on[HEAD] + Vec3::new(-0.2, -0.08, 0.0);
    expect(
        "s17",
        &[motion(&[
            hold(&rest(), 0.8),
            ramp(&rest(), &side, 1.0),
            hold(&side, 3.2),
        ])],
        false,
    );
}

#[test]
fn s18_right_hand_to_left_knee_once() {
    let mut t = bend(Quat::from_rotation_x(35f32.to_radians()));
    t[R_WRIST] = rest()[L_KNEE] + Vec3::new(-0.02, 0.05, 0.06);
    let once = [
        hold(&rest(), 1.0),
        ramp(&rest(), &t, 0.6),
        hold(&t, 0.3),
        ramp(&t, &rest(), 0.6),
        hold(&rest(), 1.5),
    ];
    expect("s18", &[motion(&once)], true);
    let twice = [
        hold(&rest(), 0.4),
        ramp(&rest(), &t, 0.4),
        ramp(&t, &rest(), 0.4),
        ramp(&rest(), &t, 0.4),
        ramp(&t, &rest(), 0.4),
        hold(&rest(), 2.0),
    ];
    expect("s18", &[motion(&twice)], false);
}

#[test]
fn s19_puts_it_down_half_a_metre_ahead() {
    let mut down = crouch(0.4);
    down[R_WRIST] = Vec3::new(0.0, 0.08, 0.6);
    let m = [
        hold(&rest(), 1.0),
        ramp(&rest(), &down, 1.0),
        hold(&down, 0.5),
        ramp(&down, &rest(), 1.0),
        hold(&rest(), 1.5),
    ];
    expect("s19", &[motion(&m)], true);
    let mut beside = down;
    beside[R_WRIST] = Vec3::new(-0.35, 0.08, 0.1);
    let m = [
        hold(&rest(), 1.0),
        ramp(&rest(), &beside, 1.0),
        hold(&beside, 0.5),
        ramp(&beside, &rest(), 1.0),
        hold(&rest(), 1.5),
    ];
    expect("s19", &[motion(&m)], false);
}

/// Walk to `stop` m ahead by 3 s, then put the right hand `reach` m ahead at shoulder
/// height for a second.
fn wall_touch(stop: f32, reach: f32) -> Motion {
    let mut m = walk(&[v2(0.0, 0.0), v2(0.0, stop)], stop / 2.5, 5.0);
    for t in 66..86 {
        let p = &mut m.frames[t];
        p[R_ELBOW] = p[R_SHOULDER] + Vec3::new(0.0, 0.0, 0.25);
        p[R_WRIST] = Vec3::new(p[R_SHOULDER].x, p[R_SHOULDER].y, reach);
    }
    m
}

#[test]
fn s20_touches_the_wall_without_going_through() {
    expect("s20", &[wall_touch(1.45, 1.92)], true);
    // Never reaches it.
    expect("s20", &[wall_touch(1.0, 1.45)], false);
    // Walks into it.
    expect("s20", &[wall_touch(1.95, 2.3)], false);
}

#[test]
fn s21_reaches_up_and_holds() {
    let mut up = rest();
    up[R_ELBOW] = Vec3::new(-0.15, 1.65, 0.12);
    up[R_WRIST] = Vec3::new(-0.1, 1.85, 0.28);
    expect(
        "s21",
        &[motion(&[
            hold(&rest(), 0.8),
            ramp(&rest(), &up, 0.6),
            hold(&up, 1.5),
            ramp(&up, &rest(), 0.6),
            hold(&rest(), 0.5),
        ])],
        true,
    );
    // Not high enough.
    let mut low = up;
    low[R_WRIST].y = 1.6;
    expect(
        "s21",
        &[motion(&[
            hold(&rest(), 0.8),
            ramp(&rest(), &low, 0.6),
            hold(&low, 1.5),
            ramp(&low, &rest(), 0.6),
            hold(&rest(), 0.5),
        ])],
        false,
    );
}

#[test]
fn s22_hands_together_in_front_of_the_chest() {
    let mut h = rest();
    h[L_ELBOW] = Vec3::new(0.2, 1.15, 0.15);
    h[R_ELBOW] = Vec3::new(-0.2, 1.15, 0.15);
    h[L_WRIST] = Vec3::new(0.03, 1.25, 0.3);
    h[R_WRIST] = Vec3::new(-0.03, 1.25, 0.3);
    expect(
        "s22",
        &[motion(&[
            hold(&rest(), 2.0),
            ramp(&rest(), &h, 1.0),
            hold(&h, 2.0),
        ])],
        true,
    );
    expect("s22", &[motion(&[hold(&rest(), 5.0)])], false);
}

// ------------------------------------------------------------------ people

/// Two people face to face along Z, `a` from 0 and `b` from `gap`, walking towards each
/// other `each` m in `secs`, then standing to `total`.
fn meet(gap: f32, each: f32, secs: f32, total: f32) -> (Motion, Motion) {
    let a = walk(&[v2(0.0, 0.0), v2(0.0, each)], each / secs, total);
    let b = walk(&[v2(0.0, gap), v2(0.0, gap - each)], each / secs, total);
    (a, b)
}

#[test]
fn s23_meet_about_a_metre_apart() {
    let (a, b) = meet(4.0, 1.5, 3.0, 6.0);
    expect("s23", &[a, b], true);
    let (a, b) = meet(4.0, 0.8, 3.0, 6.0);
    expect("s23", &[a, b], false);
}

#[test]
fn s24_handshake_held() {
    let (mut a, mut b) = meet(3.0, 1.1, 3.0, 6.0);
    for t in 80..120 {
        a.frames[t][R_WRIST] = Vec3::new(-0.03, 1.0, 1.45);
        b.frames[t][R_WRIST] = Vec3::new(0.03, 1.0, 1.55);
    }
    expect("s24", &[a.clone(), b.clone()], true);
    // Only until 4.5 s: not held for the last 1.5 s.
    for t in 90..120 {
        b.frames[t][R_WRIST] = b.frames[0][R_WRIST] + Vec3::new(0.0, 0.0, -1.1);
    }
    expect("s24", &[a, b], false);
}

#[test]
fn s25_draw_together_side_by_side() {
    // Setting off straight ahead, veering in, and straight again at the end.
    let a = walk(
        &[v2(1.5, 0.0), v2(1.5, 0.5), v2(0.5, 2.5), v2(0.5, 3.0)],
        0.6,
        6.0,
    );
    let b = walk(
        &[v2(-1.5, 0.0), v2(-1.5, 0.5), v2(-0.5, 2.5), v2(-0.5, 3.0)],
        0.6,
        6.0,
    );
    expect("s25", &[a, b], true);
    let a = walk(&[v2(1.5, 0.0), v2(1.5, 3.0)], 0.6, 6.0);
    let b = walk(&[v2(-1.5, 0.0), v2(-1.5, 3.0)], 0.6, 6.0);
    expect("s25", &[a, b], false);
}

#[test]
fn s26_follows_the_same_path() {
    let lead = [v2(0.0, 0.0), v2(0.0, 3.0), v2(4.0, 3.0)];
    let a = walk(&lead, 1.0, 7.0);
    let b = walk(&[v2(0.0, -1.5), v2(0.0, 3.0), v2(4.0, 3.0)], 1.0, 7.0);
    expect("s26", &[a.clone(), b], true);
    // The second person walks straight on instead of turning.
    let b = walk(&[v2(0.0, -1.5), v2(0.0, 5.5)], 1.0, 7.0);
    expect("s26", &[a, b], false);
}

#[test]
fn s27_waves_while_the_other_walks_past() {
    let n = 120;
    let mut a = Motion::new(hold(&rest(), 6.0));
    for (t, p) in a.frames.iter_mut().enumerate().take(110).skip(10) {
        let s = (2.0 * PI * t as f32 / 20.0).sin();
        p[R_ELBOW] = Vec3::new(-0.35, 1.40, 0.05);
        p[R_WRIST] = Vec3::new(-0.30 + 0.12 * s, 1.65, 0.05);
    }
    let pass = |z: f32| {
        let path = polyline(&[v2(2.5, z), v2(-2.5, z)], 5.0 / 6.0, n);
        along(&path, &vec![-PI / 2.0; n], &rest())
    };
    expect("s27", &[a.clone(), pass(2.0)], true);
    // Passes behind the waver.
    expect("s27", &[a, pass(-2.0)], false);
    // Nobody waves.
    expect("s27", &[Motion::new(hold(&rest(), 6.0)), pass(2.0)], false);
}

#[test]
fn s28_three_close_in_on_the_centre() {
    let r0 = 1.0 / (PI / 3.0).sin(); // 2 m neighbours on a circle, as mprog places three
    let centre = v2(0.0, r0);
    let three = |end_r: f32| -> Vec<Motion> {
        (0..3)
            .map(|i| {
                // The first at the origin facing +Z, the next going round to its right.
                let ang = -2.0 * PI / 3.0 * i as f32;
                let dir = v2(ang.sin(), -ang.cos()); // from the centre to the person
                let start = centre + dir * r0;
                let stop = centre + dir * end_r;
                let path = polyline(&[start, stop], (r0 - end_r) / 2.0, 100);
                // Facing the centre: along −dir, yaw −ang.
                along(&path, &vec![-ang; 100], &rest())
            })
            .collect()
    };
    expect("s28", &three(0.58), true);
    expect("s28", &three(0.3), false);
}
