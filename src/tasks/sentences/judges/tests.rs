//! Self-tests of the sentence judges on synthetic motions: a standing rest pose moved
//! rigidly along paths, turned, bent and posed, one motion a judge must call right and one
//! it must call wrong per task; the conventions of facing and yaw; the common checks; and
//! the task list against `bench/sentences/tasks.toml`.

mod tasks;

use super::*;
use glam::{Quat, Vec2, Vec3};
use std::f32::consts::PI;

const N_PER_S: usize = 20;

/// A standing rest pose at the origin facing +Z, left +X, from plausible HumanML3D
/// offsets: pelvis 0.95 m, hips ±0.08 m, thighs 0.38 m, shins 0.42 m, arms 0.52 m.
fn rest() -> Pose {
    let mut p = [Vec3::ZERO; 22];
    let mut set = |j: usize, x: f32, y: f32, z: f32| p[j] = Vec3::new(x, y, z);
    set(PELVIS, 0.0, 0.95, 0.0);
    set(L_HIP, 0.08, 0.88, 0.0);
    set(R_HIP, -0.08, 0.88, 0.0);
    set(SPINE1, 0.0, 1.07, -0.01);
    set(L_KNEE, 0.09, 0.50, 0.01);
    set(R_KNEE, -0.09, 0.50, 0.01);
    set(SPINE2, 0.0, 1.20, 0.0);
    set(L_ANKLE, 0.10, 0.08, -0.03);
    set(R_ANKLE, -0.10, 0.08, -0.03);
    set(SPINE3, 0.0, 1.26, 0.02);
    set(L_FOOT, 0.11, 0.02, 0.10);
    set(R_FOOT, -0.11, 0.02, 0.10);
    set(NECK, 0.0, 1.47, 0.0);
    set(L_COLLAR, 0.08, 1.40, 0.0);
    set(R_COLLAR, -0.08, 1.40, 0.0);
    set(HEAD, 0.0, 1.56, 0.04);
    set(L_SHOULDER, 0.19, 1.42, 0.0);
    set(R_SHOULDER, -0.19, 1.42, 0.0);
    set(L_ELBOW, 0.22, 1.16, -0.01);
    set(R_ELBOW, -0.22, 1.16, -0.01);
    set(L_WRIST, 0.24, 0.90, 0.02);
    set(R_WRIST, -0.24, 0.90, 0.02);
    p
}

type Pose = crate::motion::Pose;

/// The upper body (lower back up, arms included).
const UPPER: [usize; 15] = [
    SPINE1, SPINE2, SPINE3, NECK, L_COLLAR, R_COLLAR, HEAD, L_SHOULDER, R_SHOULDER, L_ELBOW,
    R_ELBOW, L_WRIST, R_WRIST, L_HIP, R_HIP,
];

/// `pose` turned by `yaw` about +Y (positive: counter-clockwise seen from above, +Z to +X,
/// a left turn) around its pelvis, and moved to the ground point `at` (x, z).
fn place(pose: &Pose, at: Vec2, yaw: f32) -> Pose {
    let q = Quat::from_rotation_y(yaw);
    let c = Vec3::new(pose[PELVIS].x, 0.0, pose[PELVIS].z);
    pose.map(|p| q * (p - c) + Vec3::new(at.x, 0.0, at.y))
}

/// Joints `js` of `pose` turned by `q` around `pivot`.
fn turn(pose: &Pose, js: &[usize], q: Quat, pivot: Vec3) -> Pose {
    let mut out = *pose;
    for &j in js {
        out[j] = q * (pose[j] - pivot) + pivot;
    }
    out
}

/// Every joint moved by `d`.
fn shift(pose: &Pose, d: Vec3) -> Pose {
    pose.map(|p| p + d)
}

/// Linear blend of two poses (0 → `a`, 1 → `b`).
fn blend(a: &Pose, b: &Pose, k: f32) -> Pose {
    std::array::from_fn(|j| a[j].lerp(b[j], k))
}

/// `secs` seconds of `pose`.
fn hold(pose: &Pose, secs: f32) -> Vec<Pose> {
    vec![*pose; (secs * N_PER_S as f32).round() as usize]
}

/// `secs` seconds going from `a` to `b`.
fn ramp(a: &Pose, b: &Pose, secs: f32) -> Vec<Pose> {
    let k = (secs * N_PER_S as f32).round() as usize;
    (0..k)
        .map(|i| blend(a, b, (i + 1) as f32 / k as f32))
        .collect()
}

fn motion(parts: &[Vec<Pose>]) -> Motion {
    Motion::new(parts.concat())
}

/// The rest pose carried along a ground path, facing the given yaws.
fn along(path: &[Vec2], yaws: &[f32], pose: &Pose) -> Motion {
    Motion::new(
        path.iter()
            .zip(yaws)
            .map(|(&p, &y)| place(pose, p, y))
            .collect(),
    )
}

/// Yaws facing along a path (standing frames keep the last heading), unwrapped.
fn path_yaws(path: &[Vec2], first: f32) -> Vec<f32> {
    let mut out = Vec::with_capacity(path.len());
    let mut last = first;
    for i in 0..path.len() {
        let d = path[(i + 1).min(path.len() - 1)] - path[i.saturating_sub(1)];
        if d.length() > 1e-5 {
            let mut y = d.x.atan2(d.y);
            while y - last > PI {
                y -= 2.0 * PI;
            }
            while y - last < -PI {
                y += 2.0 * PI;
            }
            last = y;
        }
        out.push(last);
    }
    out
}

/// `n` frames along a polyline at `speed` m/s, stopping at its end.
fn polyline(pts: &[Vec2], speed: f32, n: usize) -> Vec<Vec2> {
    (0..n)
        .map(|i| {
            let mut left = i as f32 / N_PER_S as f32 * speed;
            for w in pts.windows(2) {
                let len = w[0].distance(w[1]);
                if left <= len {
                    return w[0].lerp(w[1], left / len.max(1e-9));
                }
                left -= len;
            }
            pts[pts.len() - 1]
        })
        .collect()
}

/// A rigid walk along a polyline, facing the way it goes.
fn walk(pts: &[Vec2], speed: f32, secs: f32) -> Motion {
    let path = polyline(pts, speed, (secs * N_PER_S as f32).round() as usize);
    let d = pts[1] - pts[0];
    along(&path, &path_yaws(&path, d.x.atan2(d.y)), &rest())
}

fn v2(x: f32, z: f32) -> Vec2 {
    Vec2::new(x, z)
}

fn expect(id: &str, people: &[Motion], right: bool) {
    let v = judge(id, people).expect("known id");
    assert_eq!(v.right, right, "{id}: {}", v.reason);
    assert!(!v.reason.is_empty());
}

// ------------------------------------------------------------------ conventions

#[test]
fn rest_pose_faces_plus_z_with_left_plus_x() {
    let p = rest();
    assert!(facing_xz(&p).distance(v2(0.0, 1.0)) < 1e-5);
    assert!(left_xz(&p).distance(v2(1.0, 0.0)) < 1e-5);
    assert!(yaw_deg(facing_xz(&p)).abs() < 1e-4);
    assert!(body_front(&p).distance(Vec3::Z) < 1e-4);
    // A left turn (counter-clockwise from above) faces +X and raises the yaw.
    let l = place(&p, Vec2::ZERO, PI / 2.0);
    assert!(facing_xz(&l).distance(v2(1.0, 0.0)) < 1e-5);
    assert!((yaw_deg(facing_xz(&l)) - 90.0).abs() < 1e-3);
}

#[test]
fn yaw_track_unwraps_turns_both_ways() {
    let n = 80;
    let left: Vec<f32> = (0..n)
        .map(|i| PI * 1.5 * i as f32 / (n - 1) as f32)
        .collect();
    let m = along(&vec![Vec2::ZERO; n], &left, &rest());
    // Relative to the facing of the first five frames, so compare the change.
    let y = yaw_track(&m);
    assert!((y[n - 1] - y[0] - 270.0).abs() < 1.0, "{}", y[n - 1] - y[0]);
    let right: Vec<f32> = left.iter().map(|a| -a).collect();
    let y = yaw_track(&along(&vec![Vec2::ZERO; n], &right, &rest()));
    assert!((y[n - 1] - y[0] + 270.0).abs() < 1.0, "{}", y[n - 1] - y[0]);
}

#[test]
fn walking_speed_and_facing_are_measured() {
    let m = walk(&[v2(0.0, 0.0), v2(0.0, 20.0)], 1.3, 6.0);
    // Away from the ends, where the smoothing pads the path with its end values.
    let v = window_speeds(&m, 3..m.len() - 3);
    assert!(v.iter().all(|s| (s - 1.3).abs() < 0.01), "{v:?}");
    assert!(faces_travel(&m).0 > 0.99);
    // Backwards: facing +Z, going to −Z.
    let path = polyline(&[v2(0.0, 0.0), v2(0.0, -5.0)], 1.0, 100);
    let back = along(&path, &vec![0.0; 100], &rest());
    assert!(faces_travel(&back).0 < 0.01);
}

#[test]
fn episodes_and_runs_count_hysteresis() {
    let x = [0.0, 0.3, 0.1, 0.3, 0.0, 0.3, 0.3];
    assert_eq!(episodes(&x, 0.25, 0.05, true), vec![(1, 4), (5, 7)]);
    assert_eq!(
        runs(&[false, true, true, false, true]),
        vec![(1, 3), (4, 5)]
    );
    assert_eq!(longest_run(&[true, false, true, true, true]), 3);
    assert_eq!(smooth(&[0.0f32, 3.0, 0.0], 3), vec![1.0, 1.0, 1.0]);
}

// ------------------------------------------------------------------ the task list

#[derive(serde::Deserialize)]
struct TaskFile {
    task: Vec<TaskEntry>,
}

#[derive(serde::Deserialize)]
struct TaskEntry {
    id: String,
    sentence: String,
    people: usize,
    seconds: f32,
    program: String,
}

fn dir() -> std::path::PathBuf {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("bench/sentences")
}

#[test]
fn ids_match_the_task_file_and_every_program_exists() {
    let text = std::fs::read_to_string(dir().join("tasks.toml")).unwrap();
    let file: TaskFile = toml::from_str(&text).unwrap();
    let listed: Vec<&str> = file.task.iter().map(|t| t.id.as_str()).collect();
    assert_eq!(ids(), listed);
    assert!(listed.len() >= 25);
    for t in &file.task {
        assert_eq!(shape(&t.id), Some((t.people, t.seconds)), "{}", t.id);
        assert!((3.0..=9.8).contains(&t.seconds), "{}", t.id);
        let src = std::fs::read_to_string(dir().join(&t.program))
            .unwrap_or_else(|e| panic!("{}: {e}", t.program));
        // The program opens with its sentence.
        let first = src.lines().next().unwrap_or("");
        assert_eq!(first, format!("# {}", t.sentence), "{}", t.program);
        assert!(
            t.sentence.contains(&format!("{} seconds", t.seconds)),
            "{}",
            t.id
        );
    }
}

#[test]
fn unknown_ids_have_no_judge() {
    assert!(judge("s99", &[Motion::new(hold(&rest(), 5.0))]).is_none());
}

#[test]
fn every_judge_answers_on_standing_still_and_on_degenerate_motions() {
    for id in ids() {
        let (people, secs) = shape(id).unwrap();
        let still: Vec<Motion> = (0..people)
            .map(|i| Motion::new(hold(&place(&rest(), v2(0.0, 2.0 * i as f32), 0.0), secs)))
            .collect();
        assert!(judge(id, &still).is_some());
        // Every joint at one point: no facing, no lengths; the judge must still answer.
        let flat: Vec<Motion> = (0..people)
            .map(|i| {
                Motion::new(vec![
                    [Vec3::new(i as f32, 0.5, 0.0); 22];
                    (secs * 20.0) as usize
                ])
            })
            .collect();
        assert!(judge(id, &flat).is_some());
    }
}

#[test]
fn common_checks_catch_count_length_floor_and_overlap() {
    let m = Motion::new(hold(&rest(), 5.0));
    let v = judge("s01", &[m.clone(), m.clone()]).unwrap();
    assert!(!v.right && v.reason.contains("people"), "{}", v.reason);
    let v = judge("s01", &[Motion::new(hold(&rest(), 7.0))]).unwrap();
    assert!(!v.right && v.reason.contains("duration"), "{}", v.reason);
    let v = judge(
        "s01",
        &[Motion::new(hold(
            &shift(&rest(), Vec3::new(0.0, -0.2, 0.0)),
            5.0,
        ))],
    )
    .unwrap();
    assert!(!v.right && v.reason.contains("floor"), "{}", v.reason);
    let mut nan = hold(&rest(), 5.0);
    nan[3][HEAD].x = f32::NAN;
    assert!(!judge("s01", &[Motion::new(nan)]).unwrap().right);
    let a = Motion::new(hold(&rest(), 6.0));
    let b = Motion::new(hold(&place(&rest(), v2(0.1, 0.1), PI), 6.0));
    let v = judge("s23", &[a, b]).unwrap();
    assert!(!v.right && v.reason.contains("overlap"), "{}", v.reason);
}
