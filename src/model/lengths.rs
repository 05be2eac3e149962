//! The length prior: how long the training clips of each caption last, so that `mprog gen`
//! without `--seconds` makes a motion as long as the data's motions of the nearest known
//! captions (T2M's length estimator in its plainest form: a nearest-neighbour median, not a
//! learned regressor).
//!
//! It matters because a prompt's clips are all about one length: Bandai's runs last 2.6 s
//! (the capture volume ends), HDM05's kick takes 3 s. Asked for 6 s, the prior has never
//! seen a run that long and makes a 1.6 m/s jog; at its natural length it runs at 2.6 m/s.
//!
//! The rule: the captions whose cosine with the prompt is within [`MARGIN`] of the best
//! are the prompt's neighbours; the proposal is the median length of their training clips
//! (each caption's median, weighted by its clip count), clamped to `[MIN_FRAMES,
//! max_frames]`. Counting clips rather than captions keeps one long multi-action CMU trial
//! ("bends over, scoops something up, … lifts an arm", 18 s) from setting the length of a
//! pick-up when 32 put-down clips of 3 s sit next to it.

use super::sentence::{CaptionIndex, Nearest, SentenceEncoder};
use super::weights::WeightsError;
use crate::dataset::{Dataset, Split};
use crate::fsutil::write_bytes_atomic;
use std::collections::BTreeMap;
use std::path::Path;

/// Shortest length the prior proposes (1 s): a shorter motion is hardly a motion.
pub const MIN_FRAMES: usize = 20;

/// Captions this close to the best cosine count as the prompt's neighbours.
pub const MARGIN: f32 = super::sentence::NEIGHBOUR_MARGIN;

/// Median length and clip count of one caption's training clips.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct CaptionLength {
    /// Median length in frames (20 fps).
    pub frames: usize,
    /// Training clips carrying the caption (mirrored copies included).
    pub clips: usize,
}

/// Length statistics of each training caption (`<bundle>/lengths.json`).
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(transparent)]
pub struct CaptionLengths(BTreeMap<String, CaptionLength>);

impl CaptionLengths {
    /// Every caption of every training clip (mirrored copies included).
    pub fn of_dataset(data: &Dataset) -> CaptionLengths {
        let mut frames: BTreeMap<&str, Vec<usize>> = BTreeMap::new();
        for clip in data.clips(Split::Train) {
            for caption in &clip.captions {
                frames.entry(caption).or_default().push(clip.frames);
            }
        }
        CaptionLengths(
            frames
                .into_iter()
                .map(|(caption, mut f)| {
                    f.sort_unstable();
                    let length = CaptionLength {
                        frames: f[f.len() / 2],
                        clips: f.len(),
                    };
                    (caption.to_string(), length)
                })
                .collect(),
        )
    }

    /// The statistics of `caption`.
    pub fn get(&self, caption: &str) -> Option<CaptionLength> {
        self.0.get(caption).copied()
    }

    /// Whether no caption has a length (a bundle written before the prior existed).
    pub fn is_empty(&self) -> bool {
        self.0.is_empty()
    }

    /// The proposal for `prompt` (see the module's rule) with the nearest caption that has
    /// a length; None when none has.
    pub fn propose(
        &self,
        index: &CaptionIndex,
        encoder: &SentenceEncoder,
        prompt: &str,
        max_frames: usize,
    ) -> Option<(usize, Nearest)> {
        let sims = index.similarities(encoder, prompt);
        let known: Vec<(f32, &String, CaptionLength)> = index
            .captions()
            .iter()
            .zip(sims)
            .filter_map(|(c, s)| self.get(c).map(|l| (s, c, l)))
            .collect();
        let (best, caption, _) = known.iter().max_by(|a, b| a.0.total_cmp(&b.0))?;
        let mut near: Vec<CaptionLength> = known
            .iter()
            .filter(|(s, _, _)| *s >= best - MARGIN)
            .map(|k| k.2)
            .collect();
        near.sort_by_key(|l| l.frames);
        let total: usize = near.iter().map(|l| l.clips).sum();
        let mut seen = 0;
        let frames = near
            .iter()
            .find(|l| {
                seen += l.clips;
                2 * seen >= total
            })
            .map_or(near[0].frames, |l| l.frames);
        let nearest = Nearest {
            caption: caption.to_string(),
            cosine: *best,
        };
        Some((
            frames.clamp(MIN_FRAMES.min(max_frames), max_frames),
            nearest,
        ))
    }

    /// Writes `<dir>/lengths.json` (nothing when empty).
    pub fn save(&self, dir: &Path) -> Result<(), WeightsError> {
        if self.is_empty() {
            return Ok(());
        }
        let p = dir.join("lengths.json");
        let text = serde_json::to_string_pretty(self).expect("lengths serialise");
        write_bytes_atomic(&p, text.as_bytes()).map_err(|e| WeightsError::Write {
            path: p.clone(),
            reason: e.to_string(),
        })
    }

    /// Reads `<dir>/lengths.json`; empty when the bundle has none.
    pub fn load(dir: &Path) -> Result<CaptionLengths, WeightsError> {
        let p = dir.join("lengths.json");
        if !p.exists() {
            return Ok(CaptionLengths::default());
        }
        let text = std::fs::read_to_string(&p).map_err(|e| WeightsError::Read {
            path: p.clone(),
            reason: e.to_string(),
        })?;
        let lengths: CaptionLengths =
            serde_json::from_str(&text).map_err(|e| WeightsError::Mismatch {
                path: p.clone(),
                reason: format!("bad caption lengths: {e}"),
            })?;
        if let Some((caption, _)) = lengths
            .0
            .iter()
            .find(|(_, l)| l.frames == 0 || l.clips == 0)
        {
            return Err(WeightsError::Mismatch {
                path: p,
                reason: format!("caption {caption:?} has length 0 or no clips"),
            });
        }
        Ok(lengths)
    }
}
