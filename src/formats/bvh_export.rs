//! BVH export of the 22-joint skeleton: in, a [`Motion`] (global joint positions); out, a BVH
//! file whose forward kinematics reproduces those positions.
//!
//! * HIERARCHY and rotations: the export rig ([`super::rig`]): the 22 HumanML3D joints with
//!   their names, offsets = rest direction × the motion's own bone length (mean over
//!   frames), zero-offset connector joints where bones branch, rotations solved from the
//!   positions.
//! * Channels: the root has `Xposition Yposition Zposition Zrotation Yrotation Xrotation`,
//!   every other joint `Zrotation Yrotation Xrotation` (local rotation = Rz·Ry·Rx, degrees).
//!   The root OFFSET is zero: its position channels are absolute.
//! * Frame time = 1/fps; [`BvhExportOptions::fps`] resamples the joint positions to another
//!   rate (e.g. 30 or 60 for animation tools) before the rotations are solved, by
//!   Catmull–Rom interpolation: it follows curved joint paths, so bones keep their length
//!   (straight-line interpolation shortens a fast forearm by centimetres). Units metres (or centimetres), axes Y up (or Blender's Z up:
//!   (x, y, z) ↦ (x, −z, y)). A `#` comment after the `HIERARCHY` line states units, axes
//!   and fps; Blender's importer skips it (it only looks for keywords there).

use super::rig::{self, Node};
use crate::features::FeatureError;
use crate::features::kinematics::{self, Pose64};
use crate::fsutil::write_atomic;
use crate::motion::Motion;
use crate::skeleton::NUM_JOINTS;
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
    let poses = kinematics::poses_f64(m)?;
    let writer = Writer {
        nodes: rig::hierarchy(),
        lengths: rig::mean_bone_lengths(&poses),
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
    /// `fraction` × the rest offset of `node`, in file units and axes.
    fn offset(&self, node: &Node, fraction: f64) -> DVec3 {
        self.axes * rig::rest_offset(node, &self.lengths) * (fraction * self.scale)
    }

    /// Writes the HIERARCHY entry of node `id` and its subtree.
    fn node(&self, out: &mut String, id: usize, depth: usize) {
        let pad = "  ".repeat(depth);
        let node = &self.nodes[id];
        let o = self.offset(node, 1.0);
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
            let e = self.offset(node, 0.5);
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
        let root = self.axes * pose[0] * self.scale;
        let _ = write!(out, "{:.6} {:.6} {:.6}", root.x, root.y, root.z);
        for local in rig::local_rotations(&self.nodes, pose, frame, self.axes)? {
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
