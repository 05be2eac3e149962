//! Tests of the whole BVH import on small hand-written inputs: FK against hand-computed
//! positions for several channel orders, text variants (CRLF, tabs, exponents), every
//! error case with its line number ([`errors`]), and joint mapping of several rigs
//! ([`rigs`]).

mod errors;
mod rigs;

use super::*;
use glam::Vec3;

pub(super) fn parse(text: &str) -> Result<Bvh, BvhError> {
    parse_bvh("t.bvh", text, ParseLimits::default())
}

/// Root (6 channels) → `Mid` (`mid_channels`, offset 0 10 0) → End Site (0 0 10).
pub(super) fn chain(mid_channels: &str, frame: &str) -> String {
    format!(
        "HIERARCHY\nROOT Root\n{{\n  OFFSET 0 0 0\n  CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation\n  JOINT Mid\n  {{\n    OFFSET 0 10 0\n    CHANNELS {mid_channels}\n    End Site\n    {{\n      OFFSET 0 0 10\n    }}\n  }}\n}}\nMOTION\nFrames: 1\nFrame Time: 0.05\n{frame}\n"
    )
}

pub(super) fn positions(text: &str) -> Vec<Vec3> {
    fk::global_positions(&parse(text).unwrap())
}

pub(super) fn assert_close(a: Vec3, b: Vec3) {
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
