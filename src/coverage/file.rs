//! The coverage file: `MPROGCOV`, a little-endian u32 header length, a JSON header (what
//! it was built from, the cover distance, whether poses are read mirrored, the clips'
//! names, captions and frame counts), then every pose as 22 × (x, y, z) bytes (x and z
//! relative to the pelvis as i8 in steps of 1.5 cm, ±1.9 m; the height as u8 in steps of
//! 1.2 cm from −0.1 m to 2.96 m; each coordinate within 0.75 cm), then every clip's
//! per-frame pose indices (u16, or u32 when there are 65,535 poses or more; all ones is a
//! frame with no pose).

use super::{Clip, Coverage, NO_POSE, Pose};
use crate::skeleton::NUM_JOINTS;
use serde::{Deserialize, Serialize};
use std::path::Path;

const MAGIC: &[u8; 8] = b"MPROGCOV";
/// Version of the layout; bumped when a field changes meaning.
pub const COVERAGE_VERSION: u32 = 1;
/// One step of a stored ground coordinate (m).
const GROUND_STEP: f32 = 0.015;
/// One step of a stored height (m).
const HEIGHT_STEP: f32 = 0.012;
/// The lowest stored height (m).
const HEIGHT_FLOOR: f32 = -0.1;
/// Bytes of one pose.
const POSE_BYTES: usize = NUM_JOINTS * 3;

fn ground_byte(v: f32) -> u8 {
    ((v / GROUND_STEP).round().clamp(-127.0, 127.0) as i8) as u8
}

fn height_byte(v: f32) -> u8 {
    ((v - HEIGHT_FLOOR) / HEIGHT_STEP).round().clamp(0.0, 255.0) as u8
}

fn ground_of(b: u8) -> f32 {
    f32::from(b as i8) * GROUND_STEP
}

fn height_of(b: u8) -> f32 {
    f32::from(b) * HEIGHT_STEP + HEIGHT_FLOOR
}

#[derive(Serialize, Deserialize)]
struct Header {
    version: u32,
    source: String,
    cover: f32,
    mirrored: bool,
    poses: usize,
    index_bytes: usize,
    clips: Vec<ClipHeader>,
}

#[derive(Serialize, Deserialize)]
struct ClipHeader {
    name: String,
    caption: String,
    frames: usize,
}

/// The file's bytes.
pub fn encode(c: &Coverage) -> Vec<u8> {
    let index_bytes = if c.poses.len() < 0xFFFF { 2 } else { 4 };
    let header = Header {
        version: COVERAGE_VERSION,
        source: c.source.clone(),
        cover: c.cover,
        mirrored: c.mirrored,
        poses: c.poses.len(),
        index_bytes,
        clips: c
            .clips
            .iter()
            .map(|k| ClipHeader {
                name: k.name.clone(),
                caption: k.caption.clone(),
                frames: k.frames.len(),
            })
            .collect(),
    };
    let json = serde_json::to_vec(&header).expect("header serialises");
    let mut out = Vec::with_capacity(json.len() + c.poses.len() * POSE_BYTES + c.frames() * 4);
    out.extend_from_slice(MAGIC);
    out.extend_from_slice(&(json.len() as u32).to_le_bytes());
    out.extend_from_slice(&json);
    for p in &c.poses {
        for [x, y, z] in p {
            out.extend_from_slice(&[ground_byte(*x), height_byte(*y), ground_byte(*z)]);
        }
    }
    for k in &c.clips {
        for &i in &k.frames {
            if index_bytes == 2 {
                let i = if i == NO_POSE { 0xFFFF } else { i as u16 };
                out.extend_from_slice(&i.to_le_bytes());
            } else {
                out.extend_from_slice(&i.to_le_bytes());
            }
        }
    }
    out
}

/// Reads a coverage file's bytes; Err says what is wrong.
pub fn decode(bytes: &[u8]) -> Result<Coverage, String> {
    let rest = bytes
        .strip_prefix(MAGIC)
        .ok_or("not a coverage file (no MPROGCOV mark)")?;
    let (len, rest) = rest.split_at_checked(4).ok_or("truncated header")?;
    let len = u32::from_le_bytes(len.try_into().expect("4 bytes")) as usize;
    let (json, mut body) = rest.split_at_checked(len).ok_or("truncated header")?;
    let h: Header = serde_json::from_slice(json).map_err(|e| format!("bad header: {e}"))?;
    if h.version != COVERAGE_VERSION {
        return Err(format!(
            "coverage version {} but this mprog reads {COVERAGE_VERSION}; build it again with `mprog data coverage`",
            h.version
        ));
    }
    if !(h.index_bytes == 2 || h.index_bytes == 4) || h.cover.is_nan() || h.cover < 0.0 {
        return Err("bad header: index width or cover distance".into());
    }
    let mut take = |n: usize| -> Result<&[u8], String> {
        let (a, b) = body
            .split_at_checked(n)
            .ok_or("the file is shorter than its header says")?;
        body = b;
        Ok(a)
    };
    let raw = take(h.poses.checked_mul(POSE_BYTES).ok_or("too many poses")?)?;
    let poses: Vec<Pose> = raw
        .chunks_exact(POSE_BYTES)
        .map(|p| {
            std::array::from_fn(|j| {
                let b = &p[3 * j..3 * j + 3];
                [ground_of(b[0]), height_of(b[1]), ground_of(b[2])]
            })
        })
        .collect();
    let mut clips = Vec::with_capacity(h.clips.len());
    for k in h.clips {
        let raw = take(
            k.frames
                .checked_mul(h.index_bytes)
                .ok_or("too many frames")?,
        )?;
        let frames: Vec<u32> = raw
            .chunks_exact(h.index_bytes)
            .map(|b| match b {
                [a, b] if u16::from_le_bytes([*a, *b]) == 0xFFFF => NO_POSE,
                [a, b] => u32::from(u16::from_le_bytes([*a, *b])),
                _ => u32::from_le_bytes(b.try_into().expect("4 bytes")),
            })
            .collect();
        if frames
            .iter()
            .any(|&i| i != NO_POSE && i as usize >= h.poses)
        {
            return Err(format!("clip {} names a pose past the last", k.name));
        }
        clips.push(Clip {
            name: k.name,
            caption: k.caption,
            frames,
        });
    }
    if !body.is_empty() {
        return Err("the file is longer than its header says".into());
    }
    Ok(Coverage::new(h.source, h.cover, h.mirrored, poses, clips))
}

/// Reads `path`.
pub fn load(path: &Path) -> Result<Coverage, String> {
    let bytes = std::fs::read(path).map_err(|e| format!("cannot read {}: {e}", path.display()))?;
    decode(&bytes).map_err(|e| format!("{}: {e}", path.display()))
}

/// Writes `c` to `path`, atomically.
pub fn save(c: &Coverage, path: &Path) -> std::io::Result<()> {
    crate::fsutil::write_bytes_atomic(path, &encode(c))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_set_round_trips_within_a_centimetre() {
        let rest = crate::skeleton::rest_pose().map(|v| [v.x, v.y, v.z]);
        let mut up = rest;
        up[20][1] = 2.1234;
        let c = Coverage::new(
            "test".into(),
            0.04,
            true,
            vec![rest, up],
            vec![Clip {
                name: "a".into(),
                caption: "stands".into(),
                frames: vec![0, 1, NO_POSE, 1],
            }],
        );
        let back = decode(&encode(&c)).unwrap();
        assert_eq!(back.clips, c.clips);
        assert_eq!(back.variants(), 4);
        for (a, b) in back.poses.iter().zip(&c.poses) {
            assert!(super::super::pose::joint_distance(a, b) < 0.011);
        }
        assert_eq!(back.origin(3).clip, "a_mirror");
        let bytes = encode(&c);
        assert!(decode(&bytes[..bytes.len() - 1]).is_err());
        assert!(decode(b"nothing").is_err());
    }

    #[test]
    fn the_builtin_set_reads() {
        let c = Coverage::builtin();
        assert!(c.poses.len() > 1000 && c.frames() > 100_000, "{}", c.source);
        assert!(c.mirrored);
    }
}
