//! Motions on the user's own character (`--rig character.bvh`): the output keeps the rig's
//! hierarchy, joint names, rest offsets, channels and rotation orders, units and up axis,
//! so it imports straight onto that character.
//!
//! | step | module | in → out |
//! | --- | --- | --- |
//! | read | [`read`], [`glb`] | a `.bvh` rig (untrusted) → its joints (the MOTION section is ignored); a skinned `.glb` → its skin's joints and the file, to animate |
//! | mapping file | [`usermap`] | `--rig-map` TOML → (joint, rig joint) entries |
//! | map | [`map`], [`guess`] | joints + entries → the rig joint of each HumanML3D joint, checked (errors suggest joints by name and by shape) |
//! | rest pose | here | offsets → rest positions in metres, Y up (units from the leg, up axis from the body) |
//! | plan | [`plan`] | what turns each joint: targets, legs, the joint that moves the body |
//! | solve | [`solve`], [`fit`] | a motion → a [`Posed`] of the rig (scaled by leg length, legs by IK) |
//! | write | [`write`] | a [`Posed`] of the rig → BVH text in the rig's units, axes and channels |
//!
//! The glTF writer takes the same [`Posed`] ([`crate::formats::gltf`]). Every failure is a
//! located [`RigError`]; nothing here panics on a rig file.

pub mod error;
pub mod fit;
pub mod glb;
pub mod guess;
pub mod map;
pub mod plan;
pub mod read;
pub mod solve;
pub mod usermap;
pub mod write;

pub use error::{RigError, RigErrorKind};

use super::bvh::units::{self, ScaleFrom};
use super::bvh::{BvhJoint, UpAxis};
use super::posed::Posed;
use crate::motion::Motion;
use crate::skeleton::{JOINT_NAMES, NUM_JOINTS};
use glam::{DQuat, DVec3, Vec3};
use plan::Plan;
use std::path::Path;

/// A user's rig, read, mapped and planned: ready to take motions.
#[derive(Clone, Debug, PartialEq)]
pub struct Character {
    /// The rig file, as named in messages.
    pub origin: String,
    /// Its joints (file units, file axes), in file order.
    pub joints: Vec<BvhJoint>,
    /// Which file axis is up.
    pub up: UpAxis,
    /// Metres per file unit.
    pub unit_scale: f64,
    /// `cm`, `m`, `mm` or `… m per unit`.
    pub units: String,
    /// Rig joint of each HumanML3D joint.
    pub map: [Option<usize>; NUM_JOINTS],
    /// How the map was made.
    pub mapped_by: String,
    /// What was guessed while reading and mapping.
    pub notes: Vec<String>,
    /// Rest offset of each joint from its parent, metres, Y up.
    pub offsets: Vec<DVec3>,
    /// Rest position of each joint, metres, Y up.
    pub rest: Vec<DVec3>,
    /// Hip–knee–ankle length, mean of both legs, metres.
    pub leg: f64,
    /// What drives each joint.
    pub plan: Plan,
    /// The `.glb` the rig came from: `.glb` outputs animate that file, mesh and all.
    pub glb: Option<Box<glb::GlbRig>>,
}

impl Character {
    /// Reads the rig at `path`, with the mapping file `map` if given.
    pub fn load(path: &Path, map: Option<&Path>) -> Result<Character, RigError> {
        let is_glb = path
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("glb"));
        let (joints, glb) = if is_glb {
            let (joints, rig) = glb::read_glb_rig_file(path)?;
            (joints, Some(Box::new(rig)))
        } else {
            (read::read_rig_file(path)?, None)
        };
        let origin = path.display().to_string();
        let entries = match map {
            Some(m) => {
                let map_origin = m.display().to_string();
                let text = std::fs::read_to_string(m)
                    .map_err(|e| RigError::whole(&map_origin, RigErrorKind::Io(e.to_string())))?;
                usermap::parse_map(&map_origin, &text, &joints)?
            }
            None => Vec::new(),
        };
        let mut ch = Character::build(&origin, joints, &entries)?;
        ch.glb = glb;
        Ok(ch)
    }

    /// A rig from `.glb` bytes (and a mapping file's text).
    pub fn from_glb(
        origin: &str,
        bytes: &[u8],
        map: Option<(&str, &str)>,
    ) -> Result<Character, RigError> {
        let (joints, rig) = glb::glb_rig(origin, bytes)?;
        let entries = match map {
            Some((map_origin, text)) => usermap::parse_map(map_origin, text, &joints)?,
            None => Vec::new(),
        };
        let mut ch = Character::build(origin, joints, &entries)?;
        ch.glb = Some(Box::new(rig));
        Ok(ch)
    }

    /// A rig from BVH text (and a mapping file's text): `(origin, text)` pairs.
    pub fn from_text(rig: (&str, &str), map: Option<(&str, &str)>) -> Result<Character, RigError> {
        let joints = read::rig_joints(rig.0, rig.1)?;
        let entries = match map {
            Some((origin, text)) => usermap::parse_map(origin, text, &joints)?,
            None => Vec::new(),
        };
        Character::build(rig.0, joints, &entries)
    }

    fn build(
        origin: &str,
        joints: Vec<BvhJoint>,
        entries: &[usermap::MapEntry],
    ) -> Result<Character, RigError> {
        let found = map::correspond(origin, &joints, entries)?;
        let m = |j: usize| found.map[j].expect("required joint");
        let mut raw: Vec<Vec3> = Vec::with_capacity(joints.len());
        for j in &joints {
            let p = j.parent.map_or(j.offset, |p| raw[p] + j.offset);
            if !p.is_finite() {
                return Err(RigError::at(
                    origin,
                    j.line,
                    RigErrorKind::NonFinite(j.name.clone()),
                ));
            }
            raw.push(p);
        }
        let up = up_axis(origin, &raw, &found.map)?;
        let mut legs = [Vec3::ZERO; NUM_JOINTS];
        for j in [1, 2, 4, 5, 7, 8] {
            legs[j] = raw[m(j)];
        }
        let (scale, from) = units::detect_scale(&[legs]);
        let scale = f64::from(scale);
        let mut notes = found.notes.clone();
        let units = match (from, scale) {
            (ScaleFrom::Unit, 1.0) => "m".to_string(),
            (ScaleFrom::Unit, s) if (s - 0.01).abs() < 1e-9 => "cm".to_string(),
            (ScaleFrom::Unit, _) => "mm".to_string(),
            (ScaleFrom::LegLength, s) => {
                notes.push(format!(
                    "no standard unit gives a human leg: read at {s:.5} m per unit (a {} m leg)",
                    units::TYPICAL_LEG
                ));
                format!("{s:.5} m per unit")
            }
        };
        let axes = axes_of(up);
        let offsets: Vec<DVec3> = joints
            .iter()
            .map(|j| axes * j.offset.as_dvec3() * scale)
            .collect();
        let mut rest: Vec<DVec3> = Vec::with_capacity(joints.len());
        for (i, j) in joints.iter().enumerate() {
            rest.push(j.parent.map_or(offsets[i], |p| rest[p] + offsets[i]));
        }
        let side = |h: usize, k: usize, a: usize| {
            rest[m(h)].distance(rest[m(k)]) + rest[m(k)].distance(rest[m(a)])
        };
        let leg = 0.5 * (side(1, 4, 7) + side(2, 5, 8));
        let plan = plan::plan(origin, &joints, &rest, &found.map)?;
        Ok(Character {
            origin: origin.to_string(),
            joints,
            up,
            unit_scale: scale,
            units,
            map: found.map,
            mapped_by: found.mapped_by,
            notes,
            offsets,
            rest,
            leg,
            plan,
            glb: None,
        })
    }

    /// File axes → mprog's (Y up).
    pub fn axes(&self) -> DQuat {
        axes_of(self.up)
    }

    /// One line: joints, how they were mapped, units, axes, leg length.
    pub fn summary(&self) -> String {
        let count = self.joints.iter().filter(|j| !j.end_site).count();
        let mapped = self.map.iter().flatten().count();
        let up = match self.up {
            UpAxis::Y => "Y up",
            UpAxis::Z => "Z up",
        };
        let glb = if self.glb.is_some() {
            "; .glb outputs are this file, its mesh and skin animated"
        } else {
            ""
        };
        format!(
            "rig {}: {count} joints, {mapped} of the 22 mapped ({}), units {}, {up}, leg {:.3} m; joints it has and mprog does not keep their rest pose{glb}",
            self.origin, self.mapped_by, self.units, self.leg
        )
    }

    /// One line per HumanML3D joint: `left_knee ← LeftLeg` or `left_collar ← (rest pose)`.
    pub fn map_lines(&self) -> Vec<String> {
        (0..NUM_JOINTS)
            .map(|j| match self.map[j] {
                Some(i) => format!("{} ← {}", JOINT_NAMES[j], self.joints[i].name),
                None => format!(
                    "{} ← (none: the rig keeps its rest pose there)",
                    JOINT_NAMES[j]
                ),
            })
            .collect()
    }

    /// `m` on this rig (see [`solve`]).
    pub fn retarget(&self, m: &Motion) -> Result<Posed, String> {
        solve::retarget(self, m)
    }
}

fn axes_of(up: UpAxis) -> DQuat {
    match up {
        UpAxis::Y => DQuat::IDENTITY,
        // File +Z becomes +Y, file +Y becomes −Z (as the BVH importer reads Z-up files).
        UpAxis::Z => DQuat::from_rotation_x(-std::f64::consts::FRAC_PI_2),
    }
}

/// Y or Z, whichever the body stands along in the rest pose (ankles to head).
fn up_axis(
    origin: &str,
    raw: &[Vec3],
    map: &[Option<usize>; NUM_JOINTS],
) -> Result<UpAxis, RigError> {
    let top = [15, 12, 9, 6, 3]
        .iter()
        .find_map(|&j| map[j])
        .expect("a spine joint is required");
    let feet = 0.5 * (raw[map[7].expect("required")] + raw[map[8].expect("required")]);
    let v = raw[top] - feet;
    let a = v.abs();
    if v.y > 0.0 && a.y >= a.x && a.y >= a.z {
        Ok(UpAxis::Y)
    } else if v.z > 0.0 && a.z >= a.x && a.z >= a.y {
        Ok(UpAxis::Z)
    } else {
        Err(RigError::whole(
            origin,
            RigErrorKind::NotUpright(v.normalize_or_zero().to_array()),
        ))
    }
}
