//! Motions on a skinned glTF character (`--rig character.glb`): the HumanML3D golden clip put
//! on `tests/fixtures/rigs/mixamo_tall.glb` (the BVH rig `mixamo_tall.bvh` made into a
//! character by Blender 3.4, `scripts/blender_make_glb_rig.py`: `mixamorig:` names, bone rest
//! rotations, a box per bone skinned to it). The output is the user's file with its mesh and
//! skin, animated; evaluated by forward kinematics its joints are where the BVH rig's are;
//! an armature scaled 0.01, a joint written as a matrix and a second person give the same;
//! hostile files are errors, never panics.
//!
//! With Blender: `cargo test --test retarget_glb -- --ignored blender --nocapture`.

mod common;

use glam::DVec3;
use mprog::formats::bvh::{BvhImportOptions, import_bvh};
use mprog::formats::character::Character;
use mprog::formats::gltf::read::{chunks, node_positions_at};
use mprog::motion::Motion;
use serde_json::{Value, json};
use std::path::{Path, PathBuf};
use std::process::Command;

/// The HumanML3D names of the 22 joints on the Mixamo rig, in HumanML3D order.
const MIXAMO: [&str; 22] = [
    "Hips",
    "LeftUpLeg",
    "RightUpLeg",
    "Spine",
    "LeftLeg",
    "RightLeg",
    "Spine1",
    "LeftFoot",
    "RightFoot",
    "Spine2",
    "LeftToeBase",
    "RightToeBase",
    "Neck",
    "LeftShoulder",
    "RightShoulder",
    "Head",
    "LeftArm",
    "RightArm",
    "LeftForeArm",
    "RightForeArm",
    "LeftHand",
    "RightHand",
];

fn fixture(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/fixtures/rigs")
        .join(name)
}

fn glb_bytes() -> Vec<u8> {
    std::fs::read(fixture("mixamo_tall.glb")).unwrap()
}

/// `mprog convert input --rig rig -o outputs…`, asserting success.
fn convert_onto(input: &Path, rig: &Path, outputs: &[&Path]) {
    let out = Command::new(env!("CARGO_BIN_EXE_mprog"))
        .arg("convert")
        .arg(input)
        .arg("--rig")
        .arg(rig)
        .arg("-o")
        .args(outputs)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

/// The `.glb` of (JSON, binary chunk).
fn glb_of(json: &Value, bin: &[u8]) -> Vec<u8> {
    let mut text = serde_json::to_vec(json).unwrap();
    while !text.len().is_multiple_of(4) {
        text.push(b' ');
    }
    let mut bin = bin.to_vec();
    while !bin.len().is_multiple_of(4) {
        bin.push(0);
    }
    let total = 12 + 8 + text.len() + 8 + bin.len();
    let mut out = Vec::new();
    for w in [
        0x4654_6C67u32,
        2,
        total as u32,
        text.len() as u32,
        0x4E4F_534A,
    ] {
        out.extend(w.to_le_bytes());
    }
    out.extend(&text);
    out.extend((bin.len() as u32).to_le_bytes());
    out.extend(0x004E_4942u32.to_le_bytes());
    out.extend(bin);
    out
}

/// The JSON and binary chunk of a `.glb`.
fn split(bytes: &[u8]) -> (Value, Vec<u8>) {
    let (json, bin) = chunks(bytes).unwrap();
    (
        serde_json::from_slice(json).unwrap(),
        bin.unwrap_or_default().to_vec(),
    )
}

/// World position of the 22 mapped joints (`prefix` + Mixamo name) at every key.
fn joints_of(glb: &[u8], prefix: &str, frames: usize) -> Vec<[DVec3; 22]> {
    (0..frames)
        .map(|f| {
            let nodes = node_positions_at(glb, f).unwrap();
            MIXAMO.map(|m| {
                let want = format!("{prefix}{m}");
                nodes
                    .iter()
                    .find(|(n, _)| *n == want)
                    .unwrap_or_else(|| panic!("no node {want}"))
                    .1
            })
        })
        .collect()
}

/// Largest distance between two joint tracks.
fn largest_gap(a: &[[DVec3; 22]], b: &[[DVec3; 22]]) -> f64 {
    assert_eq!(a.len(), b.len());
    a.iter()
        .zip(b)
        .flat_map(|(x, y)| x.iter().zip(y).map(|(p, q)| p.distance(*q)))
        .fold(0.0, f64::max)
}

/// The golden clip on the BVH rig and on the `.glb` rig (`glb` bytes): the BVH output read
/// back by mprog, as tracks of the 22 joints, and the `.glb` output's bytes.
fn both(glb: &[u8], people: usize) -> (Vec<[DVec3; 22]>, Vec<u8>) {
    let (_, clip) = common::golden();
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("clip.npy");
    let motions: Vec<Motion> = (0..people)
        .map(|k| {
            let mut m = clip.clone();
            for p in &mut m.frames {
                for j in p.iter_mut() {
                    j.x += k as f32;
                }
            }
            m
        })
        .collect();
    mprog::formats::npy::write_joints_npy(&input, &motions[..1]).unwrap();
    let bvh = dir.path().join("rig.bvh");
    convert_onto(&input, &fixture("mixamo_tall.bvh"), &[&bvh]);
    let read = import_bvh(&bvh, &BvhImportOptions::default()).unwrap();
    let expected = read
        .motion
        .frames
        .iter()
        .map(|p| std::array::from_fn(|j| p[j].as_dvec3()))
        .collect();
    mprog::formats::npy::write_joints_npy(&input, &motions).unwrap();
    let rig = dir.path().join("rig.glb");
    std::fs::write(&rig, glb).unwrap();
    let out = dir.path().join("out.glb");
    convert_onto(&input, &rig, &[&out]);
    (expected, std::fs::read(&out).unwrap())
}

#[test]
fn a_glb_rig_reads_as_its_bvh() {
    let from_glb = Character::from_glb("tall.glb", &glb_bytes(), None).unwrap();
    let bvh = std::fs::read_to_string(fixture("mixamo_tall.bvh")).unwrap();
    let from_bvh = Character::from_text(("tall.bvh", &bvh), None).unwrap();
    assert_eq!(from_glb.units, "m");
    assert!((from_glb.leg - from_bvh.leg).abs() < 1e-5);
    for (j, mixamo) in MIXAMO.iter().enumerate() {
        let (g, b) = (from_glb.map[j].unwrap(), from_bvh.map[j].unwrap());
        assert_eq!(from_glb.joints[g].name, format!("mixamorig:{mixamo}"));
        assert!(
            from_glb.rest[g].distance(from_bvh.rest[b]) < 1e-5,
            "{mixamo}"
        );
    }
    assert!(from_glb.summary().contains(".glb outputs are this file"));
}

#[test]
fn the_glb_output_is_the_rig_file_animated() {
    let glb = glb_bytes();
    let (expected, out) = both(&glb, 1);
    let (json_in, bin_in) = split(&glb);
    let (json_out, bin_out) = split(&out);
    // The user's file is all there: nodes, mesh, skin, materials, and its data unchanged.
    for key in ["meshes", "skins", "materials"] {
        assert_eq!(json_out[key], json_in[key], "{key}");
    }
    assert_eq!(
        json_out["nodes"].as_array().unwrap().len(),
        json_in["nodes"].as_array().unwrap().len()
    );
    assert_eq!(&bin_out[..bin_in.len()], &bin_in[..]);
    let anim = &json_out["animations"][0];
    assert_eq!(anim["name"], "mprog");
    // A rotation track per joint of the skin, one translation track (the hips).
    let joints = json_in["skins"][0]["joints"].as_array().unwrap().len();
    let paths: Vec<&str> = anim["channels"]
        .as_array()
        .unwrap()
        .iter()
        .map(|c| c["target"]["path"].as_str().unwrap())
        .collect();
    assert_eq!(paths.iter().filter(|p| **p == "rotation").count(), joints);
    assert_eq!(paths.iter().filter(|p| **p == "translation").count(), 1);
    let got = joints_of(&out, "mixamorig:", expected.len());
    let gap = largest_gap(&got, &expected);
    println!("the .glb rig's joints: largest gap to the BVH rig's {gap:.2e} m");
    assert!(gap < 1e-4, "joints {gap} m from the BVH rig's");
}

#[test]
fn scaled_armatures_and_matrix_nodes_give_the_same_motion() {
    let glb = glb_bytes();
    let (expected, _) = both(&glb, 1);
    let (mut json, bin) = split(&glb);
    let nodes = json["nodes"].as_array_mut().unwrap();
    let armature = nodes.iter().position(|n| n["name"] == "Armature").unwrap();
    // The armature in centimetres under a 0.01 scale, as FBX imports make it, and turned
    // to face +X: the motion is where it was.
    nodes[armature]["scale"] = json!([0.01, 0.01, 0.01]);
    let quarter = glam::DQuat::from_rotation_y(std::f64::consts::FRAC_PI_2);
    nodes[armature]["rotation"] = json!(quarter.to_array());
    for n in nodes.iter_mut() {
        let name = n["name"].as_str().unwrap_or("").to_string();
        if let Some(t) = n
            .get_mut("translation")
            .filter(|_| name.starts_with("mixamorig:"))
        {
            *t = json!(
                t.as_array()
                    .unwrap()
                    .iter()
                    .map(|v| v.as_f64().unwrap() * 100.0)
                    .collect::<Vec<_>>()
            );
        }
        // The left forearm as a matrix.
        if name == "mixamorig:LeftForeArm" {
            let t = n["translation"].as_array().unwrap().clone();
            let q = n["rotation"].as_array().unwrap().clone();
            let f = |v: &Value| v.as_f64().unwrap();
            let m = glam::DMat4::from_rotation_translation(
                glam::DQuat::from_xyzw(f(&q[0]), f(&q[1]), f(&q[2]), f(&q[3])),
                DVec3::new(f(&t[0]), f(&t[1]), f(&t[2])),
            );
            let obj = n.as_object_mut().unwrap();
            for k in ["translation", "rotation", "scale"] {
                obj.remove(k);
            }
            obj.insert("matrix".into(), json!(m.to_cols_array()));
        }
    }
    let (_, out) = both(&glb_of(&json, &bin), 1);
    let gap = largest_gap(&joints_of(&out, "mixamorig:", expected.len()), &expected);
    println!("scaled 0.01, turned, a matrix joint: largest gap {gap:.2e} m");
    assert!(gap < 1e-4, "joints {gap} m from the BVH rig's");
    // A scene whose up is +Z (the armature turned a quarter about X): read as Z up, the
    // motion comes out in the same turned world.
    let up = glam::DQuat::from_rotation_x(std::f64::consts::FRAC_PI_2);
    let nodes = json["nodes"].as_array_mut().unwrap();
    nodes[armature]["rotation"] = json!(up.to_array());
    let turned = glb_of(&json, &bin);
    let ch = Character::from_glb("z_up.glb", &turned, None).unwrap();
    assert_eq!(ch.up, mprog::formats::bvh::UpAxis::Z);
    let (_, out) = both(&turned, 1);
    let want: Vec<[DVec3; 22]> = expected.iter().map(|f| f.map(|p| up * p)).collect();
    let gap = largest_gap(&joints_of(&out, "mixamorig:", expected.len()), &want);
    println!("Z up: largest gap {gap:.2e} m");
    assert!(
        gap < 1e-4,
        "Z up: joints {gap} m from the BVH rig's, turned"
    );
}

#[test]
fn two_people_are_two_copies_of_the_character() {
    let glb = glb_bytes();
    let (expected, out) = both(&glb, 2);
    let (json_in, _) = split(&glb);
    let (json_out, _) = split(&out);
    let count = |j: &Value, k: &str| j[k].as_array().unwrap().len();
    assert_eq!(count(&json_out, "nodes"), 2 * count(&json_in, "nodes"));
    assert_eq!(count(&json_out, "skins"), 2);
    assert_eq!(count(&json_out, "meshes"), count(&json_in, "meshes"));
    let first = joints_of(&out, "mixamorig:", expected.len());
    assert!(largest_gap(&first, &expected) < 1e-4);
    // The second person walked the same clip 1 m along +X: the same motion, moved along X
    // by 1 m times the rig's leg over the clip's (the path scales with the legs).
    let second = joints_of(&out, "p2_mixamorig:", expected.len());
    let shift = second[0][0] - first[0][0];
    assert!(shift.y.abs() < 1e-4 && shift.z.abs() < 1e-4 && (1.1..1.2).contains(&shift.x));
    let shifted: Vec<[DVec3; 22]> = first.iter().map(|f| f.map(|p| p + shift)).collect();
    let gap = largest_gap(&second, &shifted);
    println!("second person: largest gap to a moved copy of the first {gap:.2e} m");
    assert!(
        gap < 1e-4,
        "the second person is {gap} m off a copy of the first"
    );
}

/// Every way a `.glb` rig can be wrong is an error that says what, never a panic.
#[test]
fn hostile_glb_rigs_are_errors() {
    let glb = glb_bytes();
    let err = |bytes: &[u8]| match Character::from_glb("bad.glb", bytes, None) {
        Ok(_) => panic!("accepted"),
        Err(e) => e.to_string(),
    };
    // Cut short anywhere (every 997th byte) or its header's length wrong.
    for cut in (0..glb.len()).step_by(997) {
        let e = err(&glb[..cut]);
        assert!(e.starts_with("bad.glb: cannot read the .glb rig"), "{e}");
    }
    let (json, bin) = split(&glb);
    let mangle = |f: &dyn Fn(&mut Value)| {
        let mut j = json.clone();
        f(&mut j);
        err(&glb_of(&j, &bin))
    };
    type Mangle = Box<dyn Fn(&mut Value)>;
    let cases: Vec<(&str, Mangle)> = vec![
        (
            "has no skin",
            Box::new(|j| {
                j.as_object_mut().unwrap().remove("skins");
            }),
        ),
        (
            "is the separate file",
            Box::new(|j| {
                j["buffers"][0]["uri"] = json!("/etc/passwd");
            }),
        ),
        (
            "cycle",
            Box::new(|j| {
                let last = j["nodes"].as_array().unwrap().len() - 1;
                j["nodes"][0]["children"] = json!([last]);
            }),
        ),
        (
            "is not a node",
            Box::new(|j| {
                j["skins"][0]["joints"][3] = json!(1_000_000);
            }),
        ),
        (
            "finite numbers",
            Box::new(|j| {
                j["nodes"][5]["rotation"] = json!([0, "x", 0, 1]);
            }),
        ),
        (
            "zero quaternion",
            Box::new(|j| {
                j["nodes"][5]["rotation"] = json!([0, 0, 0, 0]);
            }),
        ),
        (
            "non-uniform",
            Box::new(|j| {
                let n = j["nodes"].as_array_mut().unwrap();
                let a = n.iter().position(|n| n["name"] == "Armature").unwrap();
                n[a]["scale"] = json!([1, 2, 1]);
            }),
        ),
        (
            "twice",
            Box::new(|j| {
                j["skins"][0]["joints"][1] = j["skins"][0]["joints"][0].clone();
            }),
        ),
        (
            "no joint for",
            Box::new(|j| {
                for n in j["nodes"].as_array_mut().unwrap() {
                    let name = n["name"].as_str().unwrap_or("").replace("Leg", "Bein");
                    n["name"] = json!(name);
                }
            }),
        ),
    ];
    for (want, f) in cases {
        let e = mangle(&*f);
        assert!(e.contains(want), "wanted `{want}`: {e}");
    }
    insta::assert_snapshot!(
        "glb_no_skin",
        mangle(&|j: &mut Value| {
            j.as_object_mut().unwrap().remove("skins");
        })
    );
    // A rig file given as a .gltf (JSON with separate files) is refused by name.
    let dir = tempfile::tempdir().unwrap();
    let gltf = dir.path().join("character.gltf");
    std::fs::write(&gltf, "{}").unwrap();
    let e = Character::load(&gltf, None).unwrap_err().to_string();
    assert!(e.contains("skinned .glb"), "{e}");
}

/// Blender's glTF importer reads the animated character as mprog does:
/// `cargo test --test retarget_glb -- --ignored blender --nocapture`.
#[test]
#[ignore = "needs Blender (apt-get install blender python3-numpy); run by hand"]
fn blender_reads_the_animated_character() {
    if Command::new("blender").arg("--version").output().is_err() {
        println!("SKIPPED: blender is not installed");
        return;
    }
    let (expected, out) = both(&glb_bytes(), 1);
    let dir = tempfile::tempdir().unwrap();
    let (file, npy) = (dir.path().join("out.glb"), dir.path().join("expected.npy"));
    std::fs::write(&file, &out).unwrap();
    let motion = Motion::from_flat(
        &expected
            .iter()
            .flat_map(|f| f.iter().flat_map(|p| p.as_vec3().to_array()))
            .collect::<Vec<f32>>(),
    );
    mprog::formats::npy::write_joints_npy(&npy, &[motion]).unwrap();
    let names: Vec<String> = MIXAMO.iter().map(|m| format!("mixamorig:{m}")).collect();
    let out = Command::new("blender")
        .args(["-b", "--factory-startup", "--python"])
        .arg(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/scripts/blender_gltf_check.py"
        ))
        .arg("--")
        .arg(&file)
        .arg(&npy)
        .args(["--names", &names.join(",")])
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&out.stdout);
    let line = stdout
        .lines()
        .find(|l| l.starts_with("blender_gltf_check"))
        .unwrap_or("no report");
    println!("{line}");
    assert!(out.status.success() && line.contains(": OK"), "{stdout}");
}

/// three.js (GLTFLoader, AnimationMixer, in Node) plays the animated character and the
/// plain `.glb` with their joints where mprog put them:
/// `npm install --prefix DIR three@0.187.0`, then
/// `THREE_MODULES=DIR/node_modules cargo test --test retarget_glb -- --ignored --nocapture three`.
#[test]
#[ignore = "needs Node and three.js (THREE_MODULES); run by hand"]
fn three_js_plays_the_animated_character_and_the_plain_glb() {
    let Some(modules) = std::env::var_os("THREE_MODULES") else {
        println!("SKIPPED: set THREE_MODULES to a node_modules folder holding three");
        return;
    };
    let (expected, out) = both(&glb_bytes(), 1);
    let (_, clip) = common::golden();
    let dir = tempfile::tempdir().unwrap();
    let track = |frames: &[[DVec3; 22]]| {
        Motion::from_flat(
            &frames
                .iter()
                .flat_map(|f| f.iter().flat_map(|p| p.as_vec3().to_array()))
                .collect::<Vec<f32>>(),
        )
    };
    let plain = mprog::formats::gltf::glb_bytes(std::slice::from_ref(&clip)).unwrap();
    let mixamo: Vec<String> = MIXAMO.iter().map(|m| format!("mixamorig:{m}")).collect();
    let cases = [
        ("rig", out, track(&expected), mixamo.join(",")),
        (
            "plain",
            plain,
            clip.clone(),
            mprog::skeleton::JOINT_NAMES.join(","),
        ),
    ];
    for (name, glb, motion, names) in cases {
        let (file, npy) = (
            dir.path().join(format!("{name}.glb")),
            dir.path().join(format!("{name}.npy")),
        );
        std::fs::write(&file, glb).unwrap();
        mprog::formats::npy::write_joints_npy(&npy, &[motion]).unwrap();
        let run = Command::new("node")
            .arg(concat!(
                env!("CARGO_MANIFEST_DIR"),
                "/scripts/three_gltf_check.mjs"
            ))
            .arg(&file)
            .arg(&npy)
            .arg(&names)
            .env("THREE_MODULES", &modules)
            .output()
            .unwrap();
        let stdout = String::from_utf8_lossy(&run.stdout);
        println!("{name}: {}", stdout.trim());
        assert!(
            run.status.success() && stdout.contains(": OK"),
            "{stdout}{}",
            String::from_utf8_lossy(&run.stderr)
        );
    }
}
