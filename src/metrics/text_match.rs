//! How well a motion matches its prompts, by the learned evaluator ([`Evaluator`]): the
//! cosine similarity of the motion's embedding and the prompt's (both unit vectors; 1 is
//! a perfect match). `mprog score` reports it per prompt span.
//!
//! The evaluator reads at most `max_frames` feature frames (196, 9.8 s), so a span longer
//! than that is scored **in windows**: windows of `max_frames` frames, the first starting
//! at the span's start and the last ending at its end, evenly spaced at most half a window
//! apart (so neighbours overlap by at least half a window), and the span's similarity is
//! the mean over its windows. A span of at most `max_frames` frames is one window. Each span of a timeline is scored
//! against its own prompt, and, where the timeline has several prompts, against each of
//! them, which names the prompt the span looks most like.

use super::error::MetricsError;
use super::evaluator::Evaluator;
use crate::features::{ExtractOptions, extract};
use crate::motion::Motion;
use burn::prelude::*;
use std::ops::Range;

/// A prompt over frames `from..to` (half-open) of one person.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct PromptSpan {
    /// Index of the person.
    pub person: usize,
    /// First frame.
    pub from: usize,
    /// One past the last frame.
    pub to: usize,
    /// The prompt.
    pub prompt: String,
}

/// The evaluator's verdict on one span.
#[derive(Clone, Debug, PartialEq)]
pub struct SpanMatch {
    /// The span (cut to the motion).
    pub span: PromptSpan,
    /// Mean cosine similarity to its prompt over the windows; `None` when the evaluator
    /// knows no word of the prompt.
    pub similarity: Option<f32>,
    /// Windows it was scored in.
    pub windows: usize,
    /// Of the timeline's distinct prompts (when there are several), the one the span
    /// matches best, with its similarity.
    pub closest: Option<(String, f32)>,
    /// Words of the prompt the evaluator does not know (left out of its embedding).
    pub unknown_words: Vec<String>,
}

/// Windows of `window` frames over `len` frames: the first at 0, the last ending at `len`,
/// evenly spaced at most `window / 2` apart; one window `0..len` when `len ≤ window`.
pub fn windows(len: usize, window: usize) -> Vec<Range<usize>> {
    let window = window.max(1);
    if len <= window {
        return std::iter::once(0..len).collect();
    }
    let (room, hop) = (len - window, (window / 2).max(1));
    let n = room.div_ceil(hop) + 1;
    (0..n)
        .map(|k| {
            let s = (k * room + (n - 1) / 2) / (n - 1);
            s..s + window
        })
        .collect()
}

/// Scores every span of `spans` against its prompt (and the others' prompts) on
/// `people`'s motions. Spans are cut to their person's motion; one left with fewer than
/// two frames, or naming a person who is not there, is an error.
pub fn text_match(
    evaluator: &Evaluator,
    people: &[Motion],
    spans: &[PromptSpan],
    device: &Device,
) -> Result<Vec<SpanMatch>, MetricsError> {
    let width = evaluator.manifest.config.features;
    let window = evaluator.manifest.config.max_frames;
    let mut features: Vec<Option<Vec<f32>>> = vec![None; people.len()];
    let mut prompts: Vec<&str> = Vec::new();
    for s in spans {
        if !prompts.contains(&s.prompt.as_str()) {
            prompts.push(&s.prompt);
        }
    }
    let unknown: Vec<(bool, Vec<String>)> = prompts
        .iter()
        .map(|p| {
            let (ids, unknown) = evaluator.vocab.tokenize(p);
            (!ids.is_empty(), unknown)
        })
        .collect();
    let texts = evaluator.embed_captions(&prompts, device)?;
    let mut out = Vec::with_capacity(spans.len());
    for s in spans {
        let Some(motion) = people.get(s.person) else {
            return Err(MetricsError::Invalid(format!(
                "a prompt span names person {} but the motion holds {}",
                s.person + 1,
                people.len()
            )));
        };
        let rows = match &features[s.person] {
            Some(f) => f,
            None => {
                let f = extract(motion, &ExtractOptions::default())?.into_vec();
                features[s.person].insert(f)
            }
        };
        // Feature row t reads frames t and t + 1: a span of frames from..to has the rows
        // from..to − 1 (the motion's last frame has none of its own).
        let total = rows.len() / width;
        let (from, to) = (s.from.min(total), s.to.min(total + 1).saturating_sub(1));
        if to < from + 1 || s.to.min(motion.len()) < s.from + 2 {
            return Err(MetricsError::Invalid(format!(
                "prompt span {}..{} of person {} (\"{}\") has fewer than 2 frames of the motion's {}",
                s.from,
                s.to,
                s.person + 1,
                s.prompt,
                motion.len()
            )));
        }
        let parts: Vec<&[f32]> = windows(to - from, window)
            .into_iter()
            .map(|w| &rows[(from + w.start) * width..(from + w.end) * width])
            .collect();
        let embedded = evaluator.embed_motions(&parts, device)?;
        let mean_sim = |text: &[f32]| {
            embedded
                .iter()
                .map(|m| m.iter().zip(text).map(|(a, b)| a * b).sum::<f32>())
                .sum::<f32>()
                / embedded.len() as f32
        };
        let sims: Vec<Option<f32>> = texts
            .iter()
            .zip(&unknown)
            .map(|(t, (known, _))| known.then(|| mean_sim(t)))
            .collect();
        let own = prompts
            .iter()
            .position(|p| *p == s.prompt)
            .unwrap_or_default();
        let closest = (prompts.len() > 1)
            .then(|| {
                sims.iter()
                    .zip(&prompts)
                    .filter_map(|(v, p)| v.map(|v| (p.to_string(), v)))
                    .max_by(|a, b| a.1.total_cmp(&b.1))
            })
            .flatten();
        out.push(SpanMatch {
            span: PromptSpan {
                from: s.from,
                to: s.to.min(motion.len()),
                ..s.clone()
            },
            similarity: sims[own],
            windows: parts.len(),
            closest,
            unknown_words: unknown[own].1.clone(),
        });
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn windows_span_the_motion_at_most_half_a_window_apart() {
        assert_eq!(windows(150, 196), vec![0..150]);
        assert_eq!(windows(196, 196), vec![0..196]);
        assert_eq!(windows(200, 196), vec![0..196, 4..200]);
        let w = windows(599, 196);
        assert_eq!(
            w,
            vec![0..196, 81..277, 161..357, 242..438, 322..518, 403..599]
        );
        assert!(w.iter().all(|r| r.len() == 196));
        assert!(w.windows(2).all(|p| p[1].start - p[0].start <= 98));
        assert!((0..599).all(|f| w.iter().any(|r| r.contains(&f))));
    }
}
