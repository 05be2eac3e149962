//! Normalisation statistics as HumanML3D computes them: per-feature mean, and per-feature
//! std averaged within each of the seven feature blocks (so joints share one scale).

use super::store::FEATURE_DIM;

/// The seven blocks of the 263-dim layout.
const BLOCKS: [std::ops::Range<usize>; 7] = [0..1, 1..3, 3..4, 4..67, 67..193, 193..259, 259..263];

/// Smallest std kept, so constant features (e.g. contacts of a set with no steps) do not
/// blow up when normalised.
const MIN_STD: f64 = 1e-3;

/// (mean, block-averaged std) over the rows of all clips.
pub fn feature_stats(clips: &[&[f32]]) -> (Vec<f32>, Vec<f32>) {
    let mut sum = vec![0f64; FEATURE_DIM];
    let mut sq = vec![0f64; FEATURE_DIM];
    let mut n = 0usize;
    for rows in clips {
        for row in rows.chunks_exact(FEATURE_DIM) {
            for (f, &v) in row.iter().enumerate() {
                sum[f] += v as f64;
                sq[f] += (v as f64) * (v as f64);
            }
            n += 1;
        }
    }
    let n = n.max(1) as f64;
    let mean: Vec<f64> = sum.iter().map(|s| s / n).collect();
    let std: Vec<f64> = sq
        .iter()
        .zip(&mean)
        .map(|(q, m)| (q / n - m * m).max(0.0).sqrt())
        .collect();
    let mut block_std = vec![0f32; FEATURE_DIM];
    for b in BLOCKS {
        let avg = std[b.clone()].iter().sum::<f64>() / b.len() as f64;
        for f in b {
            block_std[f] = avg.max(MIN_STD) as f32;
        }
    }
    (mean.iter().map(|&m| m as f32).collect(), block_std)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn std_is_averaged_within_blocks() {
        let mut a = vec![0f32; FEATURE_DIM];
        let mut b = vec![0f32; FEATURE_DIM];
        a[4] = 1.0; // ric block: one feature varies by ±0.5 → its std 0.5, block mean 0.5/63
        b[4] = 0.0;
        a[0] = 2.0;
        let (mean, std) = feature_stats(&[&a, &b]);
        assert!((mean[4] - 0.5).abs() < 1e-6);
        assert!((std[5] - 0.5 / 63.0).abs() < 1e-6);
        assert!((std[0] - 1.0).abs() < 1e-6);
        assert!((std[100] - MIN_STD as f32).abs() < 1e-9);
    }
}
