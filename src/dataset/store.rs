//! On-disk layout of a built training set, and loading it back.
//!
//! ```text
//! <dir>/clips.json     index: one entry per clip (source file, labels, captions, split,
//!                      offset and length in the frame arrays), plus build statistics
//! <dir>/features.npy   [total_frames, 263] f32, HumanML3D features, not normalised
//! <dir>/joints.npy     [total_frames, 22, 3] f32, canonicalised joints (same frames)
//! <dir>/mean.npy       [263] f32 feature mean over the training split
//! <dir>/std.npy        [263] f32 block-averaged feature std over the training split
//! ```

use crate::skeleton::NUM_JOINTS;
use npyz::WriterBuilder;
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// Version of the layout; bumped when a field changes meaning.
pub const DATASET_VERSION: u32 = 1;

/// Width of a HumanML3D feature frame.
pub const FEATURE_DIM: usize = 263;

/// Which split a clip belongs to.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Split {
    /// Training data.
    Train,
    /// Held out for choosing checkpoints.
    Val,
    /// Held out for evaluation.
    Test,
}

/// One clip of the training set.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ClipInfo {
    /// Stable name (source file stem, `_mirror` for the mirrored copy).
    pub name: String,
    /// Source file, relative to the BVH folder.
    pub source: String,
    /// Motion label from the file name (`walk`, `wave-right-hand`, …).
    pub content: String,
    /// Style label from the file name (`normal`, `tired`, …).
    pub style: String,
    /// True for the left/right mirrored copy.
    pub mirrored: bool,
    /// Split, decided by source file so a clip and its mirror stay together.
    pub split: Split,
    /// First frame in the frame arrays.
    pub offset: usize,
    /// Number of feature frames.
    pub frames: usize,
    /// Several phrasings of what happens.
    pub captions: Vec<String>,
}

/// Counts per split, reported by the build and stored in the index.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct SplitStats {
    /// Clips (mirrored copies included).
    pub clips: usize,
    /// Feature frames.
    pub frames: usize,
    /// Hours at 20 fps.
    pub hours: f64,
}

/// The index file.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct DatasetIndex {
    /// [`DATASET_VERSION`].
    pub version: u32,
    /// Frame rate of every clip.
    pub fps: f32,
    /// All clips, in frame-array order.
    pub clips: Vec<ClipInfo>,
    /// Per-split statistics: train, val, test.
    pub stats: [SplitStats; 3],
    /// Files that could not be read, with the reason.
    pub skipped: Vec<(String, String)>,
    /// Seconds the build took.
    pub build_seconds: f64,
}

/// Errors while loading a training set.
#[derive(Debug, thiserror::Error)]
pub enum DatasetError {
    /// A file is missing or unreadable.
    #[error("cannot read {path}: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// Why.
        source: std::io::Error,
    },
    /// A file exists but its content is wrong.
    #[error("{path}: {reason}")]
    Invalid {
        /// The file.
        path: PathBuf,
        /// What is wrong.
        reason: String,
    },
}

/// A loaded training set.
#[derive(Clone, Debug)]
pub struct Dataset {
    /// The index.
    pub index: DatasetIndex,
    /// `[total_frames, 263]` features.
    pub features: Vec<f32>,
    /// `[total_frames, 22, 3]` joints.
    pub joints: Vec<f32>,
    /// `[263]` mean.
    pub mean: Vec<f32>,
    /// `[263]` std.
    pub std: Vec<f32>,
}

fn invalid(path: &Path, reason: impl Into<String>) -> DatasetError {
    DatasetError::Invalid {
        path: path.to_path_buf(),
        reason: reason.into(),
    }
}

/// Reads a float32 `.npy` file, checking its shape.
pub fn read_f32_npy(
    path: &Path,
    expect_tail: &[usize],
) -> Result<(Vec<u64>, Vec<f32>), DatasetError> {
    let bytes = std::fs::read(path).map_err(|source| DatasetError::Io {
        path: path.to_path_buf(),
        source,
    })?;
    let npy = npyz::NpyFile::new(&bytes[..])
        .map_err(|e| invalid(path, format!("not a .npy file: {e}")))?;
    let shape = npy.shape().to_vec();
    let tail: Vec<usize> = shape.iter().skip(1).map(|&d| d as usize).collect();
    if tail != expect_tail {
        return Err(invalid(
            path,
            format!("shape {shape:?}, expected [_, {expect_tail:?}]"),
        ));
    }
    let data: Vec<f32> = npy
        .into_vec()
        .map_err(|e| invalid(path, format!("not float32 data: {e}")))?;
    Ok((shape, data))
}

/// Writes a float32 `.npy` file atomically.
pub fn write_f32_npy(path: &Path, shape: &[u64], data: &[f32]) -> std::io::Result<()> {
    crate::fsutil::write_atomic(path, |w| {
        let mut writer = npyz::WriteOptions::new()
            .default_dtype()
            .shape(shape)
            .writer(w)
            .begin_nd()?;
        writer.extend(data.iter().copied())?;
        writer.finish()
    })
}

impl Dataset {
    /// Loads a training set written by `mprog data build`.
    pub fn load(dir: &Path) -> Result<Dataset, DatasetError> {
        let index_path = dir.join("clips.json");
        let text = std::fs::read_to_string(&index_path).map_err(|source| DatasetError::Io {
            path: index_path.clone(),
            source,
        })?;
        let index: DatasetIndex = serde_json::from_str(&text)
            .map_err(|e| invalid(&index_path, format!("bad index: {e}")))?;
        if index.version != DATASET_VERSION {
            return Err(invalid(
                &index_path,
                format!(
                    "dataset version {} but this mprog reads {DATASET_VERSION}; rebuild it with `mprog data build`",
                    index.version
                ),
            ));
        }
        let (_, features) = read_f32_npy(&dir.join("features.npy"), &[FEATURE_DIM])?;
        let (_, joints) = read_f32_npy(&dir.join("joints.npy"), &[NUM_JOINTS, 3])?;
        let (_, mean) = read_f32_npy(&dir.join("mean.npy"), &[])?;
        let (_, std) = read_f32_npy(&dir.join("std.npy"), &[])?;
        let total = index
            .clips
            .iter()
            .try_fold(0usize, |acc, c| acc.checked_add(c.frames))
            .ok_or_else(|| invalid(&index_path, "clip frame counts overflow"))?;
        if features.len() != total * FEATURE_DIM || joints.len() != total * NUM_JOINTS * 3 {
            return Err(invalid(
                dir,
                format!("index lists {total} frames but the arrays disagree"),
            ));
        }
        for (i, c) in index.clips.iter().enumerate() {
            let end = c.offset.checked_add(c.frames);
            if c.frames == 0 || end.is_none_or(|e| e > total) || c.captions.is_empty() {
                return Err(invalid(
                    &index_path,
                    format!(
                        "clip {i} (`{}`) has offset {} and {} frames with {} captions; \
                         clips need frames, captions and must lie inside the {total} frames",
                        c.name,
                        c.offset,
                        c.frames,
                        c.captions.len()
                    ),
                ));
            }
        }
        if mean.len() != FEATURE_DIM || std.len() != FEATURE_DIM || std.iter().any(|s| *s <= 0.0) {
            return Err(invalid(
                dir,
                "mean.npy/std.npy must hold 263 values, std > 0",
            ));
        }
        Ok(Dataset {
            index,
            features,
            joints,
            mean,
            std,
        })
    }

    /// Clips of one split.
    pub fn clips(&self, split: Split) -> impl Iterator<Item = &ClipInfo> {
        self.index.clips.iter().filter(move |c| c.split == split)
    }

    /// Feature rows of a clip: `[frames, 263]`.
    pub fn clip_features(&self, clip: &ClipInfo) -> &[f32] {
        &self.features[clip.offset * FEATURE_DIM..(clip.offset + clip.frames) * FEATURE_DIM]
    }

    /// Joint rows of a clip: `[frames, 22, 3]`.
    pub fn clip_joints(&self, clip: &ClipInfo) -> &[f32] {
        let w = NUM_JOINTS * 3;
        &self.joints[clip.offset * w..(clip.offset + clip.frames) * w]
    }
}
