//! BVH text of a motion on the rig: the rig's HIERARCHY as it was (names, OFFSETs written
//! back to the same float, End Sites, CHANNELS in the file's order), then one MOTION line
//! per frame: the mover's position channels carry the body's path (in the rig's units and
//! axes), every other position channel its rest offset, rotation channels the joint's local
//! rotation as Euler angles in the joint's own channel order (degrees; zero for joints that
//! keep their rest pose).

use super::Character;
use super::plan::channel_names;
use crate::formats::bvh::parse::{Axis, Channel};
use crate::formats::posed::Posed;
use glam::DVec3;
use std::fmt::Write as _;

/// The BVH text of `posed` (made by [`Character::retarget`]) on `ch`.
pub fn bvh_text(ch: &Character, posed: &Posed) -> String {
    let mut out = String::from("HIERARCHY\n");
    let name = Path(&ch.origin);
    let up = match ch.up {
        crate::formats::bvh::UpAxis::Y => "Y up",
        crate::formats::bvh::UpAxis::Z => "Z up",
    };
    let _ = writeln!(
        out,
        "# mprog motion on the rig {name}: its joints, offsets and channels; units {}, {up}; {} fps.",
        ch.units, posed.fps
    );
    let mut children: Vec<Vec<usize>> = vec![Vec::new(); ch.joints.len()];
    for (i, j) in ch.joints.iter().enumerate() {
        if let Some(p) = j.parent {
            children[p].push(i);
        }
    }
    for (i, j) in ch.joints.iter().enumerate() {
        if j.parent.is_none() {
            joint(&mut out, ch, &children, i, 0);
        }
    }
    let _ = writeln!(out, "MOTION\nFrames: {}", posed.len());
    let _ = writeln!(out, "Frame Time: {:.8}", 1.0 / f64::from(posed.fps));
    let to_file = ch.axes().inverse();
    for f in 0..posed.len() {
        let mut first = true;
        for (i, j) in ch.joints.iter().enumerate() {
            if j.end_site {
                continue;
            }
            let position = if i == posed.mover {
                to_file * posed.translations[f] / ch.unit_scale
            } else {
                j.offset.as_dvec3()
            };
            let local = to_file * posed.rotations[f][i] * to_file.inverse();
            let angles = ch.plan.euler[i].map(|order| {
                let (a, b, c) = local.to_euler(order);
                [a, b, c].map(f64::to_degrees)
            });
            let mut rotation = 0;
            for c in &j.channels {
                let v = match *c {
                    Channel::Position(axis) => component(position, axis),
                    Channel::Rotation(_) => {
                        rotation += 1;
                        angles.map_or(0.0, |a| a[rotation - 1])
                    }
                };
                if !first {
                    out.push(' ');
                }
                first = false;
                let _ = write!(out, "{:.6}", clean(v));
            }
        }
        out.push('\n');
    }
    out
}

/// The HIERARCHY block of joint `i` and its subtree.
fn joint(out: &mut String, ch: &Character, children: &[Vec<usize>], i: usize, depth: usize) {
    let pad = "  ".repeat(depth);
    let j = &ch.joints[i];
    let o = j.offset;
    if j.end_site {
        let _ = writeln!(
            out,
            "{pad}End Site\n{pad}{{\n{pad}  OFFSET {} {} {}\n{pad}}}",
            o.x, o.y, o.z
        );
        return;
    }
    let kind = if j.parent.is_none() { "ROOT" } else { "JOINT" };
    let _ = writeln!(out, "{pad}{kind} {}\n{pad}{{", j.name);
    let _ = writeln!(out, "{pad}  OFFSET {} {} {}", o.x, o.y, o.z);
    let channels = channel_names(&j.channels);
    let _ = writeln!(out, "{pad}  CHANNELS {} {channels}", j.channels.len());
    for &c in &children[i] {
        joint(out, ch, children, c, depth + 1);
    }
    let _ = writeln!(out, "{pad}}}");
}

fn component(v: DVec3, axis: Axis) -> f64 {
    match axis {
        Axis::X => v.x,
        Axis::Y => v.y,
        Axis::Z => v.z,
    }
}

/// No `-0.000000` in the file.
fn clean(v: f64) -> f64 {
    if v.abs() < 5e-7 { 0.0 } else { v }
}

/// A file name for a comment line: the last component, control characters replaced.
struct Path<'a>(&'a str);

impl std::fmt::Display for Path<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let name = self.0.rsplit(['/', '\\']).next().unwrap_or(self.0);
        let name: String = name
            .chars()
            .map(|c| if c.is_control() { '?' } else { c })
            .collect();
        f.write_str(&name)
    }
}
