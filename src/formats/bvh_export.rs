//! BVH export of the 22-joint skeleton: in, a [`Motion`] (global joint positions); out, a BVH
//! file whose forward kinematics reproduces those positions.
//!
//! * Rotations are solved from the positions with [`ik::chained_bone_rotations`]: every bone
//!   gets its parent bone's rotation plus the minimal swing to its current direction; the
//!   bones leaving the pelvis are oriented by the body's facing ([`ik::body_facing`]).
//! * HIERARCHY: the 22 HumanML3D joints with their names, offsets = rest direction
//!   ([`RAW_OFFSETS`]) × the motion's own bone length (mean over frames). BVH gives a joint one
//!   rotation for all its children, while pelvis and spine3 have several bones leaving them
//!   whose relative angles change over time; so each of those bones hangs from a zero-offset
//!   connector joint (`pelvis_to_left_hip`, …, `spine3_to_right_collar`) that carries its
//!   rotation. The pelvis itself carries the facing yaw; spine3 carries the neck bone.
//! * Channels: the root has `Xposition Yposition Zposition Zrotation Yrotation Xrotation`,
//!   every other joint `Zrotation Yrotation Xrotation` (local rotation = Rz·Ry·Rx, degrees).
//!   The root OFFSET is zero: its position channels are absolute.
//! * Frame time = 1/fps; [`BvhExportOptions::fps`] resamples the joint positions to another
//!   rate (e.g. 30 or 60 for animation tools) before the rotations are solved, by
//!   Catmull–Rom interpolation: it follows curved joint paths, so bones keep their length
//!   (straight-line interpolation shortens a fast forearm by centimetres). Units metres (or centimetres), axes Y up (or Blender's Z up:
//!   (x, y, z) ↦ (x, −z, y)). A `#` comment after the `HIERARCHY` line states units, axes
//!   and fps; Blender's importer skips it (it only looks for keywords there).

use crate::features::FeatureError;
use crate::features::ik::{self, Pose64};
use crate::fsutil::write_atomic;
use crate::motion::Motion;
use crate::skeleton::{JOINT_NAMES, NUM_JOINTS, PARENTS, RAW_OFFSETS};
use glam::{DQuat, DVec3, EulerRot};
use std::fmt::Write as _;
use std::path::Path;
use thiserror::Error;

/// Length unit of the written file.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum BvhUnits {
    /// Metres, as mprog.
    #[default]
    Metres,
    /// Centimetres, as most mocap BVH files.
    Centimetres,
}

/// Axis convention of the written file.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum BvhAxes {
    /// Y up, as mprog (import into Blender with its default axes: forward −Z, up Y).
    #[default]
    YUp,
    /// Blender's Z up, (x, y, z) ↦ (x, −z, y) (import with forward Y, up Z).
    BlenderZUp,
}

/// Options of [`write_bvh`] / [`bvh_string`].
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct BvhExportOptions {
    /// Length unit.
    pub units: BvhUnits,
    /// Axis convention.
    pub axes: BvhAxes,
    /// Frame rate of the file (`None`: the motion's own). Positions are resampled
    /// (Catmull–Rom) before rotations are solved; the clip keeps its duration.
    pub fps: Option<f32>,
}

/// Highest frame rate [`BvhExportOptions::fps`] accepts.
pub const MAX_EXPORT_FPS: f32 = 1000.0;

/// Errors of the BVH exporter.
#[derive(Debug, Error)]
pub enum BvhExportError {
    /// The motion cannot be turned into rotations (empty, non-finite, zero-length bones, …).
    #[error("cannot export this motion as BVH: {0}")]
    Motion(#[from] FeatureError),
    /// The requested frame rate is not a positive number up to [`MAX_EXPORT_FPS`].
    #[error(
        "cannot export at {0} fps: the frame rate must be above 0 and at most {MAX_EXPORT_FPS}"
    )]
    BadFps(f32),
    /// Writing the file failed.
    #[error("cannot write the BVH file: {0}")]
    Io(#[from] std::io::Error),
}

/// Writes `m` as a BVH file (atomically).
pub fn write_bvh(path: &Path, m: &Motion, opts: &BvhExportOptions) -> Result<(), BvhExportError> {
    let text = bvh_string(m, opts)?;
    write_atomic(path, |w| w.write_all(text.as_bytes()))?;
    Ok(())
}

/// Where a BVH joint's global rotation comes from.
#[derive(Clone, Copy, Debug)]
enum Carry {
    /// The body's facing yaw (the pelvis).
    Facing,
    /// The rotation of the bone ending at this HumanML3D joint.
    Bone(usize),
    /// The parent's rotation (leaves, which have no bone of their own).
    Inherit,
}

/// One BVH joint: where it sits, what it is attached to, what drives its rotation.
#[derive(Clone, Debug)]
struct Node {
    name: String,
    parent: Option<usize>,
    /// HumanML3D joint whose rest offset this node's OFFSET is (None: zero offset).
    offset_of: Option<usize>,
    carry: Carry,
    children: Vec<usize>,
}

/// The BVH joints in file (depth-first) order.
fn hierarchy() -> Vec<Node> {
    let mut nodes = Vec::new();
    add_joint(&mut nodes, 0, None, None);
    nodes
}

fn push(nodes: &mut Vec<Node>, node: Node) -> usize {
    let id = nodes.len();
    if let Some(p) = node.parent {
        nodes[p].children.push(id);
    }
    nodes.push(node);
    id
}

/// Adds HumanML3D joint `j` under BVH node `parent`, then its subtree.
fn add_joint(nodes: &mut Vec<Node>, j: usize, parent: Option<usize>, offset_of: Option<usize>) {
    let children: Vec<usize> = (1..NUM_JOINTS).filter(|&c| PARENTS[c] == j).collect();
    let carry = match (j, children.first()) {
        (0, _) => Carry::Facing,
        (_, Some(&first)) => Carry::Bone(first),
        (_, None) => Carry::Inherit,
    };
    let name = JOINT_NAMES[j].to_string();
    let id = push(
        nodes,
        Node {
            name,
            parent,
            offset_of,
            carry,
            children: Vec::new(),
        },
    );
    for (k, &c) in children.iter().enumerate() {
        // The first child of a non-root joint uses the joint's own rotation; every other
        // bone leaving a branching joint gets a connector carrying its rotation.
        if j != 0 && k == 0 {
            add_joint(nodes, c, Some(id), Some(c));
        } else {
            let name = format!("{}_to_{}", JOINT_NAMES[j], JOINT_NAMES[c]);
            let node = Node {
                name,
                parent: Some(id),
                offset_of: None,
                carry: Carry::Bone(c),
                children: Vec::new(),
            };
            let conn = push(nodes, node);
            add_joint(nodes, c, Some(conn), Some(c));
        }
    }
}

/// The BVH text of `m`.
pub fn bvh_string(m: &Motion, opts: &BvhExportOptions) -> Result<String, BvhExportError> {
    if m.is_empty() {
        return Err(FeatureError::TooFewFrames {
            frames: 0,
            needed: 1,
        }
        .into());
    }
    let source_fps = m.fps;
    let resampled;
    let m = match opts.fps {
        Some(fps) if !(fps.is_finite() && fps > 0.0 && fps <= MAX_EXPORT_FPS) => {
            return Err(BvhExportError::BadFps(fps));
        }
        Some(fps) if fps != m.fps => {
            resampled = resample_cubic(m, fps);
            &resampled
        }
        _ => m,
    };
    let poses = ik::poses_f64(m)?;
    let writer = Writer {
        nodes: hierarchy(),
        lengths: mean_bone_lengths(&poses),
        scale: match opts.units {
            BvhUnits::Metres => 1.0,
            BvhUnits::Centimetres => 100.0,
        },
        axes: match opts.axes {
            BvhAxes::YUp => DQuat::IDENTITY,
            BvhAxes::BlenderZUp => DQuat::from_rotation_x(std::f64::consts::FRAC_PI_2),
        },
    };
    let mut out = String::new();
    write_header(&mut out, m, source_fps, opts);
    writer.node(&mut out, 0, 0);
    let _ = writeln!(out, "MOTION\nFrames: {}", poses.len());
    let _ = writeln!(out, "Frame Time: {:.8}", 1.0 / m.fps as f64);
    for (t, pose) in poses.iter().enumerate() {
        writer.frame(&mut out, pose, t)?;
    }
    Ok(out)
}

/// `m` at `fps` by Catmull–Rom interpolation of every joint between its neighbouring
/// frames (the end segments extended in straight lines); frame `i` is at time `i / fps`, the last one at or before
/// the clip's end, as [`Motion::resample`].
pub fn resample_cubic(m: &Motion, fps: f32) -> Motion {
    let n = m.len();
    if n < 2 || fps == m.fps {
        return Motion {
            frames: m.frames.clone(),
            fps,
        };
    }
    let ratio = f64::from(m.fps) / f64::from(fps);
    let count = (((n - 1) as f64 / ratio) + 1e-9).floor() as usize + 1;
    let frames = (0..count)
        .map(|i| {
            let src = i as f64 * ratio;
            let i1 = (src.floor() as usize).min(n - 1);
            let t = (src - i1 as f64) as f32;
            let i2 = (i1 + 1).min(n - 1);
            let f = &m.frames;
            std::array::from_fn(|j| {
                let (p1, p2) = (f[i1][j], f[i2][j]);
                // Past either end, continue the end segment in a straight line.
                let p0 = if i1 > 0 { f[i1 - 1][j] } else { 2.0 * p1 - p2 };
                let p3 = if i1 + 2 < n {
                    f[i1 + 2][j]
                } else {
                    2.0 * p2 - p1
                };
                0.5 * (2.0 * p1
                    + (p2 - p0) * t
                    + (2.0 * p0 - 5.0 * p1 + 4.0 * p2 - p3) * (t * t)
                    + (3.0 * p1 - p0 - 3.0 * p2 + p3) * (t * t * t))
            })
        })
        .collect();
    Motion { frames, fps }
}

/// Mean length of every bone over the frames (index = child joint).
fn mean_bone_lengths(poses: &[Pose64]) -> [f64; NUM_JOINTS] {
    let mut len = [0.0; NUM_JOINTS];
    for p in poses {
        for j in 1..NUM_JOINTS {
            len[j] += (p[j] - p[PARENTS[j]]).length() / poses.len() as f64;
        }
    }
    len
}

fn write_header(out: &mut String, m: &Motion, source_fps: f32, opts: &BvhExportOptions) {
    let units = match opts.units {
        BvhUnits::Metres => "metres",
        BvhUnits::Centimetres => "centimetres",
    };
    let axes = match opts.axes {
        BvhAxes::YUp => "Y up, the body faces +Z at the start of a canonical clip, its left is +X",
        BvhAxes::BlenderZUp => {
            "Z up (Blender), the body faces -Y at the start of a canonical clip, its left is +X"
        }
    };
    let _ = writeln!(out, "HIERARCHY");
    let _ = writeln!(
        out,
        "# mprog BVH export: HumanML3D 22-joint skeleton, units {units}, {axes},"
    );
    let resampled = if m.fps == source_fps {
        String::new()
    } else {
        format!(" (resampled from {source_fps} fps)")
    };
    let _ = writeln!(
        out,
        "# {} fps{resampled}; rotations in degrees, local rotation = Rz * Ry * Rx.",
        m.fps
    );
}

/// What the writer needs besides the poses: the joints, bone lengths, unit and axes.
struct Writer {
    nodes: Vec<Node>,
    lengths: [f64; NUM_JOINTS],
    /// Metres → file unit.
    scale: f64,
    /// Axis change applied to every position, offset and rotation.
    axes: DQuat,
}

impl Writer {
    /// `fraction` × the rest offset of HumanML3D joint `j`, in file units and axes.
    fn offset(&self, j: usize, fraction: f64) -> DVec3 {
        let raw = DVec3::from(RAW_OFFSETS[j].map(f64::from));
        self.axes * raw * (self.lengths[j] * fraction * self.scale)
    }

    /// Writes the HIERARCHY entry of node `id` and its subtree.
    fn node(&self, out: &mut String, id: usize, depth: usize) {
        let pad = "  ".repeat(depth);
        let node = &self.nodes[id];
        let o = node.offset_of.map_or(DVec3::ZERO, |j| self.offset(j, 1.0));
        let kind = if node.parent.is_none() {
            "ROOT"
        } else {
            "JOINT"
        };
        let _ = writeln!(out, "{pad}{kind} {}\n{pad}{{", node.name);
        let _ = writeln!(out, "{pad}  OFFSET {:.6} {:.6} {:.6}", o.x, o.y, o.z);
        let channels = if node.parent.is_none() {
            "6 Xposition Yposition Zposition Zrotation Yrotation Xrotation"
        } else {
            "3 Zrotation Yrotation Xrotation"
        };
        let _ = writeln!(out, "{pad}  CHANNELS {channels}");
        for &c in &node.children {
            self.node(out, c, depth + 1);
        }
        if node.children.is_empty() {
            // Leaves continue their bone by half its length (BVH needs an end site).
            let e = self.offset(node.offset_of.unwrap_or(0), 0.5);
            let _ = writeln!(out, "{pad}  End Site\n{pad}  {{");
            let _ = writeln!(
                out,
                "{pad}    OFFSET {:.6} {:.6} {:.6}\n{pad}  }}",
                e.x, e.y, e.z
            );
        }
        let _ = writeln!(out, "{pad}}}");
    }

    /// One MOTION line: root position, then every joint's local Z, Y, X rotation in degrees.
    fn frame(&self, out: &mut String, pose: &Pose64, frame: usize) -> Result<(), FeatureError> {
        let facing = ik::body_facing(pose, frame)?;
        let bones = ik::chained_bone_rotations(pose, frame, facing)?;
        let to_file = |q: DQuat| self.axes * q * self.axes.inverse();
        let mut global = vec![DQuat::IDENTITY; self.nodes.len()];
        let root = self.axes * pose[0] * self.scale;
        let _ = write!(out, "{:.6} {:.6} {:.6}", root.x, root.y, root.z);
        for (id, node) in self.nodes.iter().enumerate() {
            let parent = node.parent.map_or(DQuat::IDENTITY, |p| global[p]);
            global[id] = match node.carry {
                Carry::Facing => to_file(facing),
                Carry::Bone(b) => to_file(bones[b]),
                Carry::Inherit => parent,
            };
            let local = (parent.inverse() * global[id]).normalize();
            let (z, y, x) = local.to_euler(EulerRot::ZYX);
            let _ = write!(
                out,
                " {:.6} {:.6} {:.6}",
                z.to_degrees(),
                y.to_degrees(),
                x.to_degrees()
            );
        }
        out.push('\n');
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hierarchy_has_the_22_joints_and_5_connectors() {
        let nodes = hierarchy();
        assert_eq!(nodes.len(), NUM_JOINTS + 5);
        for name in JOINT_NAMES {
            assert_eq!(nodes.iter().filter(|n| n.name == name).count(), 1, "{name}");
        }
        // Every joint node hangs (through at most one connector) from its HumanML3D parent.
        for (id, n) in nodes.iter().enumerate().skip(1) {
            let Some(j) = n.offset_of else { continue };
            let mut p = n.parent.unwrap();
            if nodes[p].offset_of.is_none() && p != 0 {
                p = nodes[p].parent.unwrap();
            }
            assert_eq!(nodes[p].name, JOINT_NAMES[PARENTS[j]], "node {id}");
        }
    }

    #[test]
    fn cubic_resampling_keeps_frames_duration_and_straight_lines() {
        // A joint moving on a straight line at constant speed stays on it, exactly.
        let frames: Vec<_> = (0..21)
            .map(|i| [glam::Vec3::new(0.1 * i as f32, 1.0, 0.0); NUM_JOINTS])
            .collect();
        let m = Motion { frames, fps: 20.0 };
        let r = resample_cubic(&m, 30.0);
        assert_eq!((r.len(), r.fps), (31, 30.0));
        for (i, pose) in r.frames.iter().enumerate() {
            let want = 0.1 * i as f32 * 2.0 / 3.0;
            assert!(
                (pose[5].x - want).abs() < 1e-5,
                "frame {i}: {} vs {want}",
                pose[5].x
            );
        }
        // Every third 30 fps frame is an original frame.
        assert_eq!(r.frames[3][0], m.frames[2][0]);
    }

    #[test]
    fn empty_and_broken_motions_are_errors() {
        let opts = BvhExportOptions::default();
        assert!(matches!(
            bvh_string(&Motion::new(vec![]), &opts),
            Err(BvhExportError::Motion(_))
        ));
        let mut p = crate::skeleton::rest_pose();
        p[5] = p[2];
        let err = bvh_string(&Motion::new(vec![p]), &opts).unwrap_err();
        assert!(err.to_string().contains("zero length"), "{err}");
    }
}
