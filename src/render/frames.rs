//! Which frames a render shows: the clip range option, the GIF's subsampled frame list with
//! each frame's display time, and the strip's evenly spaced or explicit frames.

use super::error::RenderError;
use super::options::{RenderOptions, StripFrames};
use std::ops::Range;

/// The frames the options allow, checked against a clip of `len` frames.
pub(crate) fn clip_range(len: usize, opts: &RenderOptions) -> Result<Range<usize>, RenderError> {
    match &opts.frame_range {
        None => Ok(0..len),
        Some(r) if r.start >= r.end => Err(RenderError::BadOption(format!(
            "frame range {}..{} is empty",
            r.start, r.end
        ))),
        Some(r) if r.end > len => Err(RenderError::FrameOutOfRange {
            frame: r.end - 1,
            len,
        }),
        Some(r) => Ok(r.clone()),
    }
}

/// GIF frames: every `frame_step`-th frame of the range.
pub(crate) fn gif_frames(len: usize, opts: &RenderOptions) -> Result<Vec<usize>, RenderError> {
    if opts.frame_step == 0 {
        return Err(RenderError::BadOption(
            "frame_step must be at least 1".into(),
        ));
    }
    Ok(clip_range(len, opts)?.step_by(opts.frame_step).collect())
}

/// Display time of each GIF frame in hundredths of a second, so that the animation keeps
/// real time: rounding errors do not accumulate, and the last frame lasts one step.
pub(crate) fn gif_delays(frames: &[usize], fps: f32, step: usize) -> Result<Vec<u16>, RenderError> {
    let cs = |f: usize| (f as f64 * 100.0 / f64::from(fps)).round() as i64;
    let mut delays = Vec::with_capacity(frames.len());
    for (k, &f) in frames.iter().enumerate() {
        let next = frames.get(k + 1).copied().unwrap_or(f + step);
        let d = cs(next) - cs(f);
        // Viewers replace delays under 2 cs with 10 cs, which would slow the clip down.
        if d < 2 {
            return Err(RenderError::BadOption(format!(
                "at {fps} fps a frame_step of {step} gives GIF frames shorter than 20 ms; raise frame_step"
            )));
        }
        delays.push(u16::try_from(d).unwrap_or(u16::MAX));
    }
    Ok(delays)
}

/// Most cells a strip draws (more would shrink each figure to a few pixels).
pub(crate) const MAX_STRIP_FRAMES: usize = 64;

/// Strip frames: the explicit list, or `count` evenly spaced frames of the range with the
/// first and last included.
pub(crate) fn strip_frames(len: usize, opts: &RenderOptions) -> Result<Vec<usize>, RenderError> {
    let range = clip_range(len, opts)?;
    let too_many =
        |n: usize| RenderError::BadOption(format!("{n} strip frames; at most {MAX_STRIP_FRAMES}"));
    match &opts.strip_frames {
        StripFrames::Indices(list) if list.len() > MAX_STRIP_FRAMES => Err(too_many(list.len())),
        StripFrames::Count(k) if *k > MAX_STRIP_FRAMES => Err(too_many(*k)),
        StripFrames::Indices(list) => {
            if list.is_empty() {
                return Err(RenderError::BadOption("strip frame list is empty".into()));
            }
            match list.iter().find(|&&f| f >= len) {
                Some(&frame) => Err(RenderError::FrameOutOfRange { frame, len }),
                None => Ok(list.clone()),
            }
        }
        StripFrames::Count(0) => Err(RenderError::BadOption(
            "strip needs at least 1 frame".into(),
        )),
        StripFrames::Count(k) => {
            let n = range.len();
            let k = (*k).min(n);
            if k == 1 {
                return Ok(vec![range.start]);
            }
            Ok((0..k)
                .map(|i| range.start + (i * (n - 1) + (k - 1) / 2) / (k - 1))
                .collect())
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn opts() -> RenderOptions {
        RenderOptions::default()
    }

    #[test]
    fn gif_frames_step_through_the_range() {
        let o = RenderOptions {
            frame_step: 3,
            frame_range: Some(2..11),
            ..opts()
        };
        assert_eq!(gif_frames(20, &o).unwrap(), vec![2, 5, 8]);
        assert!(gif_frames(10, &o).is_err());
        assert!(
            gif_frames(
                20,
                &RenderOptions {
                    frame_step: 0,
                    ..opts()
                }
            )
            .is_err()
        );
        let empty = RenderOptions {
            frame_range: Some(4..4),
            ..opts()
        };
        assert!(gif_frames(20, &empty).is_err());
    }

    #[test]
    fn delays_keep_real_time() {
        assert_eq!(gif_delays(&[0, 2, 4], 20.0, 2).unwrap(), vec![10, 10, 10]);
        // 30 fps: 3.33 cs per frame; the total stays exact.
        let d = gif_delays(&[0, 1, 2, 3, 4, 5], 30.0, 1).unwrap();
        assert_eq!(d.iter().map(|&x| u32::from(x)).sum::<u32>(), 20);
        assert!(gif_delays(&[0, 1], 120.0, 1).is_err());
    }

    #[test]
    fn strip_frames_are_evenly_spaced_with_both_ends() {
        assert_eq!(
            strip_frames(200, &opts()).unwrap(),
            vec![0, 28, 57, 85, 114, 142, 171, 199]
        );
        assert_eq!(strip_frames(3, &opts()).unwrap(), vec![0, 1, 2]);
        assert_eq!(strip_frames(1, &opts()).unwrap(), vec![0]);
        let list = RenderOptions {
            strip_frames: StripFrames::Indices(vec![5, 1]),
            ..opts()
        };
        assert_eq!(strip_frames(10, &list).unwrap(), vec![5, 1]);
        assert!(matches!(
            strip_frames(5, &list),
            Err(RenderError::FrameOutOfRange { frame: 5, len: 5 })
        ));
        let zero = RenderOptions {
            strip_frames: StripFrames::Count(0),
            ..opts()
        };
        assert!(strip_frames(10, &zero).is_err());
        let many = RenderOptions {
            strip_frames: StripFrames::Count(MAX_STRIP_FRAMES + 1),
            ..opts()
        };
        assert!(strip_frames(1000, &many).is_err());
    }
}
