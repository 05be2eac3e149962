//! Seeded Gaussian noise, generated on the host so the same seed gives the same numbers
//! on every backend and device.

use burn::prelude::*;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, StandardNormal};

/// A deterministic stream of standard normal tensors.
pub struct NoiseSource {
    rng: ChaCha8Rng,
}

impl NoiseSource {
    /// A stream for `seed`.
    pub fn new(seed: u64) -> Self {
        NoiseSource {
            rng: ChaCha8Rng::seed_from_u64(seed),
        }
    }

    /// Host values of shape `dims`.
    pub fn values(&mut self, count: usize) -> Vec<f32> {
        (0..count)
            .map(|_| StandardNormal.sample(&mut self.rng))
            .collect()
    }

    /// A standard normal tensor.
    pub fn tensor<const D: usize>(&mut self, dims: [usize; D], device: &Device) -> Tensor<D> {
        let n = dims.iter().product();
        Tensor::from_data(TensorData::new(self.values(n), dims), device)
    }
}
