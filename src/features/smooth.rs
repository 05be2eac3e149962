//! 1-D Gaussian smoothing along time, as scipy's `gaussian_filter1d(x, sigma, axis=0,
//! mode='nearest')` with the default `truncate=4.0`: in, a sequence of vectors; out, the
//! smoothed sequence (same length). Used for HumanML3D's per-frame facing direction.

use glam::DVec3;

/// Smooths `xs` with a normalised Gaussian of standard deviation `sigma` frames, radius
/// `round(4·sigma)`, edges extended by repeating the first/last value ('nearest').
pub fn gaussian_nearest(xs: &[DVec3], sigma: f64) -> Vec<DVec3> {
    if xs.is_empty() {
        return Vec::new();
    }
    let radius = (4.0 * sigma + 0.5) as i64;
    let weights: Vec<f64> = (-radius..=radius)
        .map(|k| (-0.5 * (k * k) as f64 / (sigma * sigma)).exp())
        .collect();
    let total: f64 = weights.iter().sum();
    let last = xs.len() as i64 - 1;
    (0..xs.len() as i64)
        .map(|i| {
            let sum: DVec3 = weights
                .iter()
                .zip(-radius..=radius)
                .map(|(w, k)| xs[(i + k).clamp(0, last) as usize] * *w)
                .sum();
            sum / total
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn constant_stays_constant_and_step_is_smoothed_symmetrically() {
        let c = vec![DVec3::new(1.0, 2.0, 3.0); 10];
        for v in gaussian_nearest(&c, 20.0) {
            assert!((v - DVec3::new(1.0, 2.0, 3.0)).length() < 1e-12);
        }
        // A step in the middle of a long sequence: the value at the step is the mean.
        let step: Vec<DVec3> = (0..400)
            .map(|i| DVec3::splat(if i < 200 { 0.0 } else { 1.0 }))
            .collect();
        let s = gaussian_nearest(&step, 2.0);
        // Between samples 199 and 200 the smoothed curve crosses 0.5 symmetrically.
        assert!((s[199].x + s[200].x - 1.0).abs() < 1e-12);
        assert!(s[199].x > 0.3 && s[199].x < 0.5);
        assert!(s[0].x == 0.0 && s[399].x == 1.0);
    }

    #[test]
    fn matches_scipy() {
        // Values printed by scipy 1.x: gaussian_filter1d(x, sigma, mode='nearest').
        let cases: [(&[f64], f64, &[f64]); 2] = [
            (
                &[0.0, 1.0, 2.0, 3.0, 4.0],
                1.0,
                &[0.36378461, 1.06312251, 2.0, 2.93687749, 3.63621539],
            ),
            (
                &[0.0, 3.0, 1.0, 7.0, 2.0, 2.0, 9.0, 4.0, 0.0, 5.0],
                2.5,
                &[
                    1.32825904, 1.91776429, 2.52761032, 3.08184115, 3.52235818, 3.82175812,
                    3.98984174, 4.07478501, 4.14693498, 4.26222138,
                ],
            ),
        ];
        for (input, sigma, want) in cases {
            let xs: Vec<DVec3> = input.iter().map(|&x| DVec3::new(x, -x, 0.0)).collect();
            for (v, w) in gaussian_nearest(&xs, sigma).iter().zip(want) {
                assert!(
                    (v.x - w).abs() < 1e-7 && (v.y + w).abs() < 1e-7,
                    "{} vs {w}",
                    v.x
                );
            }
        }
    }
}
