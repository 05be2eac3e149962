//! Normalisation of flat feature arrays: in, `[frames, 263]` data and the dataset's Mean/Std
//! (263 each, e.g. HumanML3D's `Mean.npy`/`Std.npy`); out, `(x − Mean)/Std` or its inverse,
//! in place. The model works on normalised features; [`super::recover_from_ric`] needs
//! de-normalised ones. The tensor versions are [`super::normalize`]/[`super::denormalize`].

use super::FeatureError;
use super::layout::FEATURE_DIM;

/// Checks Mean/Std: 263 finite values each, Std strictly positive.
pub(crate) fn check_stats(mean: &[f32], std: &[f32]) -> Result<(), FeatureError> {
    if mean.len() != FEATURE_DIM || std.len() != FEATURE_DIM {
        return Err(FeatureError::BadStats(format!(
            "Mean has {} values and Std {}; both need {FEATURE_DIM}",
            mean.len(),
            std.len()
        )));
    }
    if let Some(i) = mean.iter().position(|m| !m.is_finite()) {
        return Err(FeatureError::BadStats(format!("Mean[{i}] is not finite")));
    }
    if let Some(i) = std.iter().position(|s| !(s.is_finite() && *s > 0.0)) {
        return Err(FeatureError::BadStats(format!(
            "Std[{i}] = {} is not a positive number",
            std[i]
        )));
    }
    Ok(())
}

fn check_data(data: &[f32]) -> Result<(), FeatureError> {
    if !data.len().is_multiple_of(FEATURE_DIM) {
        return Err(FeatureError::BadFeatureLength {
            len: data.len(),
            dim: FEATURE_DIM,
        });
    }
    Ok(())
}

/// `x ← (x − Mean)/Std`, frame by frame.
pub fn normalize_slice(data: &mut [f32], mean: &[f32], std: &[f32]) -> Result<(), FeatureError> {
    check_stats(mean, std)?;
    check_data(data)?;
    for row in data.chunks_exact_mut(FEATURE_DIM) {
        for ((x, m), s) in row.iter_mut().zip(mean).zip(std) {
            *x = (*x - m) / s;
        }
    }
    Ok(())
}

/// `x ← x·Std + Mean`, frame by frame.
pub fn denormalize_slice(data: &mut [f32], mean: &[f32], std: &[f32]) -> Result<(), FeatureError> {
    check_stats(mean, std)?;
    check_data(data)?;
    for row in data.chunks_exact_mut(FEATURE_DIM) {
        for ((x, m), s) in row.iter_mut().zip(mean).zip(std) {
            *x = *x * s + m;
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_trip_and_checks() {
        let mean: Vec<f32> = (0..FEATURE_DIM).map(|i| i as f32 * 0.01).collect();
        let std: Vec<f32> = (0..FEATURE_DIM).map(|i| 0.5 + i as f32 * 0.001).collect();
        let orig: Vec<f32> = (0..2 * FEATURE_DIM).map(|i| (i as f32).sin()).collect();
        let mut x = orig.clone();
        normalize_slice(&mut x, &mean, &std).unwrap();
        assert!((x[FEATURE_DIM + 5] - (orig[FEATURE_DIM + 5] - mean[5]) / std[5]).abs() < 1e-6);
        denormalize_slice(&mut x, &mean, &std).unwrap();
        assert!(x.iter().zip(&orig).all(|(a, b)| (a - b).abs() < 1e-5));
        let mut zero_std = std.clone();
        zero_std[7] = 0.0;
        assert!(matches!(
            normalize_slice(&mut x, &mean, &zero_std),
            Err(FeatureError::BadStats(_))
        ));
        assert!(matches!(
            normalize_slice(&mut x, &mean[1..], &std),
            Err(FeatureError::BadStats(_))
        ));
        assert!(matches!(
            normalize_slice(&mut x[1..], &mean, &std),
            Err(FeatureError::BadFeatureLength { .. })
        ));
    }
}
