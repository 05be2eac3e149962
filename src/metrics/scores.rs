//! Scores on sets of embeddings (T2M evaluator protocol): FID between Gaussian fits,
//! diversity (mean distance of random pairs) and R-precision (rank of the matching
//! caption among 32).
//!
//! Embeddings are rows of `dim` f32 values; statistics are accumulated in f64.

use super::linalg::{LinalgError, trace_sqrt_product};
use rand::seq::SliceRandom;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// Mean and covariance of a set of embeddings.
#[derive(Clone, Debug, PartialEq)]
pub struct Gaussian {
    /// Width.
    pub dim: usize,
    /// `[dim]` mean.
    pub mean: Vec<f64>,
    /// `[dim, dim]` covariance (unbiased, N − 1), row-major.
    pub cov: Vec<f64>,
}

/// Errors of the scores.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum ScoreError {
    /// Too few or ragged embeddings.
    #[error("{0}")]
    Invalid(String),
    /// The matrix square root failed.
    #[error(transparent)]
    Linalg(#[from] LinalgError),
}

fn check_rows(rows: &[Vec<f32>], min: usize, what: &str) -> Result<usize, ScoreError> {
    if rows.len() < min {
        return Err(ScoreError::Invalid(format!(
            "{what} needs at least {min} embeddings, got {}",
            rows.len()
        )));
    }
    let dim = rows[0].len();
    if dim == 0 || rows.iter().any(|r| r.len() != dim) {
        return Err(ScoreError::Invalid(format!(
            "{what}: embeddings must all have the same non-zero width"
        )));
    }
    if rows.iter().flatten().any(|v| !v.is_finite()) {
        return Err(ScoreError::Invalid(format!(
            "{what}: embeddings hold NaN or infinite values"
        )));
    }
    Ok(dim)
}

impl Gaussian {
    /// Fits mean and covariance to at least two embeddings.
    pub fn fit(rows: &[Vec<f32>]) -> Result<Gaussian, ScoreError> {
        let dim = check_rows(rows, 2, "a Gaussian fit")?;
        let n = rows.len() as f64;
        let mut mean = vec![0.0f64; dim];
        for r in rows {
            for (m, &v) in mean.iter_mut().zip(r) {
                *m += v as f64;
            }
        }
        mean.iter_mut().for_each(|m| *m /= n);
        let mut cov = vec![0.0f64; dim * dim];
        let mut centred = vec![0.0f64; dim];
        for r in rows {
            for ((c, &v), m) in centred.iter_mut().zip(r).zip(&mean) {
                *c = v as f64 - m;
            }
            for i in 0..dim {
                let ci = centred[i];
                for j in i..dim {
                    cov[i * dim + j] += ci * centred[j];
                }
            }
        }
        for i in 0..dim {
            for j in i..dim {
                let v = cov[i * dim + j] / (n - 1.0);
                cov[i * dim + j] = v;
                cov[j * dim + i] = v;
            }
        }
        Ok(Gaussian { dim, mean, cov })
    }
}

/// Fréchet distance between two Gaussians:
/// ‖μ₁ − μ₂‖² + tr(Σ₁) + tr(Σ₂) − 2 tr((Σ₁Σ₂)^½).
pub fn frechet_distance(a: &Gaussian, b: &Gaussian) -> Result<f64, ScoreError> {
    if a.dim != b.dim {
        return Err(ScoreError::Invalid(format!(
            "FID of {}-d and {}-d Gaussians",
            a.dim, b.dim
        )));
    }
    let n = a.dim;
    let mean: f64 = a
        .mean
        .iter()
        .zip(&b.mean)
        .map(|(x, y)| (x - y).powi(2))
        .sum();
    let tr = |c: &[f64]| (0..n).map(|i| c[i * n + i]).sum::<f64>();
    let cross = trace_sqrt_product(&a.cov, &b.cov, n)?;
    // Never below 0 (rounding can leave −1e-12).
    Ok((mean + tr(&a.cov) + tr(&b.cov) - 2.0 * cross).max(0.0))
}

/// FID between two sets of embeddings.
pub fn fid(a: &[Vec<f32>], b: &[Vec<f32>]) -> Result<f64, ScoreError> {
    frechet_distance(&Gaussian::fit(a)?, &Gaussian::fit(b)?)
}

fn distance(a: &[f32], b: &[f32]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| ((x - y) as f64).powi(2))
        .sum::<f64>()
        .sqrt()
}

/// Pairs drawn for diversity (T2M's `diversity_times`).
pub const DIVERSITY_PAIRS: usize = 300;

/// Mean Euclidean distance between `pairs` random pairs of distinct embeddings.
pub fn diversity(rows: &[Vec<f32>], pairs: usize, seed: u64) -> Result<f64, ScoreError> {
    check_rows(rows, 2, "diversity")?;
    if pairs == 0 {
        return Err(ScoreError::Invalid(
            "diversity needs at least one pair".into(),
        ));
    }
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let n = rows.len();
    let total: f64 = (0..pairs)
        .map(|_| {
            let i = rng.random_range(0..n);
            let j = (i + rng.random_range(1..n)) % n;
            distance(&rows[i], &rows[j])
        })
        .sum();
    Ok(total / pairs as f64)
}

/// Captions compared with each motion in R-precision (1 matching + 31 mismatched).
pub const R_PRECISION_POOL: usize = 32;

/// A caption embedding that can serve as a mismatched distractor.
#[derive(Clone, Debug)]
pub struct Distractor {
    /// Text embedding.
    pub embedding: Vec<f32>,
    /// Group (content label): only captions of another group count as mismatched.
    pub group: String,
}

/// Top-1/2/3 R-precision: for motion i, its own caption `texts[i]` is ranked by distance
/// among itself and 31 distractors of a group other than `groups[i]`; returns the fraction
/// of motions whose caption is within the first 1, 2, 3.
pub fn r_precision(
    motions: &[Vec<f32>],
    texts: &[Vec<f32>],
    groups: &[String],
    distractors: &[Distractor],
    seed: u64,
) -> Result<[f64; 3], ScoreError> {
    let dim = check_rows(motions, 1, "R-precision")?;
    if texts.len() != motions.len() || groups.len() != motions.len() {
        return Err(ScoreError::Invalid(
            "R-precision needs one caption and one group per motion".into(),
        ));
    }
    if texts
        .iter()
        .chain(distractors.iter().map(|d| &d.embedding))
        .any(|t| t.len() != dim)
    {
        return Err(ScoreError::Invalid(
            "R-precision: text and motion embeddings differ in width".into(),
        ));
    }
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut hits = [0usize; 3];
    for ((m, t), g) in motions.iter().zip(texts).zip(groups) {
        let mut others: Vec<&Distractor> = distractors.iter().filter(|d| &d.group != g).collect();
        if others.len() < R_PRECISION_POOL - 1 {
            return Err(ScoreError::Invalid(format!(
                "R-precision needs {} captions of other labels than `{g}`, only {} exist",
                R_PRECISION_POOL - 1,
                others.len()
            )));
        }
        others.shuffle(&mut rng);
        let own = distance(m, t);
        let rank = others[..R_PRECISION_POOL - 1]
            .iter()
            .filter(|d| distance(m, &d.embedding) < own)
            .count();
        for (k, h) in hits.iter_mut().enumerate() {
            if rank <= k {
                *h += 1;
            }
        }
    }
    Ok(hits.map(|h| h as f64 / motions.len() as f64))
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand_distr::{Distribution, StandardNormal};

    fn cloud(n: usize, dim: usize, shift: f32, seed: u64) -> Vec<Vec<f32>> {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        (0..n)
            .map(|_| {
                (0..dim)
                    .map(|k| {
                        let z: f32 = StandardNormal.sample(&mut rng);
                        z * (1.0 + 0.1 * k as f32) + shift
                    })
                    .collect()
            })
            .collect()
    }

    #[test]
    fn fid_of_a_set_with_itself_is_zero_and_grows_with_a_shift() {
        let a = cloud(200, 16, 0.0, 1);
        assert!(fid(&a, &a).unwrap() < 1e-6);
        // A pure shift by d in every dimension adds exactly ‖d‖² = 16 d².
        let shifted: Vec<Vec<f32>> = a
            .iter()
            .map(|r| r.iter().map(|v| v + 0.5).collect())
            .collect();
        assert!((fid(&a, &shifted).unwrap() - 16.0 * 0.25).abs() < 1e-4);
        let far: Vec<Vec<f32>> = a
            .iter()
            .map(|r| r.iter().map(|v| v + 1.0).collect())
            .collect();
        assert!(fid(&a, &far).unwrap() > fid(&a, &shifted).unwrap());
        // Two samples of the same distribution are close; a scaled one is not.
        let b = cloud(200, 16, 0.0, 2);
        let scaled: Vec<Vec<f32>> = b
            .iter()
            .map(|r| r.iter().map(|v| v * 2.0).collect())
            .collect();
        assert!(fid(&a, &b).unwrap() < 0.2 * fid(&a, &scaled).unwrap());
    }

    #[test]
    fn fid_of_few_samples_in_256_dimensions() {
        // 48 unit embeddings against 300 references in 256-d, as in `mprog eval`: both
        // covariances are singular (rank 47 for the small set); the result is finite, ≈ 0
        // for a set with itself, and a shift by 0.01 in every dimension adds 256 · 1e-4.
        let unit = |rows: Vec<Vec<f32>>| -> Vec<Vec<f32>> {
            rows.into_iter()
                .map(|r| {
                    let n = r.iter().map(|v| v * v).sum::<f32>().sqrt();
                    r.into_iter().map(|v| v / n).collect()
                })
                .collect()
        };
        let a = unit(cloud(48, 256, 0.0, 4));
        let r = unit(cloud(300, 256, 0.0, 5));
        assert!(fid(&a, &a).unwrap() < 1e-6);
        let base = fid(&a, &r).unwrap();
        let shift = |rows: &[Vec<f32>], d: f32| -> Vec<Vec<f32>> {
            rows.iter()
                .map(|x| x.iter().map(|v| v + d).collect())
                .collect()
        };
        assert!(base.is_finite() && fid(&shift(&a, 0.05), &r).unwrap() > base);
        let moved = fid(&a, &shift(&a, 0.01)).unwrap();
        assert!((moved - 0.0256).abs() < 1e-4, "{moved}");
    }

    #[test]
    fn fid_of_one_dimensional_gaussians_matches_the_closed_form() {
        // 1-D: (μ₁ − μ₂)² + (σ₁ − σ₂)².
        let a = Gaussian {
            dim: 1,
            mean: vec![1.0],
            cov: vec![4.0],
        };
        let b = Gaussian {
            dim: 1,
            mean: vec![3.0],
            cov: vec![9.0],
        };
        assert!((frechet_distance(&a, &b).unwrap() - (4.0 + 1.0)).abs() < 1e-12);
    }

    #[test]
    fn diversity_of_two_points_is_their_distance() {
        let rows = vec![vec![0.0, 0.0], vec![3.0, 4.0]];
        assert!((diversity(&rows, 10, 1).unwrap() - 5.0).abs() < 1e-12);
        assert!(diversity(&rows[..1], 10, 1).is_err());
    }

    #[test]
    fn r_precision_ranks_the_own_caption() {
        // 40 one-hot-ish "labels"; motion i sits on its caption, at distance 0.
        let dim = 40;
        let onehot = |k: usize| {
            (0..dim)
                .map(|d| (d == k) as u8 as f32)
                .collect::<Vec<f32>>()
        };
        let texts: Vec<Vec<f32>> = (0..dim).map(onehot).collect();
        let groups: Vec<String> = (0..dim).map(|k| format!("g{k}")).collect();
        let distractors: Vec<Distractor> = texts
            .iter()
            .zip(&groups)
            .map(|(t, g)| Distractor {
                embedding: t.clone(),
                group: g.clone(),
            })
            .collect();
        let perfect = r_precision(&texts, &texts, &groups, &distractors, 3).unwrap();
        assert_eq!(perfect, [1.0, 1.0, 1.0]);
        // Motions placed on the *next* caption: their own is never the closest.
        let wrong: Vec<Vec<f32>> = (0..dim).map(|k| onehot((k + 1) % dim)).collect();
        let r = r_precision(&wrong, &texts, &groups, &distractors, 3).unwrap();
        // The next caption is a distractor in 31/39 of draws; when it is absent, the own
        // caption ties with every distractor at √2 and ranks first (ties do not count).
        assert!(r[0] < 0.5 && r[0] <= r[1] && r[1] <= r[2], "{r:?}");
        // Too few distractors of other groups is an error, not a silent score.
        assert!(r_precision(&texts, &texts, &groups, &distractors[..10], 3).is_err());
    }
}
