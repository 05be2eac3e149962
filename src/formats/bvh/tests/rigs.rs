//! Joint mapping of CMU, Mixamo, SMPL-style and Bandai-named rigs; fill-ins, unmappable
//! rigs, unit detection and overrides.

use super::super::*;
use super::assert_close;
use glam::Vec3;

/// A skeleton from `(name, parent, offset)` rows: root with 6 channels, others 3; an
/// End Site under every leaf; `frames` frames of zero rotation.
fn rig(joints: &[(&str, Option<usize>, [f32; 3])], frames: usize) -> String {
    fn write(out: &mut String, joints: &[(&str, Option<usize>, [f32; 3])], j: usize, depth: usize) {
        let pad = "  ".repeat(depth);
        let (name, parent, [x, y, z]) = joints[j];
        let keyword = if parent.is_none() { "ROOT" } else { "JOINT" };
        let channels = if parent.is_none() {
            "6 Xposition Yposition Zposition Zrotation Xrotation Yrotation"
        } else {
            "3 Zrotation Xrotation Yrotation"
        };
        out.push_str(&format!("{pad}{keyword} {name}\n{pad}{{\n{pad}  OFFSET {x} {y} {z}\n{pad}  CHANNELS {channels}\n"));
        let children: Vec<usize> = (0..joints.len())
            .filter(|&c| joints[c].1 == Some(j))
            .collect();
        if children.is_empty() {
            // End Sites point +Z, a tenth of the root height long.
            let end = joints[0].2[1] / 10.0;
            out.push_str(&format!(
                "{pad}  End Site\n{pad}  {{\n{pad}    OFFSET 0 0 {end}\n{pad}  }}\n"
            ));
        }
        for c in children {
            write(out, joints, c, depth + 1);
        }
        out.push_str(&format!("{pad}}}\n"));
    }
    let mut text = String::from("HIERARCHY\n");
    write(&mut text, joints, 0, 0);
    let channels = 3 + 3 * joints.len();
    let mut frame = vec!["0"; channels];
    let root_height = joints[0].2[1].to_string();
    frame[1] = &root_height;
    text.push_str(&format!(
        "MOTION\nFrames: {frames}\nFrame Time: 0.0333333\n"
    ));
    for _ in 0..frames {
        text.push_str(&frame.join(" "));
        text.push('\n');
    }
    text
}

/// A CMU-style (cgspeed) skeleton in centimetres, facing +Z, left = +X.
fn cmu_rig(prefix: &str) -> Vec<(String, Option<usize>, [f32; 3])> {
    let rows: [(&str, Option<usize>, [f32; 3]); 22] = [
        ("Hips", None, [0.0, 95.0, 0.0]),
        ("LeftUpLeg", Some(0), [9.0, -5.0, 0.0]),
        ("LeftLeg", Some(1), [0.0, -42.0, 0.0]),
        ("LeftFoot", Some(2), [0.0, -42.0, 0.0]),
        ("LeftToeBase", Some(3), [0.0, -5.0, 12.0]),
        ("RightUpLeg", Some(0), [-9.0, -5.0, 0.0]),
        ("RightLeg", Some(5), [0.0, -42.0, 0.0]),
        ("RightFoot", Some(6), [0.0, -42.0, 0.0]),
        ("RightToeBase", Some(7), [0.0, -5.0, 12.0]),
        ("LowerBack", Some(0), [0.0, 2.0, 0.0]),
        ("Spine", Some(9), [0.0, 12.0, 0.0]),
        ("Spine1", Some(10), [0.0, 14.0, 0.0]),
        ("Neck", Some(11), [0.0, 20.0, 0.0]),
        ("Head", Some(12), [0.0, 10.0, 0.0]),
        ("LeftShoulder", Some(11), [4.0, 15.0, 0.0]),
        ("LeftArm", Some(14), [14.0, 0.0, 0.0]),
        ("LeftForeArm", Some(15), [28.0, 0.0, 0.0]),
        ("LeftHand", Some(16), [26.0, 0.0, 0.0]),
        ("RightShoulder", Some(11), [-4.0, 15.0, 0.0]),
        ("RightArm", Some(18), [-14.0, 0.0, 0.0]),
        ("RightForeArm", Some(19), [-28.0, 0.0, 0.0]),
        ("RightHand", Some(20), [-26.0, 0.0, 0.0]),
    ];
    rows.iter()
        .map(|(n, p, o)| (format!("{prefix}{n}"), *p, *o))
        .collect()
}

fn import(text: &str) -> BvhImport {
    import_bvh_str("rig.bvh", text, &BvhImportOptions::default()).unwrap()
}

fn borrowed(rows: &[(String, Option<usize>, [f32; 3])]) -> Vec<(&str, Option<usize>, [f32; 3])> {
    rows.iter().map(|(n, p, o)| (n.as_str(), *p, *o)).collect()
}

#[test]
fn cmu_and_mixamo_names_map_and_units_are_detected() {
    for prefix in ["", "mixamorig:"] {
        let rows = cmu_rig(prefix);
        let out = import(&rig(&borrowed(&rows), 31));
        assert_eq!(out.joint_map.rig, "name-matched");
        let lines = out.joint_map_lines.join("\n");
        for expected in [
            "pelvis ← {p}Hips",
            "left_hip ← {p}LeftUpLeg",
            "right_knee ← {p}RightLeg",
            "left_ankle ← {p}LeftFoot",
            "left_foot ← {p}LeftToeBase",
            "spine1 ← {p}LowerBack",
            "spine2 ← {p}Spine",
            "spine3 ← {p}Spine1",
            "left_collar ← {p}LeftShoulder",
            "left_shoulder ← {p}LeftArm",
            "right_elbow ← {p}RightForeArm",
            "right_wrist ← {p}RightHand",
            "head ← {p}Head",
        ] {
            let expected = expected.replace("{p}", prefix);
            assert!(
                lines.contains(&expected),
                "missing `{expected}` in\n{lines}"
            );
        }
        assert!(out.units_detected);
        assert_eq!(out.unit_scale, 0.01);
        // 31 frames at 30 fps = 1 s → 21 frames at 20 fps.
        assert_eq!(
            (out.source_frames, out.motion.len(), out.motion.fps),
            (31, 21, 20.0)
        );
        let pose = out.motion.frames[0];
        assert_close(pose[0], Vec3::new(0.0, 0.95, 0.0));
        assert_close(pose[1], Vec3::new(0.09, 0.90, 0.0));
        assert_close(pose[20], Vec3::new(0.72, 1.38, 0.0));
        assert!(
            out.joint_map.unused.is_empty(),
            "{:?}",
            out.joint_map.unused
        );
    }
}

#[test]
fn smpl_names_and_missing_spine_and_toes_are_filled() {
    // SMPL names where `shoulder` is the arm joint; no spine2, no toes.
    let rows: Vec<(&str, Option<usize>, [f32; 3])> = vec![
        ("Pelvis", None, [0.0, 0.9, 0.0]),
        ("L_Hip", Some(0), [0.1, -0.05, 0.0]),
        ("L_Knee", Some(1), [0.0, -0.4, 0.0]),
        ("L_Ankle", Some(2), [0.0, -0.4, 0.0]),
        ("R_Hip", Some(0), [-0.1, -0.05, 0.0]),
        ("R_Knee", Some(4), [0.0, -0.4, 0.0]),
        ("R_Ankle", Some(5), [0.0, -0.4, 0.0]),
        ("Spine1", Some(0), [0.0, 0.1, 0.0]),
        ("Spine3", Some(7), [0.0, 0.2, 0.0]),
        ("Neck", Some(8), [0.0, 0.2, 0.0]),
        ("Head", Some(9), [0.0, 0.1, 0.0]),
        ("L_Collar", Some(8), [0.05, 0.1, 0.0]),
        ("L_Shoulder", Some(11), [0.1, 0.0, 0.0]),
        ("L_Elbow", Some(12), [0.25, 0.0, 0.0]),
        ("L_Wrist", Some(13), [0.25, 0.0, 0.0]),
        ("R_Collar", Some(8), [-0.05, 0.1, 0.0]),
        ("R_Shoulder", Some(15), [-0.1, 0.0, 0.0]),
        ("R_Elbow", Some(16), [-0.25, 0.0, 0.0]),
        ("R_Wrist", Some(17), [-0.25, 0.0, 0.0]),
    ];
    let out = import(&rig(&rows, 2));
    assert_eq!(out.unit_scale, 1.0);
    let lines = out.joint_map_lines.join("\n");
    assert!(lines.contains("left_shoulder ← L_Shoulder"), "{lines}");
    assert!(lines.contains("left_collar ← L_Collar"), "{lines}");
    assert!(lines.contains("left_foot ← L_Ankle End Site"), "{lines}");
    let pose = out.motion.frames[0];
    // spine2 lies between Spine1 (y 1.0) and Spine3 (y 1.2) at 0.714 of the way.
    let t = crate::skeleton::BONE_LENGTHS[6]
        / (crate::skeleton::BONE_LENGTHS[6] + crate::skeleton::BONE_LENGTHS[9]);
    assert_close(pose[6], Vec3::new(0.0, 1.0 + 0.2 * t, 0.0));
    assert_close(pose[10], Vec3::new(0.1, 0.05, 0.09));
    assert_eq!(out.warnings.len(), 2, "{:?}", out.warnings);
}

#[test]
fn unmappable_rig_lists_missing_joints() {
    let rows = [
        ("Base", None, [0.0, 0.0, 0.0]),
        ("Arm1", Some(0), [0.0, 1.0, 0.0]),
        ("Arm2", Some(1), [0.0, 1.0, 0.0]),
    ];
    let e = import_bvh_str("robot.bvh", &rig(&rows, 1), &BvhImportOptions::default()).unwrap_err();
    let BvhErrorKind::Unmapped { missing, available } = &e.kind else {
        panic!("{e}")
    };
    assert!(
        missing.contains(&"pelvis") && missing.contains(&"left_wrist"),
        "{missing:?}"
    );
    assert_eq!(available, "Base, Arm1, Arm2");
    assert!(e.to_string().starts_with("robot.bvh: cannot map"), "{e}");
}

#[test]
fn unit_override_and_z_up() {
    let rows = cmu_rig("");
    let text = rig(&borrowed(&rows), 1);
    let opts = BvhImportOptions {
        units: Units::Millimetres,
        up: UpAxis::Z,
        ..Default::default()
    };
    let out = import_bvh_str("z.bvh", &text, &opts).unwrap();
    assert!(!out.units_detected);
    assert_close(out.motion.frames[0][0], Vec3::new(0.0, 0.0, -0.095));
    assert!(
        out.warnings.iter().any(|w| w.contains("unusual body size")),
        "{:?}",
        out.warnings
    );
    let bad = BvhImportOptions {
        fps: 0.0,
        ..Default::default()
    };
    assert!(matches!(
        import_bvh_str("z.bvh", &text, &bad).unwrap_err().kind,
        BvhErrorKind::BadOption(_)
    ));
}

#[test]
fn bandai_named_fixture_uses_the_bandai_table() {
    // Hand-made, CRLF, tabs; joints named as in the Bandai-Namco dataset, centimetres.
    let text = include_str!("../../../../tests/fixtures/bandai_like.bvh");
    let out = import_bvh_str("bandai_like.bvh", text, &BvhImportOptions::default()).unwrap();
    assert_eq!(out.joint_map.rig, "bandai-namco");
    assert_eq!(out.joint_map.unused, ["joint_Root"]);
    assert_eq!(
        (out.unit_scale, out.source_fps, out.source_frames),
        (0.01, 30.0, 4)
    );
    assert_eq!(out.motion.len(), 3); // 0.1 s at 20 fps
    let p = out.motion.frames[0];
    assert_close(p[0], Vec3::new(0.0, 0.95, 0.0));
    assert_close(p[3], Vec3::new(0.0, 1.05, 0.0));
    assert_close(p[9], Vec3::new(0.0, 1.20, 0.0));
    // spine2 at HumanML3D's rest proportion between spine1 and spine3.
    let t = crate::skeleton::BONE_LENGTHS[6]
        / (crate::skeleton::BONE_LENGTHS[6] + crate::skeleton::BONE_LENGTHS[9]);
    assert_close(p[6], Vec3::new(0.0, 1.05 + 0.15 * t, 0.0));
    assert_close(p[1], Vec3::new(0.09, 0.90, 0.0));
    // Left leg turned −10° about X: (0,−88,12) cm hip→toe becomes
    // (0, −88 cos10° + 12 sin10°, 88 sin10° + 12 cos10°) = (0, −84.58, 27.10).
    assert_close(p[10], Vec3::new(0.09, 0.0542, 0.2710));
    // Output frame 1 is source frame 1.5: the pelvis has moved 6 cm forward.
    assert_close(out.motion.frames[1][0], Vec3::new(0.0, 0.95, 0.06));
}
