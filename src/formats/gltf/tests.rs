//! The `.glb` read back by a reader written here (header, JSON chunk, binary chunk, forward
//! kinematics over the node tree) puts every joint within 1 cm of the motion it came from.

use super::document::Document;
use super::*;
use crate::formats::bvh_export::BvhExportOptions;
use crate::formats::outputs::{OutputJob, write_outputs};
use crate::motion::Meta;
use crate::render::test_motion::walk;
use crate::skeleton::JOINT_NAMES;
use glam::{Mat4, Quat, Vec3};

/// A parsed `.glb`: its document and binary chunk.
fn parse_glb(bytes: &[u8]) -> (Document, Vec<u8>) {
    let word = |at: usize| u32::from_le_bytes(bytes[at..at + 4].try_into().unwrap());
    assert_eq!((word(0), word(4)), (GLB_MAGIC, 2), "header");
    assert_eq!(word(8) as usize, bytes.len(), "total length");
    let json_len = word(12) as usize;
    assert_eq!(word(16), CHUNK_JSON);
    let json = &bytes[20..20 + json_len];
    let bin_at = 20 + json_len;
    let bin_len = word(bin_at) as usize;
    assert_eq!(word(bin_at + 4), CHUNK_BIN);
    assert_eq!(bin_at + 8 + bin_len, bytes.len(), "chunks fill the file");
    let doc: Document = serde_json::from_slice(json).expect("JSON chunk");
    (doc, bytes[bin_at + 8..].to_vec())
}

/// The floats of accessor `a`.
fn floats(doc: &Document, bin: &[u8], a: usize) -> Vec<f32> {
    let acc = &doc.accessors[a];
    let view = &doc.buffer_views[acc.buffer_view];
    assert_eq!(acc.component_type, document::FLOAT);
    bin[view.byte_offset..view.byte_offset + view.byte_length]
        .chunks_exact(4)
        .map(|c| f32::from_le_bytes(c.try_into().unwrap()))
        .collect()
}

/// World position of every node at key `frame`, by forward kinematics from the roots.
fn node_positions(doc: &Document, bin: &[u8], frame: usize) -> Vec<Vec3> {
    let anim = &doc.animations[0];
    let mut rot: Vec<Quat> = doc
        .nodes
        .iter()
        .map(|n| Quat::from_array(n.rotation))
        .collect();
    let mut pos: Vec<Vec3> = doc
        .nodes
        .iter()
        .map(|n| Vec3::from(n.translation))
        .collect();
    for ch in &anim.channels {
        let s = &anim.samplers[ch.sampler];
        let out = floats(doc, bin, s.output);
        match ch.target.path.as_str() {
            "rotation" => rot[ch.target.node] = Quat::from_slice(&out[frame * 4..frame * 4 + 4]),
            "translation" => pos[ch.target.node] = Vec3::from_slice(&out[frame * 3..frame * 3 + 3]),
            other => panic!("unexpected path {other}"),
        }
    }
    let local: Vec<Mat4> = (0..doc.nodes.len())
        .map(|i| Mat4::from_rotation_translation(rot[i], pos[i]))
        .collect();
    let mut world = vec![None; doc.nodes.len()];
    let mut stack: Vec<(usize, Mat4)> = doc.scenes[doc.scene]
        .nodes
        .iter()
        .map(|&r| (r, Mat4::IDENTITY))
        .collect();
    while let Some((n, parent)) = stack.pop() {
        let w = parent * local[n];
        world[n] = Some(w);
        stack.extend(doc.nodes[n].children.iter().map(|&c| (c, w)));
    }
    world
        .into_iter()
        .map(|w| w.expect("every node is in the scene").w_axis.truncate())
        .collect()
}

/// Largest distance between the joints of person `prefix` in the file and `m`.
fn worst_error(doc: &Document, bin: &[u8], m: &Motion, prefix: &str) -> f32 {
    let ids: Vec<usize> = JOINT_NAMES
        .iter()
        .map(|j| {
            let name = format!("{prefix}{j}");
            doc.nodes.iter().position(|n| n.name == name).expect(&name)
        })
        .collect();
    let mut worst = 0.0f32;
    for (f, pose) in m.frames.iter().enumerate() {
        let got = node_positions(doc, bin, f);
        for (j, &id) in ids.iter().enumerate() {
            worst = worst.max((got[id] - pose[j]).length());
        }
    }
    worst
}

#[test]
fn glb_reads_back_within_a_centimetre_at_20_fps() {
    let m = walk(40, 1.2, Vec3::new(0.5, 0.0, -1.0), Vec3::X);
    let (doc, bin) = parse_glb(&glb_bytes(std::slice::from_ref(&m)).unwrap());
    assert_eq!(doc.asset.version, "2.0");
    assert_eq!(doc.nodes.len(), rig::hierarchy().len());
    let times = floats(&doc, &bin, doc.animations[0].samplers[0].input);
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
    let err = worst_error(&doc, &bin, &m, "");
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
    };
    let written = write_outputs(std::slice::from_ref(&out), &job).unwrap();
    assert_eq!(written, std::slice::from_ref(&out), "one file, no sidecar");
    let (doc, bin) = parse_glb(&std::fs::read(&out).unwrap());
    assert_eq!(doc.scenes[0].nodes.len(), 2);
    assert!(worst_error(&doc, &bin, &a, "p1_") < 0.01);
    assert!(worst_error(&doc, &bin, &b, "p2_") < 0.01);
}

#[test]
fn broken_motions_are_refused_with_the_frame_and_joint() {
    let mut m = walk(5, 1.0, Vec3::ZERO, Vec3::Z);
    m.frames[3][20].y = f32::NAN;
    let err = glb_bytes(&[m]).unwrap_err().to_string();
    assert!(err.contains("left_wrist") && err.contains('3'), "{err}");
    assert!(glb_bytes(&[Motion::new(vec![])]).is_err());
}
