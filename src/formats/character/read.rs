//! Reading a rig file: its HIERARCHY only (the MOTION section, if any, is not read).
//!
//! In: a path (or text, for tests). Out: the joints as the BVH parser gives them (names,
//! parents, offsets in file units, channels, End Sites, lines). Untrusted input: the file
//! must be a `.bvh`, its hierarchy at most [`MAX_HIERARCHY_BYTES`], UTF-8 text; every
//! syntax error is the BVH parser's located error.

use super::error::{RigError, RigErrorKind};
use crate::formats::bvh::{BvhJoint, hierarchy, rigs, text};
use std::io::Read;
use std::path::Path;

/// Largest hierarchy read (a 100-joint rig is about 10 kB).
pub const MAX_HIERARCHY_BYTES: u64 = 16 << 20;

/// The joints of the rig file at `path`.
pub fn read_rig_file(path: &Path) -> Result<Vec<BvhJoint>, RigError> {
    let origin = path.display().to_string();
    let ext = path
        .extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase())
        .unwrap_or_default();
    if ext != "bvh" {
        return Err(RigError::whole(&origin, RigErrorKind::NotBvh(ext)));
    }
    let io = |e: std::io::Error| RigError::whole(&origin, RigErrorKind::Io(e.to_string()));
    let file = std::fs::File::open(path).map_err(io)?;
    let mut bytes = Vec::new();
    file.take(MAX_HIERARCHY_BYTES + 1)
        .read_to_end(&mut bytes)
        .map_err(io)?;
    let cut = motion_start(&bytes);
    if cut.is_none() && bytes.len() as u64 > MAX_HIERARCHY_BYTES {
        return Err(RigError::whole(
            &origin,
            RigErrorKind::TooLarge {
                limit: MAX_HIERARCHY_BYTES,
            },
        ));
    }
    bytes.truncate(cut.unwrap_or(bytes.len()));
    let text = text::decode(&origin, &bytes).map_err(|e| from_bvh(&origin, e))?;
    rig_joints(&origin, text)
}

/// The joints of rig text (the hierarchy, with or without a MOTION section).
pub fn rig_joints(origin: &str, text: &str) -> Result<Vec<BvhJoint>, RigError> {
    let lines: Vec<&str> = text.lines().collect();
    let end = lines
        .iter()
        .position(|l| l.trim() == "MOTION")
        .unwrap_or(lines.len());
    let joints =
        hierarchy::parse_hierarchy(origin, &lines[..end]).map_err(|e| from_bvh(origin, e))?;
    let mut bvh = crate::formats::bvh::Bvh {
        joints,
        channel_count: 0,
        frame_time: 1.0,
        frame_count: 0,
        values: Vec::new(),
    };
    // DeepMimic-style rigs write some End Sites as zero: give them the model's offsets.
    rigs::complete_end_sites(&mut bvh);
    Ok(bvh.joints)
}

/// Byte offset of the line `MOTION`, if there is one.
fn motion_start(bytes: &[u8]) -> Option<usize> {
    let mut at = 0;
    for line in bytes.split(|&b| b == b'\n') {
        if line.trim_ascii() == b"MOTION" {
            return Some(at);
        }
        at += line.len() + 1;
    }
    None
}

fn from_bvh(origin: &str, e: crate::formats::bvh::BvhError) -> RigError {
    RigError {
        origin: origin.to_string(),
        line: e.line,
        kind: RigErrorKind::Parse(e.kind.to_string()),
    }
}
