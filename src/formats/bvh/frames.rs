//! The MOTION section: `Frames:`, `Frame Time:` and one line of channel values per frame.
//!
//! In: all lines of the file, the index of the first line after `MOTION`, the channel
//! count from the hierarchy. Out: the frame time and a flat `[frames, channels]` array.
//! Checked: header syntax, sizes against [`ParseLimits`], values per line, finiteness,
//! and that the number of frame lines equals `Frames:`.

use super::error::{BvhError, BvhErrorKind};
use super::parse::ParseLimits;
use super::text::parse_number;

/// The parsed MOTION section.
pub struct MotionSection {
    pub frame_time: f32,
    pub frame_count: usize,
    pub values: Vec<f32>,
}

/// Parses the MOTION section starting at `lines[start]` (0-based index).
pub fn parse_motion(
    origin: &str,
    lines: &[&str],
    start: usize,
    channel_count: usize,
    limits: ParseLimits,
) -> Result<MotionSection, BvhError> {
    let err = |index: usize, kind| BvhError::at(origin, index + 1, kind);
    let mut rows = lines
        .iter()
        .enumerate()
        .skip(start)
        .filter(|(_, l)| !l.trim().is_empty());

    let last = lines.len().saturating_sub(1);
    let (frames_at, frames_text) = header(origin, &mut rows, "Frames", last)?;
    let frame_count: u64 = frames_text
        .parse()
        .map_err(|_| err(frames_at, BvhErrorKind::BadFrameCount(frames_text.clone())))?;
    if frame_count == 0 {
        return Err(err(frames_at, BvhErrorKind::ZeroFrames));
    }
    let value_count = frame_count.saturating_mul(channel_count as u64);
    if value_count > limits.max_values {
        let kind = BvhErrorKind::TooBig {
            what: "frames × channels",
            count: value_count,
            limit: limits.max_values,
        };
        return Err(err(frames_at, kind));
    }
    let frame_count = frame_count as usize;

    let (time_at, time_text) = header(origin, &mut rows, "Frame Time", last)?;
    let frame_time = match time_text.parse::<f32>() {
        Ok(t) if t.is_finite() && t > 0.0 => t,
        _ => return Err(err(time_at, BvhErrorKind::BadFrameTime(time_text))),
    };

    // Reserve no more than the text can hold, whatever `Frames:` claims.
    let mut values =
        Vec::with_capacity(value_count.min((lines.len() * channel_count) as u64) as usize);
    let mut frames_read = 0;
    for (index, line) in rows {
        if frames_read == frame_count {
            return Err(err(
                index,
                BvhErrorKind::ExtraFrames {
                    declared: frame_count,
                },
            ));
        }
        let before = values.len();
        for word in line.split_ascii_whitespace() {
            values.push(parse_number(word).map_err(|kind| err(index, kind))?);
        }
        let found = values.len() - before;
        if found != channel_count {
            return Err(err(
                index,
                BvhErrorKind::ValueCount {
                    found,
                    expected: channel_count,
                },
            ));
        }
        frames_read += 1;
    }
    if frames_read < frame_count {
        let kind = BvhErrorKind::MissingFrames {
            found: frames_read,
            declared: frame_count,
        };
        return Err(err(last, kind));
    }
    Ok(MotionSection {
        frame_time,
        frame_count,
        values,
    })
}

/// Reads `Name: value` (the colon may be glued or spaced, any case) from the next
/// non-blank line; `name` is the header without its colon.
fn header<'a>(
    origin: &str,
    rows: &mut impl Iterator<Item = (usize, &'a &'a str)>,
    name: &'static str,
    last_index: usize,
) -> Result<(usize, String), BvhError> {
    let missing = BvhErrorKind::MissingHeader(name);
    let Some((index, line)) = rows.next() else {
        return Err(BvhError::at(origin, last_index + 1, missing));
    };
    let joined = line.split_whitespace().collect::<Vec<_>>().join(" ");
    let value = joined
        .get(..name.len())
        .filter(|head| head.eq_ignore_ascii_case(name))
        .and_then(|_| joined[name.len()..].trim_start().strip_prefix(':'));
    match value {
        Some(v) => Ok((index, v.trim().to_string())),
        None => Err(BvhError::at(origin, index + 1, missing)),
    }
}
