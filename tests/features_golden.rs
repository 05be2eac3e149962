//! Golden tests of the HumanML3D features against clip 012314 of HumanML3D
//! (`tests/fixtures/humanml3d`), and round trips positions → features → positions.

mod common;

use common::{golden, max_joint_error, synthetic_walk};
use mprog::features::layout::{CONTACT, LOCAL_VEL, RIC, ROOT_VEL, ROOT_YAW_VEL, ROT};
use mprog::features::{
    ExtractOptions, FEATURE_DIM, Features, canonicalize, extract, recover_from_ric,
    uniform_skeleton,
};
use mprog::motion::Motion;

/// Largest and mean absolute difference of one block over the frames both arrays have.
fn block_error(a: &Features, b: &[f32], block: std::ops::Range<usize>) -> (f32, f32) {
    let (mut max, mut sum, mut count) = (0.0f32, 0.0f64, 0usize);
    for (t, row) in a.rows().enumerate() {
        for i in block.clone() {
            let e = (row[i] - b[t * FEATURE_DIM + i]).abs();
            max = max.max(e);
            sum += e as f64;
            count += 1;
        }
    }
    (max, (sum / count as f64) as f32)
}

#[test]
fn recover_reproduces_the_golden_joints() {
    let (feats, joints) = golden();
    let rec = recover_from_ric(&feats).unwrap();
    assert_eq!(rec.len(), 170);
    let err = max_joint_error(&rec, &joints);
    println!("golden recover_from_ric (f32 path): max error {err:.2e} m");
    assert!(err < 1e-4, "max error {err}");
}

#[test]
fn foot_contacts_are_reproduced_exactly() {
    let (feats, joints) = golden();
    let ours = extract(&joints, &ExtractOptions::default()).unwrap();
    assert_eq!(ours.frames(), 169);
    for (t, row) in ours.rows().enumerate() {
        assert_eq!(
            &row[CONTACT],
            &feats[t * FEATURE_DIM..][CONTACT],
            "frame {t}"
        );
    }
    // Not trivially all ones: the clip has both contact and swing phases.
    let ones = ours.rows().filter(|r| r[CONTACT.start] == 1.0).count();
    assert!(ones > 10 && ones < 160, "{ones} left-ankle contacts");
}

#[test]
fn root_and_body_blocks_match_the_golden_features() {
    let (feats, joints) = golden();
    let ours = extract(&joints, &ExtractOptions::default()).unwrap();
    let report = |name: &str, block: std::ops::Range<usize>, max_tol: f32, mean_tol: f32| {
        let (max, mean) = block_error(&ours, &feats, block);
        println!("{name:10} max {max:.2e} mean {mean:.2e}");
        assert!(
            max < max_tol && mean < mean_tol,
            "{name}: max {max} mean {mean}"
        );
    };
    // The golden features were extracted from the 171-frame source clip; ours from the
    // 170 recovered frames, so the smoothed facing differs slightly near the end.
    report("yaw", ROOT_YAW_VEL, 1e-3, 1e-4);
    report("root vel", ROOT_VEL, 5e-4, 3e-5);
    report("ric", RIC, 1e-2, 5e-4);
    report("rot 6d", ROT, 3e-2, 5e-4);
    report("local vel", LOCAL_VEL, 1e-3, 3e-5);
}

#[test]
fn golden_clip_round_trips_within_a_millimetre() {
    let (_, joints) = golden();
    let feats = extract(&joints, &ExtractOptions::default()).unwrap();
    let back = recover_from_ric(feats.as_slice()).unwrap();
    assert_eq!(back.len(), joints.len() - 1);
    let canon = canonicalize(&joints).unwrap();
    let err = max_joint_error(&back, &canon);
    println!("golden round trip: max error {err:.2e} m");
    assert!(err < 1e-3, "max error {err}");
    // The golden clip is already canonical, so it is also close to the input itself.
    assert!(max_joint_error(&back, &joints) < 1e-3);
}

#[test]
fn synthetic_walk_round_trips_within_a_millimetre() {
    let walk = synthetic_walk(120);
    let feats = extract(&walk, &ExtractOptions::default()).unwrap();
    let back = recover_from_ric(feats.as_slice()).unwrap();
    let err = max_joint_error(&back, &canonicalize(&walk).unwrap());
    println!("synthetic walk round trip: max error {err:.2e} m");
    assert!(err < 1e-3, "max error {err}");
    // It really walks: about 4.8 m in 120 frames.
    let dist = (back.frames[118][0] - back.frames[0][0]).length();
    assert!(dist > 4.0, "walked {dist} m");
}

#[test]
fn features_ignore_where_the_clip_starts_and_which_way_it_faces() {
    let walk = synthetic_walk(50);
    let turn = glam::Quat::from_rotation_y(-2.5);
    let shift = glam::Vec3::new(-4.0, 0.3, 7.5);
    let moved = Motion::new(
        walk.frames
            .iter()
            .map(|p| p.map(|v| turn * v + shift))
            .collect(),
    );
    let a = extract(&walk, &ExtractOptions::default()).unwrap();
    let b = extract(&moved, &ExtractOptions::default()).unwrap();
    let (max, _) = block_error(&a, b.as_slice(), 0..FEATURE_DIM);
    assert!(max < 1e-5, "max feature difference {max}");
}

#[test]
fn uniform_skeleton_option_retargets_a_larger_body() {
    let walk = synthetic_walk(60);
    let big = Motion::new(walk.frames.iter().map(|p| p.map(|v| v * 1.2)).collect());
    let opts = ExtractOptions {
        uniform_skeleton: true,
    };
    let feats = extract(&big, &opts).unwrap();
    // Retargeting undoes the scaling, so the features equal those of the original walk.
    let plain = extract(&walk, &ExtractOptions::default()).unwrap();
    let (max, _) = block_error(&feats, plain.as_slice(), 0..FEATURE_DIM);
    assert!(max < 1e-4, "max feature difference {max}");
    let back = recover_from_ric(feats.as_slice()).unwrap();
    let want = canonicalize(&uniform_skeleton(&big).unwrap()).unwrap();
    assert!(max_joint_error(&back, &want) < 1e-3);
}
