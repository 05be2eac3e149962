//! Caption augmentation of a sentence-encoder run: each sample's caption is, with
//! probability `paraphrase_prob`, replaced by one of its rule-made paraphrases
//! ([`super::paraphrase`]) that the sentence encoder places near it, so the model is
//! trained on the neighbourhood of each caption instead of one point (a paraphrase it
//! never saw drifted: issue 49). A held-out paraphrase set (`paraphrase_holdout`) is
//! never trained on.
//!
//! The kept paraphrases are fixed at a run's first start (`<out>/paraphrases.json`) and
//! embedded with their side-swapped twins once (`<out>/paraphrases.safetensors`).

use super::paraphrase::{action_of, paraphrases};
use super::text::TrainText;
use super::{TrainError, file_err};
use crate::fsutil::write_bytes_atomic;
use crate::model::prompt::swap_side_words;
use crate::model::sentence::{CaptionIndex, SentenceEncoder};
use burn::prelude::*;
use rand::seq::SliceRandom;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::collections::{BTreeMap, HashSet};
use std::path::Path;

/// Caption → its kept paraphrases.
pub type ParaphraseTable = BTreeMap<String, Vec<String>>;

/// What [`verify`] kept and dropped, for the run's log.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct AugmentReport {
    /// Captions with at least one kept paraphrase.
    pub captions: usize,
    /// Paraphrases kept.
    pub kept: usize,
    /// Candidates below the cosine floor.
    pub too_far: usize,
    /// Candidates nearer another action's caption than their own.
    pub other_action: usize,
    /// Candidates equal to a held-out wording.
    pub held_out: usize,
}

/// A wording in the form held-out sets are compared in: lower case, single spaces, no
/// final full stop.
pub fn normalise(text: &str) -> String {
    text.to_lowercase()
        .split_whitespace()
        .collect::<Vec<_>>()
        .join(" ")
        .trim_end_matches(['.', '!'])
        .to_string()
}

/// Every string in a TOML file (whatever its layout): the held-out wordings.
pub fn held_out_wordings(path: &Path) -> Result<HashSet<String>, TrainError> {
    let text = std::fs::read_to_string(path).map_err(|e| file_err(path, e))?;
    let value: toml::Value = toml::from_str(&text).map_err(|e| file_err(path, e))?;
    let mut out = HashSet::new();
    collect_strings(&value, &mut out);
    Ok(out)
}

fn collect_strings(v: &toml::Value, out: &mut HashSet<String>) {
    match v {
        toml::Value::String(s) => {
            out.insert(normalise(s));
        }
        toml::Value::Array(a) => a.iter().for_each(|x| collect_strings(x, out)),
        toml::Value::Table(t) => t.values().for_each(|x| collect_strings(x, out)),
        _ => {}
    }
}

/// Candidates of each caption, at most `per_caption`, drawn in a fixed order (a seeded
/// shuffle, so subjects and phrasings mix) with the held-out wordings taken out.
fn candidates(
    captions: &[&str],
    per_caption: usize,
    held_out: &HashSet<String>,
    report: &mut AugmentReport,
) -> Vec<(usize, String)> {
    let mut out = Vec::new();
    for (i, c) in captions.iter().enumerate() {
        let mut all = paraphrases(c);
        let before = all.len();
        all.retain(|p| !held_out.contains(&normalise(p)));
        report.held_out += before - all.len();
        let seed = c
            .bytes()
            .fold(0u64, |h, b| h.wrapping_mul(31).wrapping_add(b as u64));
        all.shuffle(&mut ChaCha8Rng::seed_from_u64(seed));
        // Twice the quota: the encoder check drops some.
        all.truncate(per_caption * 2);
        out.extend(all.into_iter().map(|p| (i, p)));
    }
    out
}

/// The paraphrases of `captions` the sentence encoder places near their caption: cosine
/// at least `min_cos` to it, and no caption of another action nearer (so "lifts the left
/// arm" is not closer to a wave than to a raise). `index` holds every training caption.
pub fn verify(
    encoder: &SentenceEncoder,
    index: &CaptionIndex,
    captions: &[&str],
    per_caption: usize,
    min_cos: f64,
    held_out: &HashSet<String>,
) -> (ParaphraseTable, AugmentReport) {
    let mut report = AugmentReport::default();
    let cands = candidates(captions, per_caption, held_out, &mut report);
    let known = index.captions();
    let row_of = |c: &str| known.iter().position(|k| k == c);
    let table_emb = index.embeddings().clone();
    let mut table = ParaphraseTable::new();
    for chunk in cands.chunks(256) {
        let texts: Vec<&str> = chunk.iter().map(|(_, p)| p.as_str()).collect();
        let emb = encoder.encode(&texts).to_device(&table_emb.device());
        let sims = emb
            .matmul(table_emb.clone().transpose())
            .into_data()
            .try_to_vec_as::<f32>()
            .expect("float tensors read back as f32");
        for ((ci, p), row) in chunk.iter().zip(sims.chunks_exact(known.len().max(1))) {
            let caption = captions[*ci];
            let Some(own) = row_of(caption).map(|r| row[r]) else {
                continue;
            };
            if (own as f64) < min_cos {
                report.too_far += 1;
                continue;
            }
            let best = (0..known.len()).max_by(|&a, &b| row[a].total_cmp(&row[b]));
            let same = best.is_some_and(|b| action_of(&known[b]) == action_of(caption));
            if !same {
                report.other_action += 1;
                continue;
            }
            let kept = table.entry(caption.to_string()).or_default();
            if kept.len() < per_caption {
                kept.push(p.clone());
            }
        }
    }
    report.captions = table.len();
    report.kept = table.values().map(Vec::len).sum();
    (table, report)
}

/// The run's caption augmentation.
#[derive(Clone, Debug)]
pub struct CaptionAugment {
    /// Caption → kept paraphrases.
    pub table: ParaphraseTable,
    /// Probability a sample's caption is replaced.
    pub prob: f64,
}

impl CaptionAugment {
    /// Every paraphrase and its side-swapped twin (what the text table must hold).
    pub fn wordings(&self) -> Vec<String> {
        let mut all: Vec<String> = self
            .table
            .values()
            .flatten()
            .flat_map(|p| [p.clone(), swap_side_words(p)])
            .collect();
        all.sort_unstable();
        all.dedup();
        all
    }

    /// Replaces each caption with a paraphrase with probability `prob` (seeded by the
    /// run's seed and step, so a resumed run draws the same).
    pub fn apply(&self, captions: &mut [String], seed: u64, step: usize) {
        if self.prob <= 0.0 {
            return;
        }
        let mut rng = ChaCha8Rng::seed_from_u64(
            seed.wrapping_mul(0xD1B5_4A32_D192_ED03) ^ (step as u64).rotate_left(17),
        );
        for c in captions.iter_mut() {
            let draw = rng.random::<f64>();
            let Some(list) = self.table.get(c.as_str()).filter(|l| !l.is_empty()) else {
                continue;
            };
            let pick = rng.random_range(0..list.len());
            if draw < self.prob {
                *c = list[pick].clone();
            }
        }
    }

    /// Reads the table fixed at the run's first start.
    pub fn load_table(path: &Path) -> Result<ParaphraseTable, TrainError> {
        let text = std::fs::read_to_string(path).map_err(|e| file_err(path, e))?;
        serde_json::from_str(&text).map_err(|e| file_err(path, e))
    }

    /// Writes the table (atomically).
    pub fn save_table(table: &ParaphraseTable, path: &Path) -> Result<(), TrainError> {
        let text = serde_json::to_string_pretty(table).expect("strings serialise");
        write_bytes_atomic(path, text.as_bytes()).map_err(|e| file_err(path, e))
    }
}

impl super::TrainRun<'_> {
    /// The run's caption augmentation (None when `paraphrase_prob` is 0): the table fixed
    /// at the first start, or verified now and saved; its wordings added to `text`.
    pub(super) fn caption_augment(
        &self,
        text: &mut TrainText,
        plain: &Device,
    ) -> Result<Option<CaptionAugment>, TrainError> {
        let cfg = &self.config;
        if cfg.paraphrase_prob <= 0.0 {
            return Ok(None);
        }
        let TrainText::Sentences { prompts, .. } = &*text else {
            return Err(TrainError::Invalid(
                "`paraphrase_prob` needs a sentence-encoder run".into(),
            ));
        };
        let (encoder, index) = (prompts.encoder.clone(), prompts.captions.clone());
        let table_path = self.out.join("paraphrases.json");
        let table = if table_path.exists() {
            CaptionAugment::load_table(&table_path)?
        } else {
            let held_out = match &cfg.paraphrase_holdout {
                Some(p) => held_out_wordings(Path::new(p))?,
                None => HashSet::new(),
            };
            let captions: Vec<&str> = index.captions().iter().map(String::as_str).collect();
            eprintln!(
                "checking paraphrases of {} captions with the sentence encoder ...",
                captions.len()
            );
            let (table, report) = verify(
                &encoder,
                &index,
                &captions,
                cfg.paraphrases_per_caption,
                cfg.paraphrase_min_cos,
                &held_out,
            );
            eprintln!(
                "kept {} paraphrases of {} captions ({} below cosine {}, {} nearer another action, {} held out)",
                report.kept,
                report.captions,
                report.too_far,
                cfg.paraphrase_min_cos,
                report.other_action,
                report.held_out
            );
            std::fs::create_dir_all(&self.out).map_err(|e| file_err(&self.out, e))?;
            CaptionAugment::save_table(&table, &table_path)?;
            table
        };
        let augment = CaptionAugment {
            table,
            prob: cfg.paraphrase_prob,
        };
        let wordings = augment.wordings();
        let refs: Vec<&str> = wordings.iter().map(String::as_str).collect();
        let emb_path = self.out.join("paraphrases.safetensors");
        let cached = CaptionIndex::load(&emb_path, plain)
            .ok()
            .filter(|i| i.covers(&refs));
        let extra = match cached {
            Some(i) => i,
            None => {
                eprintln!("embedding {} paraphrases ...", refs.len());
                let i = CaptionIndex::build(&encoder, &refs);
                i.save(&emb_path).map_err(|e| file_err(&emb_path, e))?;
                i
            }
        };
        text.add_wordings(&extra);
        Ok(Some(augment))
    }
}

/// Adds Gaussian noise of `sigma` per dimension to each row of two `[B, D]` tables of
/// unit vectors (the same noise to both, so their difference, the side vector, keeps its
/// meaning) and returns both renormalised.
pub fn noisy_vectors(
    vectors: Tensor<2>,
    mirrored: Tensor<2>,
    sigma: f64,
    seed: u64,
) -> (Tensor<2>, Tensor<2>) {
    if sigma <= 0.0 {
        return (vectors, mirrored);
    }
    let dims = vectors.dims();
    let device = vectors.device();
    let noise = crate::model::noise::NoiseSource::new(seed ^ 0x7E47_0015)
        .tensor(dims, &device)
        .mul_scalar(sigma as f32);
    let unit = |t: Tensor<2>| {
        let norm = t.clone().powi_scalar(2).sum_dim(1).sqrt().clamp_min(1e-12);
        t / norm
    };
    (unit(vectors + noise.clone()), unit(mirrored + noise))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn normalised_wordings_compare_loosely() {
        assert_eq!(normalise("  A man  walks forward. "), "a man walks forward");
    }

    #[test]
    fn held_out_strings_are_read_from_any_layout() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("set.toml");
        std::fs::write(
            &p,
            "[[entry]]\ncaption = \"a person walks forward\"\nwordings = [\"A guy strolls ahead.\"]\n",
        )
        .unwrap();
        let set = held_out_wordings(&p).unwrap();
        assert!(set.contains("a guy strolls ahead"), "{set:?}");
        std::fs::write(&p, "[[entry]\n").unwrap();
        let err = held_out_wordings(&p).unwrap_err().to_string();
        assert!(err.contains("set.toml"), "{err}");
    }

    #[test]
    fn candidates_leave_out_held_out_wordings() {
        let caption = "a person raises the left hand";
        let first = paraphrases(caption)[0].clone();
        let held: HashSet<String> = [normalise(&first)].into_iter().collect();
        let mut report = AugmentReport::default();
        let c = candidates(&[caption], 1000, &held, &mut report);
        assert_eq!(report.held_out, 1);
        assert!(c.iter().all(|(_, p)| *p != first));
        assert!(!c.is_empty());
    }

    #[test]
    fn replacement_is_seeded_and_keeps_unknown_captions() {
        let mut table = ParaphraseTable::new();
        table.insert("a".into(), vec!["b".into(), "c".into()]);
        let aug = CaptionAugment { table, prob: 0.5 };
        let run = |step| {
            let mut caps: Vec<String> = vec!["a".into(); 64];
            caps.push("z".into());
            aug.apply(&mut caps, 3, step);
            caps
        };
        let once = run(7);
        assert_eq!(once, run(7));
        assert_ne!(once, run(8));
        assert_eq!(once[64], "z");
        let replaced = once[..64].iter().filter(|c| *c != "a").count();
        assert!((16..48).contains(&replaced), "{replaced} of 64");
        assert_eq!(aug.wordings(), vec!["b".to_string(), "c".to_string()]);
    }

    #[test]
    fn noise_keeps_unit_length_and_the_side_difference() {
        let device = Default::default();
        let v = Tensor::<2>::from_data(
            TensorData::new(vec![1.0f32, 0.0, 0.0, 0.0], [1, 4]),
            &device,
        );
        let m = Tensor::<2>::from_data(
            TensorData::new(vec![0.0f32, 1.0, 0.0, 0.0], [1, 4]),
            &device,
        );
        let (a, b) = noisy_vectors(v.clone(), m.clone(), 0.05, 1);
        let norm = |t: Tensor<2>| t.powi_scalar(2).sum().into_scalar::<f32>().sqrt();
        assert!((norm(a.clone()) - 1.0).abs() < 1e-5);
        assert!((norm(b.clone()) - 1.0).abs() < 1e-5);
        let cos = (a.clone() * v.clone()).sum().into_scalar::<f32>();
        assert!(cos > 0.95 && cos < 1.0, "{cos}");
        let (same, _) = noisy_vectors(v.clone(), m, 0.0, 1);
        assert_eq!(same.into_data(), v.into_data());
    }
}
