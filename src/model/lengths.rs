//! The length prior: how long the training clips of each caption last, so that `mprog gen`
//! without `--seconds` makes a motion as long as the data's motions of the nearest known
//! caption (T2M's length estimator in its plainest form: the median length of the nearest
//! caption's clips, not a learned regressor).
//!
//! It matters because a prompt's clips are all about one length: Bandai's runs last 2.6 s
//! (the capture volume ends), HDM05's hop takes 2 s. Asked for 6 s, the prior has never
//! seen a run that long and makes a 1.6 m/s jog; at 2.6 s it runs at 2.65 m/s.

use super::weights::WeightsError;
use crate::dataset::{Dataset, Split};
use crate::fsutil::write_bytes_atomic;
use std::collections::BTreeMap;
use std::path::Path;

/// Shortest length the prior proposes (1 s): a shorter motion is hardly a motion.
pub const MIN_FRAMES: usize = 20;

/// Median training-clip length, in frames, of each caption (`<bundle>/lengths.json`).
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(transparent)]
pub struct CaptionLengths(BTreeMap<String, usize>);

impl CaptionLengths {
    /// Every caption of every training clip (mirrored copies included) with the median
    /// length of the clips that carry it.
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
                    (caption.to_string(), f[f.len() / 2])
                })
                .collect(),
        )
    }

    /// The median length of `caption`'s clips.
    pub fn get(&self, caption: &str) -> Option<usize> {
        self.0.get(caption).copied()
    }

    /// Whether no caption has a length (a bundle written before the prior existed).
    pub fn is_empty(&self) -> bool {
        self.0.is_empty()
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
        if let Some((caption, _)) = lengths.0.iter().find(|(_, f)| **f == 0) {
            return Err(WeightsError::Mismatch {
                path: p,
                reason: format!("caption {caption:?} has length 0"),
            });
        }
        Ok(lengths)
    }
}
