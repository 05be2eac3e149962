//! The parsed content of a BVH file, before any kinematics.
//!
//! In: BVH text. Out: [`Bvh`]: the joint tree (names, parents, offsets, channels, End
//! Sites) and the motion as one flat `[frames, channels]` array of raw channel values
//! (file units, degrees). [`parse_bvh`] checks everything a later stage relies on, so FK
//! and retargeting cannot fail on a parsed file.

use super::error::{BvhError, BvhErrorKind};
use super::{frames, hierarchy};
use glam::Vec3;

/// A coordinate axis of a channel.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Axis {
    X,
    Y,
    Z,
}

/// One animated degree of freedom of a joint.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Channel {
    /// Translation along an axis, in file units; replaces that axis of the OFFSET.
    Position(Axis),
    /// Rotation about an axis, in degrees.
    Rotation(Axis),
}

impl Channel {
    /// Reads a channel name (`Xposition`, `Zrotation`, case-insensitive).
    pub fn from_name(name: &str) -> Option<Channel> {
        let lower = name.to_ascii_lowercase();
        let axis = match lower.as_bytes().first()? {
            b'x' => Axis::X,
            b'y' => Axis::Y,
            b'z' => Axis::Z,
            _ => return None,
        };
        match &lower[1..] {
            "position" => Some(Channel::Position(axis)),
            "rotation" => Some(Channel::Rotation(axis)),
            _ => None,
        }
    }
}

/// A joint of the hierarchy (or an End Site, which has no channels).
#[derive(Clone, Debug, PartialEq)]
pub struct BvhJoint {
    /// Name as written (End Sites are named `<parent> End Site`).
    pub name: String,
    /// Index of the parent joint; `None` for a ROOT.
    pub parent: Option<usize>,
    /// Rest offset from the parent, in file units.
    pub offset: Vec3,
    /// Channels in file order.
    pub channels: Vec<Channel>,
    /// Index of this joint's first channel within a frame's values.
    pub first_channel: usize,
    /// True for an End Site.
    pub end_site: bool,
    /// Line of the ROOT / JOINT / End keyword.
    pub line: usize,
}

/// A parsed BVH file. Joints are in file order, so every parent precedes its children.
#[derive(Clone, Debug, PartialEq)]
pub struct Bvh {
    pub joints: Vec<BvhJoint>,
    /// Channels per frame (the sum over joints).
    pub channel_count: usize,
    /// Seconds per frame, as written.
    pub frame_time: f32,
    /// Number of frames.
    pub frame_count: usize,
    /// `[frame_count, channel_count]` raw channel values.
    pub values: Vec<f32>,
}

impl Bvh {
    /// Channel values of one frame.
    pub fn frame(&self, index: usize) -> &[f32] {
        &self.values[index * self.channel_count..(index + 1) * self.channel_count]
    }

    /// Frames per second; snapped to the nearest integer when within 0.1 % of it,
    /// because frame times are written with few digits (`0.0333333`).
    pub fn fps(&self) -> f32 {
        let fps = 1.0 / self.frame_time;
        let rounded = fps.round();
        if rounded > 0.0 && ((fps - rounded) / rounded).abs() < 1e-3 {
            rounded
        } else {
            fps
        }
    }

    /// Index of the joint called `name` (End Sites excluded).
    pub fn joint_index(&self, name: &str) -> Option<usize> {
        self.joints
            .iter()
            .position(|j| !j.end_site && j.name == name)
    }
}

/// Size limits that protect against absurd or hostile inputs.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ParseLimits {
    /// Largest accepted `frames × channels` (each value takes 4 bytes in memory).
    pub max_values: u64,
}

impl Default for ParseLimits {
    fn default() -> Self {
        // 5·10⁷ values = 200 MB: an hour at 120 fps of a 115-channel rig. Bigger is refused.
        ParseLimits {
            max_values: 50_000_000,
        }
    }
}

/// Parses BVH text; `origin` names the input in error messages.
pub fn parse_bvh(origin: &str, text: &str, limits: ParseLimits) -> Result<Bvh, BvhError> {
    let lines: Vec<&str> = text.lines().collect();
    let motion_at = lines.iter().position(|l| l.trim() == "MOTION");
    let hierarchy_end = motion_at.unwrap_or(lines.len());
    let joints = hierarchy::parse_hierarchy(origin, &lines[..hierarchy_end])?;
    let channel_count: usize = joints.iter().map(|j| j.channels.len()).sum();
    if channel_count == 0 {
        return Err(BvhError::at(origin, 1, BvhErrorKind::NoChannels));
    }
    let Some(motion_at) = motion_at else {
        return Err(BvhError::at(
            origin,
            lines.len().max(1),
            BvhErrorKind::MissingMotion,
        ));
    };
    let motion = frames::parse_motion(origin, &lines, motion_at + 1, channel_count, limits)?;
    Ok(Bvh {
        joints,
        channel_count,
        frame_time: motion.frame_time,
        frame_count: motion.frame_count,
        values: motion.values,
    })
}
