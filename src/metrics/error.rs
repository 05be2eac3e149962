//! Errors of the evaluation: bad input, unreadable or mismatched evaluator files,
//! generation and scoring failures.

use crate::dataset::DatasetError;
use crate::features::FeatureError;
use crate::model::generate::GenerateError;
use std::path::{Path, PathBuf};

/// Anything that stops an evaluation or an evaluator training run.
#[derive(Debug, thiserror::Error)]
pub enum MetricsError {
    /// The request cannot be served (too few clips, bad settings).
    #[error("{0}")]
    Invalid(String),
    /// A file is missing, unreadable, or does not fit this build.
    #[error("{path}: {reason}")]
    File {
        /// The file.
        path: PathBuf,
        /// What is wrong.
        reason: String,
    },
    /// The dataset could not be loaded.
    #[error(transparent)]
    Dataset(#[from] DatasetError),
    /// Generating motions failed.
    #[error("generating motions: {0}")]
    Generate(#[from] GenerateError),
    /// Extracting features or recovering joints failed.
    #[error(transparent)]
    Features(#[from] FeatureError),
    /// A score could not be computed.
    #[error("scoring: {0}")]
    Score(#[from] super::scores::ScoreError),
    /// Training diverged.
    #[error("evaluator training diverged at step {step}: loss {loss}")]
    Diverged {
        /// Step.
        step: usize,
        /// Loss value.
        loss: f32,
    },
}

/// A [`MetricsError::File`] for `path`.
pub fn file_error(path: &Path, reason: impl std::fmt::Display) -> MetricsError {
    MetricsError::File {
        path: path.to_path_buf(),
        reason: reason.to_string(),
    }
}
