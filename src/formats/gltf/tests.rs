//! The `.glb` read back by a reader written here (header, JSON chunk, binary chunk, forward
//! kinematics over the node tree) puts every joint within 1 cm of the motion it came from.

use super::read::{Glb, parse_glb};
use super::*;
use crate::formats::bvh_export::BvhExportOptions;
use crate::formats::outputs::{OutputJob, write_outputs};
use crate::motion::Meta;
use crate::render::test_motion::walk;
use crate::skeleton::JOINT_NAMES;
use glam::{Mat4, Vec3};

fn parse(bytes: &[u8]) -> Glb {
    parse_glb(bytes).expect("a valid .glb")
}

/// Largest distance between the joints of person `prefix` in the file and `m`.
fn worst_error(glb: &Glb, m: &Motion, prefix: &str) -> f32 {
    let ids: Vec<usize> = JOINT_NAMES
        .iter()
        .map(|j| {
            let name = format!("{prefix}{j}");
            glb.doc
                .nodes
                .iter()
                .position(|n| n.name == name)
                .expect(&name)
        })
        .collect();
    let mut worst = 0.0f32;
    for (f, pose) in m.frames.iter().enumerate() {
        let world = glb.world(f).unwrap();
        for (j, &id) in ids.iter().enumerate() {
            worst = worst.max((world[id].w_axis.truncate() - pose[j]).length());
        }
    }
    worst
}

#[test]
fn glb_reads_back_within_a_centimetre_at_20_fps() {
    let m = walk(40, 1.2, Vec3::new(0.5, 0.0, -1.0), Vec3::X);
    let glb = parse(&glb_bytes(std::slice::from_ref(&m)).unwrap());
    let doc = &glb.doc;
    assert_eq!(doc.asset.version, "2.0");
    // The joint nodes and the body's node.
    assert_eq!(doc.nodes.len(), super::super::rig::hierarchy().len() + 1);
    let times = glb.floats(doc.animations[0].samplers[0].input).unwrap();
    assert_eq!(times.len(), 40);
    assert!((times[1] - 0.05).abs() < 1e-6, "20 fps keys: {}", times[1]);
    // Only the root is translated by the animation; every other node keeps its offset.
    let moved: Vec<_> = doc.animations[0]
        .channels
        .iter()
        .filter(|c| c.target.path == "translation")
        .map(|c| doc.nodes[c.target.node].name.as_str())
        .collect();
    assert_eq!(moved, ["pelvis"]);
    let err = worst_error(&glb, &m, "");
    assert!(err < 0.01, "max error {err} m");
}

#[test]
fn several_people_are_several_skeletons_in_one_file() {
    let a = walk(20, 1.0, Vec3::ZERO, Vec3::Z);
    let b = walk(20, 1.4, Vec3::new(2.0, 0.0, 0.0), Vec3::X);
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("pair.glb");
    let job = OutputJob {
        people: &[a.clone(), b.clone()],
        meta: &Meta::new(),
        title: "pair",
        bvh: &BvhExportOptions::default(),
        rig: None,
    };
    let written = write_outputs(std::slice::from_ref(&out), &job).unwrap();
    assert_eq!(written, std::slice::from_ref(&out), "one file, no sidecar");
    let glb = parse(&std::fs::read(&out).unwrap());
    // Per person: the skeleton's root and the body's node.
    assert_eq!(glb.doc.scenes[0].nodes.len(), 4);
    assert_eq!(glb.doc.skins.len(), 2);
    assert!(worst_error(&glb, &a, "p1_") < 0.01);
    assert!(worst_error(&glb, &b, "p2_") < 0.01);
}

#[test]
fn broken_motions_are_refused_with_the_frame_and_joint() {
    let mut m = walk(5, 1.0, Vec3::ZERO, Vec3::Z);
    m.frames[3][20].y = f32::NAN;
    let err = glb_bytes(&[m]).unwrap_err().to_string();
    assert!(err.contains("left_wrist") && err.contains('3'), "{err}");
    assert!(glb_bytes(&[Motion::new(vec![])]).is_err());
}

#[test]
fn the_skin_binds_a_body_that_follows_the_joints() {
    let m = walk(30, 1.2, Vec3::new(0.5, 0.0, -1.0), Vec3::X);
    let glb = parse(&glb_bytes(std::slice::from_ref(&m)).unwrap());
    let doc = &glb.doc;
    let [skin] = &doc.skins[..] else {
        panic!("one skin")
    };
    // Every joint node is in the skin, the body node is not; the skeleton is the pelvis.
    assert_eq!(skin.joints.len(), doc.nodes.len() - 1);
    assert_eq!(doc.nodes[skin.skeleton].name, "pelvis");
    let body = doc.nodes.iter().position(|n| n.skin == Some(0)).unwrap();
    assert!(
        doc.scenes[0].nodes.contains(&body),
        "the body is a scene root"
    );
    assert!(!skin.joints.contains(&body));
    // Inverse bind matrices undo the rest pose: IBM × (bind world) = identity.
    let ibm = glb.floats(skin.inverse_bind_matrices).unwrap();
    assert_eq!(ibm.len(), 16 * skin.joints.len());
    let rest = rest_world(&glb);
    for (k, &n) in skin.joints.iter().enumerate() {
        let inv = Mat4::from_cols_slice(&ibm[k * 16..k * 16 + 16]);
        let id = inv * rest[n];
        assert!(id.abs_diff_eq(Mat4::IDENTITY, 1e-5), "joint {k}: {id}");
    }
    // The mesh: matching attribute counts, indices in range, joints in the skin.
    let prim = &doc.meshes[doc.nodes[body].mesh.unwrap()].primitives[0];
    let count = doc.accessors[prim.attributes["POSITION"]].count;
    assert!(count > 27 * 30, "{count} vertices");
    for a in ["NORMAL", "JOINTS_0", "WEIGHTS_0"] {
        assert_eq!(doc.accessors[prim.attributes[a]].count, count, "{a}");
    }
    let indices = glb.uints(prim.indices).unwrap();
    assert_eq!(indices.len() % 3, 0);
    assert!(indices.iter().all(|&i| (i as usize) < count));
    let joints = glb.uints(prim.attributes["JOINTS_0"]).unwrap();
    assert!(joints.iter().all(|&j| (j as usize) < skin.joints.len()));
    let weights = glb.floats(prim.attributes["WEIGHTS_0"]).unwrap();
    for w in weights.chunks_exact(4) {
        assert!((w.iter().sum::<f32>() - 1.0).abs() < 1e-6);
    }
    for v in &doc.buffer_views {
        assert_eq!(v.byte_offset % 4, 0, "views are 4-byte aligned");
    }
    // Skinned at a frame, every vertex stays within reach of the joint it is bound to.
    for f in [0, 17] {
        let verts = glb.skinned_vertices(body, f).unwrap();
        let world = glb.world(f).unwrap();
        for (v, j) in verts.iter().zip(joints.chunks_exact(4)) {
            let at = world[skin.joints[j[0] as usize]].w_axis.truncate();
            assert!(v.distance(at) < 0.6, "vertex {v} far from its joint {at}");
        }
        let lowest = verts.iter().map(|v| v.y).fold(f32::MAX, f32::min);
        assert!(lowest > -0.1, "frame {f}: body {lowest} m below the floor");
    }
}

/// World transform of every node in the rest pose (the nodes' own rotation and translation).
fn rest_world(glb: &Glb) -> Vec<Mat4> {
    let doc = &glb.doc;
    let mut world = vec![Mat4::IDENTITY; doc.nodes.len()];
    let mut stack: Vec<(usize, Mat4)> = doc.scenes[0]
        .nodes
        .iter()
        .map(|&r| (r, Mat4::IDENTITY))
        .collect();
    while let Some((n, parent)) = stack.pop() {
        let node = &doc.nodes[n];
        let w = parent
            * Mat4::from_rotation_translation(
                glam::Quat::from_array(node.rotation),
                Vec3::from(node.translation),
            );
        world[n] = w;
        stack.extend(node.children.iter().map(|&c| (c, w)));
    }
    world
}
