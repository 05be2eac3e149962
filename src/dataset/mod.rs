//! Training set built from BVH folders: features, joints, captions, splits, statistics.
//!
//! [`build::build_dataset`] writes it, [`store::Dataset::load`] reads it back.

pub mod build;
pub mod captions;
pub mod captions_cmu;
pub mod captions_hdm05;
pub mod envelope;
pub mod labels;
pub mod split;
pub mod stats;
pub mod store;
pub mod takes;

pub use store::{ClipInfo, Dataset, DatasetError, DatasetIndex, FEATURE_DIM, Split, SplitStats};
