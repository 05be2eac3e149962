//! Tests of the whole BVH import on small hand-written inputs: FK against hand-computed
//! positions for several channel orders, text variants (CRLF, tabs, exponents), every
//! error case with its line number, and joint mapping of several rigs.

use super::*;
use glam::Vec3;

fn parse(text: &str) -> Result<Bvh, BvhError> {
    parse_bvh("t.bvh", text, ParseLimits::default())
}

/// Root (6 channels) → `Mid` (`mid_channels`, offset 0 10 0) → End Site (0 0 10).
fn chain(mid_channels: &str, frame: &str) -> String {
    format!(
        "HIERARCHY\nROOT Root\n{{\n  OFFSET 0 0 0\n  CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation\n  JOINT Mid\n  {{\n    OFFSET 0 10 0\n    CHANNELS {mid_channels}\n    End Site\n    {{\n      OFFSET 0 0 10\n    }}\n  }}\n}}\nMOTION\nFrames: 1\nFrame Time: 0.05\n{frame}\n"
    )
}

fn positions(text: &str) -> Vec<Vec3> {
    fk::global_positions(&parse(text).unwrap())
}

fn assert_close(a: Vec3, b: Vec3) {
    assert!((a - b).length() < 1e-4, "{a} != {b}");
}

#[test]
fn fk_rotation_orders_compose_intrinsically() {
    // Root at (1,2,3) turned 90° about Z: Mid's offset (0,10,0) goes to (-10,0,0).
    // Mid ZXY = (90, 90, 90) on (0,0,10): Ry → (10,0,0), Rx keeps it, Rz → (0,10,0);
    // then the root's Rz turns it to (-10,0,0).
    let p = positions(&chain(
        "3 Zrotation Xrotation Yrotation",
        "1 2 3 90 0 0 90 90 90",
    ));
    assert_close(p[0], Vec3::new(1.0, 2.0, 3.0));
    assert_close(p[1], Vec3::new(-9.0, 2.0, 3.0));
    assert_close(p[2], Vec3::new(-19.0, 2.0, 3.0));
    // XYZ = (90, 90, 90) on (0,0,10): Rz keeps it, Ry → (10,0,0), Rx keeps it.
    let p = positions(&chain(
        "3 Xrotation Yrotation Zrotation",
        "0 0 0 0 0 0 90 90 90",
    ));
    assert_close(p[2], Vec3::new(10.0, 10.0, 0.0));
    // ZX = (90, 90): Rx → (0,-10,0), Rz → (10,0,0).  XZ: Rz keeps it, Rx → (0,-10,0).
    let p = positions(&chain("2 Zrotation Xrotation", "0 0 0 0 0 0 90 90"));
    assert_close(p[2], Vec3::new(10.0, 10.0, 0.0));
    let p = positions(&chain("2 Xrotation Zrotation", "0 0 0 0 0 0 90 90"));
    assert_close(p[2], Vec3::new(0.0, 0.0, 0.0));
}

#[test]
fn fk_position_channels_replace_the_offset() {
    // Mid has a full 6-channel set: its position (5,0,0) replaces the offset (0,10,0).
    let text = chain(
        "6 Xposition Yposition Zposition Zrotation Xrotation Yrotation",
        "0 0 0 0 0 0 5 0 0 0 0 0",
    );
    let p = positions(&text);
    assert_close(p[1], Vec3::new(5.0, 0.0, 0.0));
    assert_close(p[2], Vec3::new(5.0, 0.0, 10.0));
    // Only Yposition: X and Z keep the offset's values.
    let p = positions(&chain("1 Yposition", "0 0 0 0 0 0 -4"));
    assert_close(p[1], Vec3::new(0.0, -4.0, 0.0));
}

#[test]
fn crlf_tabs_exponents_and_glued_braces() {
    let text = "HIERARCHY\r\nROOT\tRoot{\r\n\tOFFSET 0 0 0\r\n\tCHANNELS 3 Xposition Yposition Zposition \r\n\tEnd Site\r\n\t{\r\n\t\tOFFSET 1.87e-05 1E1 -0\r\n\t}\r\n}\r\nMOTION\r\nFrames:\t2\r\nFrame Time:\t0.0333333\r\n1e-3 2.5E+1 -3\r\n\t0 0 0 \r\n";
    let bvh = parse(text).unwrap();
    assert_eq!(bvh.frame_count, 2);
    assert_eq!(bvh.fps(), 30.0);
    assert_eq!(bvh.frame(0), [1e-3, 25.0, -3.0]);
    assert_close(bvh.joints[1].offset, Vec3::new(1.87e-5, 10.0, 0.0));
    let p = fk::global_positions(&bvh);
    assert_close(p[1], Vec3::new(1e-3 + 1.87e-5, 35.0, -3.0));
}

#[test]
fn joint_names_may_contain_spaces() {
    let text = "HIERARCHY\nROOT Left Hip Joint\n{\nOFFSET 0 0 0\nCHANNELS 1 Xrotation\n}\nMOTION\nFrames: 1\nFrame Time: 0.1\n0\n";
    assert_eq!(parse(text).unwrap().joints[0].name, "Left Hip Joint");
}

/// Parses `text` and returns the error's line and kind.
fn error_of(text: &str) -> (Option<usize>, BvhErrorKind) {
    let e = parse(text).unwrap_err();
    assert!(e.to_string().starts_with("t.bvh:"), "{e}");
    (e.line, e.kind)
}

#[test]
fn errors_name_the_line() {
    let good = chain("3 Zrotation Xrotation Yrotation", "0 0 0 0 0 0 0 0 0");
    let lines: Vec<&str> = good.lines().collect();
    let edit = |line: usize, new: &str| -> String {
        let mut l = lines.clone();
        l[line - 1] = new;
        l.join("\n")
    };
    use BvhErrorKind as K;
    // Missing CHANNELS line (line 9) on joint Mid (line 6).
    let (line, kind) = error_of(&edit(9, ""));
    assert_eq!((line, kind), (Some(6), K::MissingChannels("Mid".into())));
    // Fewer channel names than declared.
    let (line, kind) = error_of(&edit(9, "CHANNELS 3 Zrotation Xrotation"));
    assert_eq!(
        (line, kind),
        (
            Some(9),
            K::ChannelCount {
                declared: 3,
                found: 2
            }
        )
    );
    assert_eq!(
        error_of(&edit(9, "CHANNELS 2 Zrotation Wrotation")),
        (Some(9), K::UnknownChannel("Wrotation".into()))
    );
    assert_eq!(
        error_of(&edit(8, "OFFSET 0 ten 0")),
        (Some(8), K::BadNumber("ten".into()))
    );
    assert_eq!(
        error_of(&edit(8, "OFFSET 0 nan 0")),
        (Some(8), K::NonFinite("nan".into()))
    );
    assert_eq!(
        error_of(&edit(8, "")),
        (Some(6), K::MissingOffset("Mid".into()))
    );
    assert_eq!(
        error_of(&edit(10, "Bone Site")),
        (Some(10), K::UnknownKeyword("Bone".into()))
    );
    assert_eq!(
        error_of(&edit(1, "HIERARCHIE")),
        (Some(1), K::MissingHierarchy("HIERARCHIE".into()))
    );
    // Motion section.
    let (line, kind) = error_of(&edit(19, "0 0 0 0 0 0 0 0"));
    assert_eq!(
        (line, kind),
        (
            Some(19),
            K::ValueCount {
                found: 8,
                expected: 9
            }
        )
    );
    assert_eq!(
        error_of(&edit(19, "0 0 0 0 0 0 0 NaN 0")),
        (Some(19), K::NonFinite("NaN".into()))
    );
    assert_eq!(
        error_of(&edit(19, "0 0 0 0 0 0 0 inf 0")),
        (Some(19), K::NonFinite("inf".into()))
    );
    assert_eq!(error_of(&edit(17, "Frames: 0")), (Some(17), K::ZeroFrames));
    assert_eq!(
        error_of(&edit(17, "Frames: two")),
        (Some(17), K::BadFrameCount("two".into()))
    );
    assert_eq!(
        error_of(&edit(17, "Frame: 1")),
        (Some(17), K::MissingHeader("Frames"))
    );
    assert_eq!(
        error_of(&edit(18, "Frame Time: 0")),
        (Some(18), K::BadFrameTime("0".into()))
    );
    assert_eq!(
        error_of(&edit(17, "Frames: 3")),
        (
            Some(19),
            K::MissingFrames {
                found: 1,
                declared: 3
            }
        )
    );
    let extra = format!("{good}0 0 0 0 0 0 0 0 0\n");
    assert_eq!(error_of(&extra), (Some(20), K::ExtraFrames { declared: 1 }));
    let (line, kind) = error_of(&edit(17, "Frames: 100000000"));
    assert_eq!(line, Some(17));
    assert!(
        matches!(
            kind,
            K::TooBig {
                count: 900_000_000,
                ..
            }
        ),
        "{kind:?}"
    );
}

#[test]
fn truncated_files_are_errors() {
    let good = chain("3 Zrotation Xrotation Yrotation", "0 0 0 0 0 0 0 0 0");
    let lines: Vec<&str> = good.lines().collect();
    // Cut inside the hierarchy: after Mid's CHANNELS line (line 9).
    let (line, kind) = error_of(&lines[..9].join("\n"));
    assert_eq!(
        (line, kind),
        (Some(9), BvhErrorKind::UnclosedJoint("Mid".into()))
    );
    // Cut after the hierarchy.
    assert_eq!(
        error_of(&lines[..15].join("\n")),
        (Some(15), BvhErrorKind::MissingMotion)
    );
    // Cut inside the MOTION header.
    assert_eq!(
        error_of(&lines[..16].join("\n")),
        (Some(16), BvhErrorKind::MissingHeader("Frames"))
    );
    assert_eq!(
        error_of(&lines[..17].join("\n")),
        (Some(17), BvhErrorKind::MissingHeader("Frame Time"))
    );
    assert_eq!(
        error_of(""),
        (
            Some(1),
            BvhErrorKind::MissingHierarchy("end of file".into())
        )
    );
}

#[test]
fn binary_input_is_refused_through_the_entry_point() {
    let mut bytes = chain("1 Xrotation", "0 0 0 0 0 0 0").into_bytes();
    bytes.extend_from_slice(&[0, 159, 146, 150]);
    let e = import_bvh_bytes("b.bvh", &bytes, &BvhImportOptions::default()).unwrap_err();
    assert_eq!((e.line, e.kind), (Some(20), BvhErrorKind::Binary));
}

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
