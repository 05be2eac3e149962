//! Adam on a flat host array, with PyTorch's defaults and update rule (β = (0.9, 0.999),
//! ε = 1e-8, bias-corrected moments, no weight decay), as PMG uses it on the noise.

/// Adam state for one flat variable.
#[derive(Clone, Debug)]
pub struct Adam {
    /// Learning rate.
    pub lr: f64,
    /// First-moment decay.
    pub beta1: f64,
    /// Second-moment decay.
    pub beta2: f64,
    /// Denominator offset.
    pub eps: f64,
    m: Vec<f64>,
    v: Vec<f64>,
    t: i32,
}

impl Adam {
    /// Fresh state for a variable of `len` values.
    pub fn new(len: usize, lr: f64) -> Self {
        Adam {
            lr,
            beta1: 0.9,
            beta2: 0.999,
            eps: 1e-8,
            m: vec![0.0; len],
            v: vec![0.0; len],
            t: 0,
        }
    }

    /// One update of `x` against the gradient `g`.
    ///
    /// # Panics
    /// If `x` or `g` do not have the length the state was made for.
    pub fn step(&mut self, x: &mut [f32], g: &[f32]) {
        assert_eq!(x.len(), self.m.len(), "Adam: variable length");
        assert_eq!(g.len(), self.m.len(), "Adam: gradient length");
        self.t += 1;
        let bc1 = 1.0 - self.beta1.powi(self.t);
        let bc2 = 1.0 - self.beta2.powi(self.t);
        for (((x, &g), m), v) in x.iter_mut().zip(g).zip(&mut self.m).zip(&mut self.v) {
            let g = g as f64;
            *m = self.beta1 * *m + (1.0 - self.beta1) * g;
            *v = self.beta2 * *v + (1.0 - self.beta2) * g * g;
            let denom = (*v / bc2).sqrt() + self.eps;
            *x -= (self.lr * (*m / bc1) / denom) as f32;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn first_step_moves_by_lr_against_the_gradient_sign() {
        let mut a = Adam::new(3, 0.1);
        let mut x = [1.0f32, 1.0, 1.0];
        a.step(&mut x, &[2.0, -0.5, 0.0]);
        assert!((x[0] - 0.9).abs() < 1e-6 && (x[1] - 1.1).abs() < 1e-6 && x[2] == 1.0);
    }

    #[test]
    fn minimises_a_quadratic() {
        let mut a = Adam::new(2, 0.05);
        let mut x = [3.0f32, -2.0];
        for _ in 0..500 {
            let g = [2.0 * (x[0] - 1.0), 2.0 * (x[1] + 1.0)];
            a.step(&mut x, &g);
        }
        assert!(
            (x[0] - 1.0).abs() < 1e-2 && (x[1] + 1.0).abs() < 1e-2,
            "{x:?}"
        );
    }
}
