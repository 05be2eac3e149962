//! Training batches: random clips of the training split, random crops, captions and
//! timesteps, drawn from a generator seeded by (run seed, step) so a resumed run sees the
//! same data it would have seen without the interruption.

use super::config::TrainConfig;
use super::schedule::DIFFUSION_STEPS;
use super::text::{is_function_word, words_of};
use crate::dataset::{ClipInfo, Dataset, FEATURE_DIM};
use crate::features::layout::{LOCAL_VEL, ROOT_VEL, ROOT_YAW_VEL};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// First timestep of the high-noise share (`TrainConfig::high_noise_fraction`).
pub const HIGH_NOISE_FROM: usize = 900;

/// A batch on the host, normalised, padded to the longest crop.
#[derive(Clone, Debug)]
pub struct HostBatch {
    /// `[B, N, 263]` normalised clean features (zeros on padding).
    pub x0: Vec<f32>,
    /// `[B, N]` true on padded frames.
    pub padding: Vec<bool>,
    /// Frames per sample (N).
    pub frames: usize,
    /// One caption per sample.
    pub captions: Vec<String>,
    /// Diffusion timestep per sample.
    pub timesteps: Vec<usize>,
    /// 1 keeps the caption, 0 drops it (classifier-free guidance training).
    pub keep_text: Vec<f32>,
    /// Generator state after drawing the batch (used for the noise).
    pub noise_seed: u64,
    /// Per-dimension noise added to the sentence vectors (`TrainConfig::text_noise`).
    pub text_noise: f64,
    /// 1 keeps the sentence vector for a text ControlNet's AdaIN, 0 empties it
    /// (`TrainConfig::eos_drop`); empty without it.
    pub eos_keep: Vec<f32>,
}

/// Feature columns that are motion to the next frame (zero while a pose is held).
const MOVING: [std::ops::Range<usize>; 3] = [ROOT_YAW_VEL, ROOT_VEL, LOCAL_VEL];

/// One sample of a batch: `len` frames of `clip` from `start`, placed at `before` in a
/// window of `total` frames (`before = 0, total = len` unless hold-padded).
struct Pick<'a> {
    clip: &'a ClipInfo,
    start: usize,
    len: usize,
    before: usize,
    total: usize,
}

/// Generator for step `step` of a run seeded with `seed`.
pub fn step_rng(seed: u64, step: usize) -> ChaCha8Rng {
    ChaCha8Rng::seed_from_u64(seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) ^ step as u64)
}

/// `caption` with each word dropped with probability `p`; the words the text encoder
/// reads are never all dropped (when every one was, the caption comes back whole).
pub fn drop_words(caption: &str, p: f64, rng: &mut impl Rng) -> String {
    if p <= 0.0 {
        return caption.to_string();
    }
    let kept: Vec<&str> = caption
        .split_whitespace()
        .filter(|_| rng.random::<f64>() >= p)
        .collect();
    let text = kept.join(" ");
    if words_of(&text).iter().any(|w| !is_function_word(w)) {
        text
    } else {
        caption.to_string()
    }
}

/// Sampling weight of a clip under `cfg.source_weights` (longest matching prefix, else 1).
pub fn clip_weight(cfg: &TrainConfig, clip: &ClipInfo) -> f64 {
    cfg.source_weights
        .iter()
        .filter(|(prefix, _)| clip.source.starts_with(prefix.as_str()))
        .max_by_key(|(prefix, _)| prefix.len())
        .map_or(1.0, |(_, &w)| w)
}

/// Draws the batch of `step`.
pub fn draw_batch(ds: &Dataset, clips: &[&ClipInfo], cfg: &TrainConfig, step: usize) -> HostBatch {
    let mut rng = step_rng(cfg.seed, step);
    // Cumulative weights; without source weights the draw is the plain uniform one (the
    // same data order as runs made before weights existed).
    let cumulative: Option<Vec<f64>> = (!cfg.source_weights.is_empty()).then(|| {
        clips
            .iter()
            .scan(0.0, |acc, c| {
                *acc += clip_weight(cfg, c);
                Some(*acc)
            })
            .collect()
    });
    let picks: Vec<Pick> = (0..cfg.batch_size)
        .map(|_| {
            let index = match &cumulative {
                None => rng.random_range(0..clips.len()),
                Some(cum) => {
                    let u = rng.random::<f64>() * cum[cum.len() - 1];
                    cum.partition_point(|&c| c <= u).min(clips.len() - 1)
                }
            };
            let clip = clips[index];
            let len = clip.frames.min(cfg.crop_frames);
            let start = rng.random_range(0..=clip.frames - len);
            let (before, total) = if cfg.hold_pad > 0.0
                && clip.frames < cfg.crop_frames
                && rng.random::<f64>() < cfg.hold_pad
            {
                let total = rng.random_range(len..=(2 * len).min(cfg.crop_frames));
                (rng.random_range(0..=total - len), total)
            } else {
                (0, len)
            };
            Pick {
                clip,
                start,
                len,
                before,
                total,
            }
        })
        .collect();
    let frames = picks.iter().map(|p| p.total).max().unwrap_or(1);
    let b = picks.len();
    let mut x0 = vec![0.0f32; b * frames * FEATURE_DIM];
    let mut padding = vec![true; b * frames];
    let mut captions = Vec::with_capacity(b);
    for (i, pick) in picks.iter().enumerate() {
        let clip = pick.clip;
        let features = ds.clip_features(clip);
        for k in 0..pick.total {
            // Held frames repeat the clip's first or last pose, standing still.
            let inside = k.clamp(pick.before, pick.before + pick.len - 1) - pick.before;
            let held = k != inside + pick.before;
            let row = &features[(pick.start + inside) * FEATURE_DIM..][..FEATURE_DIM];
            let dst = &mut x0[(i * frames + k) * FEATURE_DIM..][..FEATURE_DIM];
            for f in 0..FEATURE_DIM {
                let still = held && MOVING.iter().any(|r| r.contains(&f));
                let v = if still { 0.0 } else { row[f] };
                dst[f] = (v - ds.mean[f]) / ds.std[f];
            }
            padding[i * frames + k] = false;
        }
        let caption = &clip.captions[rng.random_range(0..clip.captions.len())];
        captions.push(drop_words(caption, cfg.word_drop, &mut rng));
    }
    // Without a high-noise share the draw is the plain uniform one (the same timesteps as
    // runs made before the option existed).
    let timesteps = (0..b)
        .map(|_| {
            if cfg.high_noise_fraction > 0.0 && rng.random::<f64>() < cfg.high_noise_fraction {
                rng.random_range(HIGH_NOISE_FROM..DIFFUSION_STEPS)
            } else {
                rng.random_range(0..DIFFUSION_STEPS)
            }
        })
        .collect();
    let keep_text = (0..b)
        .map(|_| {
            if rng.random::<f64>() < cfg.cond_drop {
                0.0
            } else {
                1.0
            }
        })
        .collect();
    let noise_seed = rng.random();
    // Drawn after everything else, so runs without it draw what they always drew.
    let eos_keep = if cfg.eos_drop > 0.0 {
        (0..b)
            .map(|_| f32::from(u8::from(rng.random::<f64>() >= cfg.eos_drop)))
            .collect()
    } else {
        Vec::new()
    };
    HostBatch {
        x0,
        padding,
        frames,
        captions,
        timesteps,
        keep_text,
        noise_seed,
        text_noise: cfg.text_noise,
        eos_keep,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn word_dropout_keeps_a_content_word_and_is_seeded() {
        let caption = "a person walks forward";
        let mut rng = step_rng(1, 0);
        let mut seen = std::collections::HashSet::new();
        for _ in 0..400 {
            let short = drop_words(caption, 0.5, &mut rng);
            assert!(
                words_of(&short).iter().any(|w| !is_function_word(w)),
                "{short:?} has no content word"
            );
            assert!(short.split_whitespace().all(|w| caption.contains(w)));
            seen.insert(short);
        }
        // Subsets appear: "person walks", "a walks", "walks forward", ... and the whole.
        assert!(
            seen.contains("person walks") && seen.contains(caption),
            "{seen:?}"
        );
        assert!(seen.len() > 8, "{seen:?}");
        let again = |seed| drop_words(caption, 0.5, &mut step_rng(seed, 3));
        assert_eq!(again(7), again(7));
        assert_eq!(drop_words(caption, 0.0, &mut rng), caption);
        // Only function words left: the caption comes back whole.
        assert_eq!(drop_words("a the", 0.9, &mut rng), "a the");
    }
}
