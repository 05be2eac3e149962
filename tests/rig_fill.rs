//! The DeepMimic fill policy measured: a real 22-joint clip (HumanML3D's golden clip
//! 012314, shipped under `tests/fixtures/`, MIT) reduced to the joints a DeepMimic file has
//! (root on the line between the hips, chest = spine2, neck, hips, knees, ankles,
//! shoulders, elbows; wrists and toes as End Sites), then filled back by the `deepmimic`
//! rig table. Prints the error of every
//! filled joint next to the generic fill the importer falls back on (spine at HumanML3D's
//! rest proportions pelvis → neck, collars halfway spine3 → shoulder), and what the fill
//! does to every joint once both clips are retargeted to HumanML3D's skeleton (what
//! training sees). Fails if the table's fill is more than 5 mm worse than the generic one,
//! off by more than 6 cm on average, or moves the retargeted joints by more than 5 cm.

use glam::Vec3;
use mprog::features::uniform_skeleton;
use mprog::formats::bvh::parse::{BvhJoint, Channel};
use mprog::formats::bvh::{Bvh, retarget::map_joints};
use mprog::formats::{LoadedMotion, read_motion};
use mprog::motion::{Motion, Pose};
use std::path::PathBuf;

/// DeepMimic joint names and the HumanML3D joint each stands for in the reduction
/// (End Sites: `None` name, parent index).
const REDUCED: [(&str, Option<usize>, usize); 16] = [
    ("root", None, 0),
    ("chest", Some(0), 6),
    ("neck", Some(1), 12),
    ("right_shoulder", Some(1), 17),
    ("right_elbow", Some(3), 19),
    ("", Some(4), 21),
    ("left_shoulder", Some(1), 16),
    ("left_elbow", Some(6), 18),
    ("", Some(7), 20),
    ("right_hip", Some(0), 2),
    ("right_knee", Some(9), 5),
    ("right_ankle", Some(10), 8),
    ("", Some(11), 11),
    ("left_hip", Some(0), 1),
    ("left_knee", Some(13), 4),
    ("left_ankle", Some(14), 7),
];

fn skeleton() -> Bvh {
    let mut joints: Vec<BvhJoint> = REDUCED
        .iter()
        .enumerate()
        .map(|(i, (name, parent, _))| BvhJoint {
            name: name.to_string(),
            parent: *parent,
            offset: Vec3::Y,
            channels: vec![],
            first_channel: 0,
            end_site: name.is_empty(),
            line: i + 1,
        })
        .collect();
    joints[0].channels = vec![Channel::Rotation(mprog::formats::bvh::parse::Axis::X)];
    // The left ankle's End Site (toe), and the neck's (head).
    joints.push(BvhJoint {
        name: String::new(),
        parent: Some(15),
        offset: Vec3::Z,
        channels: vec![],
        first_channel: 0,
        end_site: true,
        line: 17,
    });
    joints.push(BvhJoint {
        name: String::new(),
        parent: Some(2),
        offset: Vec3::Y,
        channels: vec![],
        first_channel: 0,
        end_site: true,
        line: 18,
    });
    Bvh {
        joints,
        channel_count: 1,
        frame_time: 0.05,
        frame_count: 1,
        values: vec![0.0],
    }
}

fn golden() -> Vec<Pose> {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("tests/fixtures/humanml3d/new_joints_012314.npy");
    match read_motion(&path).unwrap() {
        LoadedMotion::Joints { people, .. } => people[0].motion.frames.clone(),
        other => panic!("expected joints, got {other:?}"),
    }
}

/// Generic fill: the root as the pelvis, spine at rest proportions between it and the neck, collars halfway
/// spine3 → shoulder.
fn generic(p: &Pose, j: usize) -> Vec3 {
    // The importer's fallback takes the root as the pelvis.
    let root = p[1].lerp(p[2], 0.5);
    let spine = |t: f32| root.lerp(p[12], t);
    // Cumulative rest lengths pelvis–spine1–spine2–spine3–neck (skeleton::BONE_LENGTHS).
    let s1 = 0.13157;
    let s3 = s1 + 0.14319 + 0.05736;
    let neck = s3 + 0.21936;
    match j {
        0 => root,
        3 => spine(s1 / neck),
        9 => spine(s3 / neck),
        13 => spine(s3 / neck).lerp(p[16], 0.5),
        _ => spine(s3 / neck).lerp(p[17], 0.5),
    }
}

#[test]
fn deepmimic_fill_against_a_real_22_joint_clip() {
    let bvh = skeleton();
    let map = map_joints(&bvh).unwrap();
    assert_eq!(map.rig, "deepmimic");
    let frames = golden();
    let filled = [0usize, 3, 9, 13, 14];
    let mut table_err = [0.0f32; 5];
    let mut filled_clip = Vec::new();
    let mut generic_err = [0.0f32; 5];
    for truth in &frames {
        let mut globals: Vec<Vec3> = REDUCED.iter().map(|(_, _, h)| truth[*h]).collect();
        // DeepMimic's root lies on the line between the hips.
        globals[0] = truth[1].lerp(truth[2], 0.5);
        globals.push(truth[10]);
        // The neck's End Site sits so that the table's head (0.36 of the way) is the head.
        globals.push(truth[12] + (truth[15] - truth[12]) / 0.36);
        let pose = map.pose(&globals);
        filled_clip.push(pose);
        for (k, &j) in filled.iter().enumerate() {
            table_err[k] += pose[j].distance(truth[j]);
            generic_err[k] += generic(truth, j).distance(truth[j]);
        }
    }
    let n = frames.len() as f32;
    println!(
        "joint        deepmimic table  generic fill   (mean error, m, {} frames)",
        frames.len()
    );
    for (k, &j) in filled.iter().enumerate() {
        println!(
            "{:12} {:>15.3} {:>13.3}",
            mprog::skeleton::JOINT_NAMES[j],
            table_err[k] / n,
            generic_err[k] / n
        );
    }
    let table: f32 = table_err.iter().sum::<f32>() / (5.0 * n);
    let generic: f32 = generic_err.iter().sum::<f32>() / (5.0 * n);
    println!("all filled   {table:>15.3} {generic:>13.3}");
    // What training sees: both clips on HumanML3D's skeleton, compared joint by joint.
    let retarget = |frames: Vec<Pose>| {
        uniform_skeleton(&Motion { frames, fps: 20.0 })
            .unwrap()
            .frames
    };
    let (a, b) = (retarget(frames.clone()), retarget(filled_clip));
    let mut per_joint = [0.0f32; 22];
    for (pa, pb) in a.iter().zip(&b) {
        for j in 0..22 {
            per_joint[j] += pa[j].distance(pb[j]) / n;
        }
    }
    let mean_all = per_joint.iter().sum::<f32>() / 22.0;
    println!(
        "after retargeting: mean over the 22 joints {mean_all:.3} m; head {:.3}, wrists {:.3} {:.3}, shoulders {:.3} {:.3}",
        per_joint[15], per_joint[20], per_joint[21], per_joint[16], per_joint[17]
    );
    assert!(
        table <= generic + 0.005,
        "table fill {table} worse than generic {generic}"
    );
    assert!(table < 0.06, "table fill off by {table} m on average");
    assert!(
        mean_all < 0.05,
        "retargeted joints move by {mean_all} m on average"
    );
}
