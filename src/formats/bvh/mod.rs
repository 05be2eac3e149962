//! BVH import: text → joint tree and channels → global positions → the 22 HumanML3D
//! joints in metres at 20 fps.
//!
//! | step | module | in → out |
//! | --- | --- | --- |
//! | text | [`text`] | bytes → checked UTF-8, tokens with lines |
//! | parse | [`parse`], [`hierarchy`], [`frames`] | text → [`Bvh`] |
//! | kinematics | [`fk`] | [`Bvh`] → global joint positions (file units) |
//! | retarget | [`rigs`], [`names`], [`retarget`] | joint names → [`JointMap`] → 22 joints |
//! | rest frame | [`tpose`] | a leading T-pose frame is dropped |
//! | units | [`units`] | leg length / up axis → metres, Y up |
//!
//! Entry points: [`import_bvh`] (a file) and [`import_bvh_str`] (text, for tests and
//! fuzzing). Errors name the input and line ([`BvhError`]).

pub mod error;
pub mod fk;
pub mod frames;
pub mod hierarchy;
pub mod names;
pub mod parse;
pub mod retarget;
pub mod rigs;
pub mod text;
pub mod tpose;
pub mod units;

#[cfg(test)]
mod tests;

pub use error::{BvhError, BvhErrorKind};
pub use parse::{Bvh, BvhJoint, Channel, ParseLimits, parse_bvh};
pub use retarget::{JointMap, JointSource};
pub use units::{Units, UpAxis};

use crate::motion::{Motion, Pose};
use crate::skeleton::FPS;
use std::path::Path;

/// How to import a BVH file.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BvhImportOptions {
    /// File length units (default: detect).
    pub units: Units,
    /// Which file axis is up (default: Y).
    pub up: UpAxis,
    /// Output frame rate (default: 20, mprog's rate).
    pub fps: f32,
    /// Size limits.
    pub limits: ParseLimits,
}

impl Default for BvhImportOptions {
    fn default() -> Self {
        BvhImportOptions {
            units: Units::Auto,
            up: UpAxis::Y,
            fps: FPS,
            limits: ParseLimits::default(),
        }
    }
}

/// An imported motion and how it was obtained.
#[derive(Clone, Debug, PartialEq)]
pub struct BvhImport {
    /// The 22 HumanML3D joints, metres, Y up, at [`BvhImportOptions::fps`].
    pub motion: Motion,
    /// Frame rate of the file.
    pub source_fps: f32,
    /// Frames in the file.
    pub source_frames: usize,
    /// Joint map: which rig was recognised and where each joint comes from.
    pub joint_map: JointMap,
    /// One readable line per HumanML3D joint (`left_hip ← UpperLeg_L`).
    pub joint_map_lines: Vec<String>,
    /// Metres per file unit.
    pub unit_scale: f32,
    /// True when [`unit_scale`](Self::unit_scale) was detected rather than given.
    pub units_detected: bool,
    /// Things the importer filled in or found odd.
    pub warnings: Vec<String>,
}

/// Imports a BVH file.
pub fn import_bvh(path: &Path, opts: &BvhImportOptions) -> Result<BvhImport, BvhError> {
    let origin = path.display().to_string();
    let io = |e: std::io::Error| BvhError::whole(&origin, BvhErrorKind::Io(e.to_string()));
    let size = std::fs::metadata(path).map_err(io)?.len();
    // Every value takes at least two bytes of text; a far bigger file cannot be valid.
    let limit = opts.limits.max_values.saturating_mul(24).max(1 << 20);
    if size > limit {
        return Err(BvhError::whole(
            &origin,
            BvhErrorKind::FileTooLarge { size, limit },
        ));
    }
    let bytes = std::fs::read(path).map_err(io)?;
    import_bvh_bytes(&origin, &bytes, opts)
}

/// Imports BVH bytes; `origin` names them in errors.
pub fn import_bvh_bytes(
    origin: &str,
    bytes: &[u8],
    opts: &BvhImportOptions,
) -> Result<BvhImport, BvhError> {
    let text = text::decode(origin, bytes)?;
    import_bvh_str(origin, text, opts)
}

/// Imports BVH text; `origin` names it in errors.
pub fn import_bvh_str(
    origin: &str,
    text: &str,
    opts: &BvhImportOptions,
) -> Result<BvhImport, BvhError> {
    let bvh = parse_bvh(origin, text, opts.limits)?;
    import_parsed(origin, bvh, opts)
}

/// Imports a parsed (or built, see [`crate::formats::asf`]) skeleton and motion.
pub fn import_parsed(
    origin: &str,
    mut bvh: Bvh,
    opts: &BvhImportOptions,
) -> Result<BvhImport, BvhError> {
    if !(opts.fps.is_finite() && opts.fps > 0.0) {
        return Err(BvhError::whole(
            origin,
            BvhErrorKind::BadOption(format!("output fps must be positive, got {}", opts.fps)),
        ));
    }
    if let Some(s) = opts.units.scale()
        && !(s.is_finite() && s > 0.0)
    {
        return Err(BvhError::whole(
            origin,
            BvhErrorKind::BadOption(format!("unit scale must be positive, got {s}")),
        ));
    }
    let end_site_notes = rigs::complete_end_sites(&mut bvh);
    let joint_map = retarget::map_joints(&bvh).map_err(|kind| BvhError::whole(origin, kind))?;
    // cgspeed's CMU files (and other MotionBuilder exports) start with a T-pose frame.
    let skip = tpose::leading_tpose_frames(&bvh, &joint_map, opts.up);
    let source_fps = bvh.fps();
    // A long frame time makes many output frames from few lines: bound what FK allocates.
    let kept = bvh.frame_count - skip;
    let out_values = fk::sample_count(kept, source_fps, opts.fps) * (bvh.joints.len() * 3) as f64;
    if out_values > opts.limits.max_values as f64 {
        let kind = BvhErrorKind::TooBig {
            what: "frames after resampling × joints × 3",
            count: out_values.min(u64::MAX as f64) as u64,
            limit: opts.limits.max_values,
        };
        return Err(BvhError::whole(origin, kind));
    }
    // Resampled on the channels, so bones stay rigid (see `fk`).
    let samples: Vec<fk::SamplePoint> = fk::sample_points(kept, source_fps, opts.fps)
        .into_iter()
        .map(|p| fk::SamplePoint {
            i0: p.i0 + skip,
            i1: p.i1 + skip,
            t: p.t,
        })
        .collect();
    let globals = fk::global_positions_at(&bvh, &samples);
    let joint_count = bvh.joints.len();
    let file_poses: Vec<Pose> = globals
        .chunks_exact(joint_count)
        .map(|g| joint_map.pose(g))
        .collect();

    let mut warnings = end_site_notes;
    warnings.extend(joint_map.warnings.iter().cloned());
    if skip > 0 {
        warnings.push(format!(
            "dropped {skip} leading T-pose frame(s) of {}",
            bvh.frame_count
        ));
    }
    let (unit_scale, units_detected) = match opts.units.scale() {
        Some(s) => (s, false),
        None => {
            let step = (file_poses.len() / 16).max(1);
            let sample: Vec<Pose> = file_poses.iter().step_by(step).copied().collect();
            let (scale, from) = units::detect_scale(&sample);
            if from == units::ScaleFrom::LegLength {
                warnings.push(format!(
                    "no standard unit gives a human leg: scaled to a {} m leg ({scale:.5} m per file unit)",
                    units::TYPICAL_LEG
                ));
            }
            (scale, true)
        }
    };
    let body = units::body_path_length(&file_poses[0]) * unit_scale;
    if !(0.5..=3.0).contains(&body) {
        warnings.push(format!(
            "unusual body size: ankle-to-head bone path is {body:.2} m at {unit_scale} m per file unit; check the units"
        ));
    }
    let frames: Vec<Pose> = file_poses
        .iter()
        .map(|pose| pose.map(|p| opts.up.to_y_up(p) * unit_scale))
        .collect();
    // Finite values can still add up to ∞ along a chain of joints (or make the unit
    // detection meaningless): refuse rather than hand out non-finite positions.
    if let Some((f, j)) = frames
        .iter()
        .enumerate()
        .find_map(|(f, pose)| pose.iter().position(|p| !p.is_finite()).map(|j| (f, j)))
    {
        let kind = BvhErrorKind::NonFinitePosition {
            frame: samples.get(f).map_or(f, |s| s.i0) + 1,
            joint: crate::skeleton::JOINT_NAMES[j],
        };
        return Err(BvhError::whole(origin, kind));
    }
    let motion = Motion {
        frames,
        fps: opts.fps,
    };
    Ok(BvhImport {
        motion,
        source_fps,
        source_frames: bvh.frame_count,
        joint_map_lines: joint_map.describe(&bvh),
        joint_map,
        unit_scale,
        units_detected,
        warnings,
    })
}
