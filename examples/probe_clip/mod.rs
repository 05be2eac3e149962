//! What the one-clip probes (`caption_probe`, `low_noise_probe`) share: the bundle, the
//! dataset and one named clip of it, clean and normalised.

use burn::prelude::*;
use mprog::dataset::{ClipInfo, Dataset, FEATURE_DIM};
use mprog::features::normalize_slice;
use mprog::model::ModelBundle;
use std::path::PathBuf;

/// A bundle and one dataset clip, as `<bundle> <dataset> <clip name>` name them.
pub struct ProbeClip {
    pub device: Device,
    pub bundle: ModelBundle,
    pub clip: ClipInfo,
    /// Frames used: the clip's, at most the model's longest.
    pub frames: usize,
    /// `[frames · 263]` de-normalised features.
    pub raw: Vec<f32>,
    /// `[1, frames, 263]` normalised with the bundle's statistics.
    pub clean: Tensor<3>,
}

/// Loads what `args[1..4]` name, or prints `usage` and exits.
pub fn load(args: &[String], usage: &str) -> ProbeClip {
    if args.len() < 4 {
        eprintln!("usage: {usage}");
        std::process::exit(2);
    }
    let device = Device::flex();
    let bundle = ModelBundle::load(&PathBuf::from(&args[1]), &device).expect("bundle");
    let data = Dataset::load(&PathBuf::from(&args[2])).expect("dataset");
    let clip = data
        .index
        .clips
        .iter()
        .find(|c| c.name == args[3])
        .expect("no clip of that name")
        .clone();
    let frames = clip.frames.min(bundle.config.max_frames);
    let raw = data.clip_features(&clip)[..frames * FEATURE_DIM].to_vec();
    let mut x0 = raw.clone();
    normalize_slice(&mut x0, &bundle.mean, &bundle.std).expect("feature rows");
    let clean = Tensor::from_data(TensorData::new(x0, [1, frames, FEATURE_DIM]), &device);
    ProbeClip {
        device,
        bundle,
        clip,
        frames,
        raw,
        clean,
    }
}
