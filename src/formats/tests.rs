//! Tests of `.npy` and `.json` reading and writing and of the extension dispatch:
//! round trips, every dtype/order variant built byte by byte, and each error case.

use super::json::{JsonError, read_json_str};
use super::npy::{NpyError, read_npy_bytes};
use super::*;
use crate::motion::{Motion, Pose};
use crate::skeleton::{NUM_JOINTS, rest_pose};
use glam::Vec3;
use std::path::PathBuf;

/// A short motion whose every coordinate differs.
fn sample_motion(frames: usize, shift: f32) -> Motion {
    let poses: Vec<Pose> = (0..frames)
        .map(|f| {
            let rest = rest_pose();
            std::array::from_fn(|j| {
                rest[j] + Vec3::new(f as f32 * 0.1 + shift, j as f32 * 0.01, -(f as f32))
            })
        })
        .collect();
    Motion::new(poses)
}

/// A version 1.0 `.npy` file: magic, header dict padded to 64 bytes, payload.
fn npy_bytes(descr: &str, fortran: bool, shape: &[usize], payload: &[u8]) -> Vec<u8> {
    let shape_text = match shape {
        [one] => format!("({one},)"),
        dims => format!(
            "({})",
            dims.iter()
                .map(|d| d.to_string())
                .collect::<Vec<_>>()
                .join(", ")
        ),
    };
    let mut dict = format!(
        "{{'descr': '{descr}', 'fortran_order': {}, 'shape': {shape_text}, }}",
        if fortran { "True" } else { "False" }
    );
    while (10 + dict.len() + 1) % 64 != 0 {
        dict.push(' ');
    }
    dict.push('\n');
    let mut out = b"\x93NUMPY\x01\x00".to_vec();
    out.extend_from_slice(&(dict.len() as u16).to_le_bytes());
    out.extend_from_slice(dict.as_bytes());
    out.extend_from_slice(payload);
    out
}

#[test]
fn npy_round_trip_one_and_two_people() {
    let dir = tempfile::tempdir().unwrap();
    let one = dir.path().join("one.npy");
    let m = sample_motion(5, 0.0);
    write_motion(&one, std::slice::from_ref(&m), &Meta::new()).unwrap();
    let array = npy::read_npy(&one).unwrap();
    assert_eq!(array.shape, [5, NUM_JOINTS, 3]);
    let LoadedMotion::Joints { people, .. } = read_motion(&one).unwrap() else {
        panic!("joints expected")
    };
    assert_eq!(people[0].motion, m);

    let two = dir.path().join("two.NPY");
    let m2 = sample_motion(5, 3.0);
    write_motion(&two, &[m.clone(), m2.clone()], &Meta::new()).unwrap();
    assert_eq!(npy::read_npy(&two).unwrap().shape, [2, 5, NUM_JOINTS, 3]);
    let LoadedMotion::Joints { people, .. } = read_motion(&two).unwrap() else {
        panic!("joints expected")
    };
    assert_eq!(
        (people[0].motion.clone(), people[1].motion.clone()),
        (m, m2)
    );
    let ragged = write_motion(
        &two,
        &[sample_motion(5, 0.0), sample_motion(4, 0.0)],
        &Meta::new(),
    );
    let e = ragged.unwrap_err().to_string();
    assert!(e.contains("different lengths [5, 4]"), "{e}");
}

#[test]
fn npy_float64_big_endian_and_fortran_order() {
    // Shape [1, 22, 3], value = flat C index.
    let shape = [1, NUM_JOINTS, 3];
    let c_values: Vec<f64> = (0..66).map(f64::from).collect();
    let be: Vec<u8> = c_values.iter().flat_map(|v| v.to_be_bytes()).collect();
    let a = read_npy_bytes("be.npy", &npy_bytes(">f8", false, &shape, &be)).unwrap();
    assert_eq!(
        a.data,
        c_values.iter().map(|&v| v as f32).collect::<Vec<_>>()
    );
    // Fortran order: element (0, j, k) stored at j + 22 k.
    let mut f_values = vec![0f32; 66];
    for j in 0..NUM_JOINTS {
        for k in 0..3 {
            f_values[j + NUM_JOINTS * k] = (3 * j + k) as f32;
        }
    }
    let le: Vec<u8> = f_values.iter().flat_map(|v| v.to_le_bytes()).collect();
    let a = read_npy_bytes("f.npy", &npy_bytes("<f4", true, &shape, &le)).unwrap();
    assert_eq!(a.data, (0..66).map(|v| v as f32).collect::<Vec<_>>());
}

#[test]
fn npy_errors_are_specific() {
    let zeros = |n: usize, size: usize| vec![0u8; n * size];
    let e = read_npy_bytes(
        "i.npy",
        &npy_bytes("<i4", false, &[2, 22, 3], &zeros(132, 4)),
    )
    .unwrap_err();
    assert!(
        matches!(e, NpyError::DType { .. }) && e.to_string().contains("<i4"),
        "{e}"
    );
    let e = read_npy_bytes(
        "t.npy",
        &npy_bytes("<f4", false, &[2, 22, 3], &zeros(131, 4)),
    )
    .unwrap_err();
    assert!(
        matches!(
            e,
            NpyError::Truncated {
                needed: 528,
                found: 524,
                ..
            }
        ),
        "{e}"
    );
    let e = read_npy_bytes("h.npy", b"\x93NUMPY\x01\x00garbage").unwrap_err();
    assert!(matches!(e, NpyError::Header { .. }), "{e}");
    let mut values = vec![0f32; 66];
    values[3 * 5 + 1] = f32::NAN;
    let bytes: Vec<u8> = values.iter().flat_map(|v| v.to_le_bytes()).collect();
    let e = read_npy_bytes("n.npy", &npy_bytes("<f4", false, &[1, 22, 3], &bytes)).unwrap_err();
    assert!(
        matches!(&e, NpyError::NonFinite { index, .. } if index == &[0, 5, 1]),
        "{e}"
    );
    let a = read_npy_bytes(
        "s.npy",
        &npy_bytes("<f4", false, &[2, 21, 3], &zeros(126, 4)),
    )
    .unwrap();
    let e = npy::classify("s.npy", a).unwrap_err();
    assert!(e.to_string().contains("[2, 21, 3]"), "{e}");
    let a = read_npy_bytes(
        "f.npy",
        &npy_bytes("<f4", false, &[4, 263], &zeros(4 * 263, 4)),
    )
    .unwrap();
    assert!(
        matches!(npy::classify("f.npy", a), Ok(MotionFile::Features(NpyArray { ref shape, .. })) if shape == &[4, 263])
    );
}

fn shared_dir() -> Option<PathBuf> {
    let dir = std::env::var_os("MPROG_SHARED")
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../shared"));
    let golden = dir.join("reference/humanml3d");
    if golden.is_dir() {
        Some(golden)
    } else {
        eprintln!(
            "SKIPPED: no HumanML3D golden files at {} (set MPROG_SHARED)",
            golden.display()
        );
        None
    }
}

#[test]
fn humanml3d_golden_files_read_as_joints_and_features() {
    let Some(dir) = shared_dir() else { return };
    let LoadedMotion::Joints { people, .. } =
        read_motion(&dir.join("new_joints_012314.npy")).unwrap()
    else {
        panic!("new_joints should read as joints")
    };
    let m = &people[0].motion;
    assert!(m.len() > 10 && m.is_finite());
    // HumanML3D clips stand on the floor with the pelvis near 0.8–1.0 m.
    let (lo, _) = m.bounds();
    assert!(
        lo.y.abs() < 0.05 && (0.6..1.2).contains(&m.frames[0][0].y),
        "{lo} {}",
        m.frames[0][0]
    );
    let LoadedMotion::Features(f) = read_motion(&dir.join("new_joint_vecs_012314.npy")).unwrap()
    else {
        panic!("new_joint_vecs should read as features")
    };
    // HumanML3D saves new_joints recovered from the features: one joint frame per row.
    assert_eq!(f.shape, [m.len(), 263]);
}

#[test]
fn json_round_trip_keeps_meta_and_motion() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("out.json");
    let mut meta = Meta::new();
    meta.insert("seed".into(), 7.into());
    meta.insert("program".into(), "keep left_hand above head".into());
    let motions = [sample_motion(3, 0.0), sample_motion(3, 1.0)];
    write_motion(&path, &motions, &meta).unwrap();
    let text = std::fs::read_to_string(&path).unwrap();
    assert!(
        text.starts_with("{\"format\":\"mprog-motion\",\"version\":1"),
        "{text:.80}"
    );
    let LoadedMotion::Joints { people, meta: back } = read_motion(&path).unwrap() else {
        panic!()
    };
    assert_eq!(back, meta);
    assert_eq!(people[1].name, "person 2");
    assert_eq!(
        people.iter().map(|p| p.motion.clone()).collect::<Vec<_>>(),
        motions
    );
}

/// A valid one-person document with two frames, as a JSON value to edit.
fn document() -> serde_json::Value {
    let doc = json::MotionDocument::new(
        &[Person {
            name: "a".into(),
            motion: sample_motion(2, 0.0),
        }],
        Meta::new(),
    );
    serde_json::to_value(doc).unwrap()
}

fn json_error(doc: &serde_json::Value) -> String {
    read_json_str("d.json", &doc.to_string())
        .unwrap_err()
        .to_string()
}

#[test]
fn json_validation_errors_say_what_is_wrong() {
    let mut d = document();
    d["people"][0]["frames"][1].as_array_mut().unwrap().pop();
    assert_eq!(
        json_error(&d),
        "d.json: person 0 (\"a\") frame 1 has 21 joints, expected 22"
    );
    let mut d = document();
    d["format"] = "other".into();
    assert!(json_error(&d).contains("`format` is \"other\""));
    let mut d = document();
    d["version"] = 2.into();
    assert!(json_error(&d).contains("version 2 is not supported"));
    let mut d = document();
    d["joint_names"][0] = "hips".into();
    assert!(json_error(&d).contains("joint_names"));
    let mut d = document();
    d["fps"] = 0.into();
    assert!(json_error(&d).contains("`fps` must be positive"));
    let mut d = document();
    d["units"] = "ft".into();
    assert!(json_error(&d).contains("`units` is \"ft\""));
    let e = read_json_str(
        "d.json",
        "{\n  \"format\": \"mprog-motion\",\n  \"version\": 1,\n}",
    )
    .unwrap_err();
    assert!(matches!(e, JsonError::Syntax { line: 4, .. }), "{e}");
    assert!(e.to_string().starts_with("d.json:4:"), "{e}");
}

#[test]
fn json_centimetres_and_other_rates_are_converted() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("cm.json");
    let mut d = document();
    d["units"] = "cm".into();
    d["fps"] = 10.into();
    std::fs::write(&path, d.to_string()).unwrap();
    let LoadedMotion::Joints { people, .. } = read_motion(&path).unwrap() else {
        panic!()
    };
    let m = &people[0].motion;
    // Two frames at 10 fps span 0.1 s: three frames at 20 fps, the middle one halfway.
    assert_eq!((m.len(), m.fps), (3, 20.0));
    let original = sample_motion(2, 0.0);
    let expected = original.frames[0][4].lerp(original.frames[1][4], 0.5) * 0.01;
    assert!((m.frames[1][4] - expected).length() < 1e-6);
}

#[test]
fn dispatch_refuses_unknown_extensions_and_several_people_in_bvh() {
    let dir = tempfile::tempdir().unwrap();
    let m = [sample_motion(2, 0.0)];
    let pose = crate::skeleton::rest_pose();
    let standing = Motion::new(vec![pose; 3]);
    write_motion(
        &dir.path().join("one.bvh"),
        std::slice::from_ref(&standing),
        &Meta::new(),
    )
    .unwrap();
    assert!(
        std::fs::read_to_string(dir.path().join("one.bvh"))
            .unwrap()
            .starts_with("HIERARCHY")
    );
    let e = write_motion(
        &dir.path().join("x.bvh"),
        &[standing.clone(), standing],
        &Meta::new(),
    )
    .unwrap_err();
    assert!(
        e.to_string()
            .contains("one skeleton but there are 2 people"),
        "{e}"
    );
    let e = write_motion(&dir.path().join("x.csv"), &m, &Meta::new()).unwrap_err();
    assert!(e.to_string().contains("cannot write `.csv`"), "{e}");
    let e = read_motion(&dir.path().join("x.fbx")).unwrap_err();
    assert!(e.to_string().contains("cannot read `.fbx`"), "{e}");
    let e = read_motion(&dir.path().join("missing.npy")).unwrap_err();
    assert!(e.to_string().contains("missing.npy: cannot read"), "{e}");
    assert!(!dir.path().join("x.bvh").exists());
}

/// mprog reads its own BVH back: the header comment is skipped, the joints map by their
/// HumanML3D names (not through the zero-offset connectors), positions within 1 mm.
#[test]
fn own_bvh_export_reads_back_through_read_motion() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("walk.bvh");
    let walk = crate::render::test_motion::walk(30, 1.2, Vec3::new(0.5, 0.0, -1.0), Vec3::X);
    write_motion(&path, std::slice::from_ref(&walk), &Meta::new()).unwrap();
    let LoadedMotion::Joints { people, meta } = read_motion(&path).unwrap() else {
        panic!("joints expected")
    };
    assert_eq!(meta["rig"], "humanml3d");
    assert_eq!(meta["warnings"], serde_json::json!([]));
    let back = &people[0].motion;
    assert_eq!(back.len(), walk.len());
    for (f, (a, b)) in back.frames.iter().zip(&walk.frames).enumerate() {
        for j in 0..NUM_JOINTS {
            let err = (a[j] - b[j]).length();
            assert!(err < 1e-3, "frame {f} joint {j}: {err} m");
        }
    }
}

#[test]
fn bvh_through_read_motion_reports_the_import() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("walk.bvh");
    std::fs::write(&path, include_str!("../../tests/fixtures/bandai_like.bvh")).unwrap();
    let LoadedMotion::Joints { people, meta } = read_motion(&path).unwrap() else {
        panic!()
    };
    assert_eq!(people[0].name, "walk");
    assert_eq!(meta["rig"], "bandai-namco");
    assert_eq!(meta["unit_scale"], 0.01f32);
    assert_eq!(people[0].motion.fps, 20.0);
}

#[test]
fn pictures_draw_the_meta_timeline_and_refuse_a_broken_one() {
    use super::outputs::OutputJob;
    let people = [sample_motion(60, 0.0)];
    let bvh = super::bvh_export::BvhExportOptions::default();
    let picture = |meta: serde_json::Value| {
        let meta = meta.as_object().unwrap().clone();
        let job = OutputJob {
            people: &people,
            meta: &meta,
            title: "t",
            bvh: &bvh,
            rig: None,
        };
        (
            super::writers::png("t.png", &job),
            super::writers::gif("t.gif", &job),
        )
    };
    let (plain, plain_gif) = picture(serde_json::json!({}));
    let timeline = serde_json::json!({"timeline": [[
        {"from": 0, "to": 30, "prompt": "a person walks forward"},
        {"from": 30, "to": 60, "prompt": "a person sits down"}
    ]]});
    let (with, with_gif) = picture(timeline);
    assert_ne!(plain.unwrap(), with.unwrap());
    assert_ne!(plain_gif.unwrap(), with_gif.unwrap());
    let (bad, _) =
        picture(serde_json::json!({"timeline": [[{"from": 70, "to": 80, "prompt": "x"}]]}));
    let e = bad.unwrap_err();
    assert!(
        e.contains("t.png: meta.timeline[0]: span 70..80 starts past"),
        "{e}"
    );
}
