//! The cosine noise schedule (1000 steps, MDM/improved-DDPM) and its derived coefficients,
//! plus timestep respacing for DDIM and shortened DDPM chains.
//!
//! All coefficients are computed in f64 on the host; samplers read them as scalars.

/// Number of diffusion steps of the base schedule.
pub const DIFFUSION_STEPS: usize = 1000;

/// Coefficients of a (possibly respaced) noise schedule.
#[derive(Clone, Debug)]
pub struct NoiseSchedule {
    /// Original timestep index of each step (what the network is told), ascending.
    pub timesteps: Vec<usize>,
    /// ᾱ_t at each step.
    pub alphas_cumprod: Vec<f64>,
    /// β_t of each step (re-derived from ᾱ when respaced).
    pub betas: Vec<f64>,
}

fn cosine_alpha_bar(s: f64) -> f64 {
    (((s + 0.008) / 1.008) * std::f64::consts::FRAC_PI_2)
        .cos()
        .powi(2)
}

impl NoiseSchedule {
    /// The full cosine schedule: β_i = min(1 − ᾱ((i+1)/T)/ᾱ(i/T), 0.999).
    pub fn cosine(steps: usize) -> Self {
        let betas: Vec<f64> = (0..steps)
            .map(|i| {
                let a = cosine_alpha_bar(i as f64 / steps as f64);
                let b = cosine_alpha_bar((i + 1) as f64 / steps as f64);
                (1.0 - b / a).min(0.999)
            })
            .collect();
        let mut prod = 1.0;
        let alphas_cumprod = betas
            .iter()
            .map(|b| {
                prod *= 1.0 - b;
                prod
            })
            .collect();
        NoiseSchedule {
            timesteps: (0..steps).collect(),
            alphas_cumprod,
            betas,
        }
    }

    /// Keeps `count` evenly strided steps of this schedule (the "ddimN" rule: stride
    /// T/count, steps {0, s, 2s, …}) and re-derives β from ᾱ at those steps.
    pub fn respaced(&self, count: usize) -> Self {
        let total = self.timesteps.len();
        let count = count.clamp(1, total);
        let stride = total / count;
        let kept: Vec<usize> = (0..count).map(|i| i * stride).collect();
        self.at(&kept)
    }

    /// The steps of this schedule at the given step indices (any order; kept ascending,
    /// once each), β re-derived from ᾱ at those steps.
    pub fn at(&self, timesteps: &[usize]) -> Self {
        let mut kept: Vec<usize> = timesteps
            .iter()
            .map(|&t| t.min(self.timesteps.len() - 1))
            .collect();
        kept.sort_unstable();
        kept.dedup();
        let mut last = 1.0;
        let mut betas = Vec::with_capacity(kept.len());
        let mut alphas = Vec::with_capacity(kept.len());
        for &k in &kept {
            let a = self.alphas_cumprod[k];
            betas.push(1.0 - a / last);
            alphas.push(a);
            last = a;
        }
        NoiseSchedule {
            timesteps: kept.iter().map(|&k| self.timesteps[k]).collect(),
            alphas_cumprod: alphas,
            betas,
        }
    }

    /// Number of steps.
    pub fn len(&self) -> usize {
        self.timesteps.len()
    }

    /// True for an empty schedule (never produced by the constructors).
    pub fn is_empty(&self) -> bool {
        self.timesteps.is_empty()
    }

    /// ᾱ of the previous step (1 before the first).
    pub fn alpha_cumprod_prev(&self, i: usize) -> f64 {
        if i == 0 {
            1.0
        } else {
            self.alphas_cumprod[i - 1]
        }
    }

    /// Posterior q(x_{i−1} | x_i, x0) mean coefficients (on x0, on x_i) and variance.
    pub fn posterior(&self, i: usize) -> PosteriorCoefficients {
        let a = self.alphas_cumprod[i];
        let a_prev = self.alpha_cumprod_prev(i);
        let beta = self.betas[i];
        let variance = beta * (1.0 - a_prev) / (1.0 - a);
        // "Clipped" log variance: step 0 has zero variance, so use step 1's.
        let clipped = if i == 0 && self.len() > 1 {
            self.posterior(1).variance
        } else {
            variance
        };
        PosteriorCoefficients {
            coef_x0: beta * a_prev.sqrt() / (1.0 - a),
            coef_xt: (1.0 - a_prev) * (1.0 - beta).sqrt() / (1.0 - a),
            variance,
            variance_clipped: clipped,
        }
    }
}

/// A consistency model's boundary scalings at timestep `t` (LCM: σ_data 0.5, timestep
/// scaling 10): f(x, t) = c_skip·x + c_out·x̂0, so f(x, 0) = x exactly and from t = 20 on
/// f is the network's x̂0 within 1e-5.
pub fn consistency_scalings(t: usize) -> (f64, f64) {
    let sigma2 = 0.25;
    let scaled = t as f64 * 10.0;
    let c_skip = sigma2 / (scaled * scaled + sigma2);
    let c_out = scaled / (scaled * scaled + sigma2).sqrt();
    (c_skip, c_out)
}

/// Timesteps of a `steps`-step consistency chain on a `grid`-step DDIM grid, descending:
/// LCM's rule, every (grid / steps)-th grid point from the top.
pub fn consistency_timesteps(grid: usize, steps: usize) -> Vec<usize> {
    let grid = grid.clamp(1, DIFFUSION_STEPS);
    let stride = DIFFUSION_STEPS / grid;
    let steps = steps.clamp(1, grid);
    let skip = grid / steps;
    (0..steps).map(|k| (grid - 1 - k * skip) * stride).collect()
}

/// Coefficients of the Gaussian posterior of one step.
#[derive(Clone, Copy, Debug)]
pub struct PosteriorCoefficients {
    /// Mean coefficient on x̂0.
    pub coef_x0: f64,
    /// Mean coefficient on x_t.
    pub coef_xt: f64,
    /// β̃_t.
    pub variance: f64,
    /// β̃_t with step 0 replaced by step 1 (used for log-variance and guidance scale).
    pub variance_clipped: f64,
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cosine_schedule_matches_reference_values() {
        let s = NoiseSchedule::cosine(DIFFUSION_STEPS);
        assert!((s.betas[0] - 4.13e-5).abs() < 1e-6, "{}", s.betas[0]);
        assert!((s.betas[999] - 0.999).abs() < 1e-12);
        assert!(s.alphas_cumprod[999] < 1e-8);
        assert!(s.alphas_cumprod.windows(2).all(|w| w[1] < w[0]));
    }

    #[test]
    fn respacing_keeps_alpha_bar_at_kept_steps() {
        let s = NoiseSchedule::cosine(DIFFUSION_STEPS);
        let r = s.respaced(100);
        assert_eq!(r.len(), 100);
        assert_eq!(r.timesteps[1], 10);
        assert_eq!(*r.timesteps.last().unwrap(), 990);
        for (i, &t) in r.timesteps.iter().enumerate() {
            assert!((r.alphas_cumprod[i] - s.alphas_cumprod[t]).abs() < 1e-12);
        }
    }

    #[test]
    fn consistency_chains_follow_lcm() {
        assert_eq!(consistency_timesteps(50, 4), vec![980, 740, 500, 260]);
        assert_eq!(consistency_timesteps(50, 1), vec![980]);
        assert_eq!(consistency_timesteps(50, 2), vec![980, 480]);
        let (skip, out) = consistency_scalings(0);
        assert_eq!((skip, out), (1.0, 0.0));
        let (skip, out) = consistency_scalings(20);
        assert!(skip < 1e-5 && (out - 1.0).abs() < 1e-5, "{skip} {out}");
    }

    #[test]
    fn posterior_mean_of_clean_input_is_clean() {
        let s = NoiseSchedule::cosine(DIFFUSION_STEPS);
        for i in [1, 10, 500, 999] {
            let p = s.posterior(i);
            // x_t = sqrt(ᾱ) x0 with no noise ⇒ mean = sqrt(ᾱ_prev) x0.
            let mean = p.coef_x0 + p.coef_xt * s.alphas_cumprod[i].sqrt();
            assert!((mean - s.alpha_cumprod_prev(i).sqrt()).abs() < 1e-9);
        }
    }
}
