//! Questions of the coverage set: the pose that comes nearest (by a score the caller
//! computes per pose variant) and the longest run of training frames whose poses all
//! pass a test (how long the data holds a pose).

use super::{Coverage, NO_POSE};

/// A run of consecutive frames of one training clip.
#[derive(Clone, Debug, PartialEq)]
pub struct Run {
    /// Its length in frames (20 fps).
    pub frames: usize,
    /// The clip's index in [`Coverage::clips`].
    pub clip: usize,
    /// The clip's name (`…_mirror` when read mirrored).
    pub name: String,
    /// Its first frame.
    pub start: usize,
    /// The run is the whole clip: the pose is held as long as it was recorded.
    pub whole_clip: bool,
}

/// The index and score of the smallest finite score.
pub fn nearest(scores: &[f32]) -> Option<(usize, f32)> {
    scores
        .iter()
        .copied()
        .enumerate()
        .filter(|(_, s)| s.is_finite())
        .min_by(|a, b| a.1.total_cmp(&b.1))
}

impl Coverage {
    /// The longest run of consecutive frames, in any clip read as stored or mirrored,
    /// whose poses all pass: `ok[v]` for variant `v` ([`Coverage::variant`]). None when
    /// no frame passes.
    pub fn longest_run(&self, ok: &[bool]) -> Option<Run> {
        let n = self.poses.len();
        let sides = if self.mirrored { 2 } else { 1 };
        let mut best: Option<Run> = None;
        for (c, clip) in self.clips.iter().enumerate() {
            for side in 0..sides {
                let mut start = 0;
                for t in 0..=clip.frames.len() {
                    let pass = clip.frames.get(t).is_some_and(|&p| {
                        p != NO_POSE && ok.get(p as usize + side * n).copied().unwrap_or(false)
                    });
                    if pass {
                        continue;
                    }
                    let len = t - start;
                    if len > 0 && best.as_ref().is_none_or(|b| len > b.frames) {
                        best = Some(Run {
                            frames: len,
                            clip: c,
                            name: if side == 1 {
                                format!("{}_mirror", clip.name)
                            } else {
                                clip.name.clone()
                            },
                            start,
                            whole_clip: len == clip.frames.len(),
                        });
                    }
                    start = t + 1;
                }
            }
        }
        best
    }
}

#[cfg(test)]
mod tests {
    use super::super::{Clip, Coverage, NO_POSE};

    #[test]
    fn runs_are_found_on_either_side_and_break_at_missing_frames() {
        let rest = crate::skeleton::rest_pose().map(|v| [v.x, v.y, v.z]);
        let clips = vec![
            Clip {
                name: "a".into(),
                caption: String::new(),
                frames: vec![0, 1, 1, 1, NO_POSE, 1, 0],
            },
            Clip {
                name: "b".into(),
                caption: String::new(),
                frames: vec![0, 0],
            },
        ];
        let c = Coverage::new("t".into(), 0.04, true, vec![rest, rest], clips);
        // Pose 1 as stored: frames 1..4 of "a".
        let r = c.longest_run(&[false, true, false, false]).unwrap();
        assert_eq!(
            (r.frames, r.start, r.name.as_str(), r.whole_clip),
            (3, 1, "a", false)
        );
        // Pose 0 mirrored: the whole of "b".
        let r = c.longest_run(&[false, false, true, false]).unwrap();
        assert_eq!(
            (r.frames, r.name.as_str(), r.whole_clip),
            (2, "b_mirror", true)
        );
        assert!(c.longest_run(&[false; 4]).is_none());
        assert_eq!(super::nearest(&[3.0, f32::NAN, 1.0]), Some((2, 1.0)));
    }
}
