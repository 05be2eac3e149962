//! The contract between the language and the solvers: [`MotionError`], a differentiable
//! error on joint positions. `lang::Program` implements it; `solve` minimises any
//! implementation, so neither module knows the other.

use burn::tensor::Tensor;

/// Differentiable error of a batch of motions: joints `[batch, people, frames, 22, 3]`
/// (metres, Y up, world placement applied) → total error per sample `[batch]`.
///
/// Solvers minimise it. It must be built from burn tensor ops on the input's device so
/// gradients reach the joints; it is called on plain and on autodiff devices. Closures
/// `Fn(Tensor<5>) -> Tensor<1>` implement it.
pub trait MotionError {
    /// `[batch]` error of each sample.
    fn error(&self, joints: Tensor<5>) -> Tensor<1>;

    /// `[batch, terms]`: the error split into terms that sum to [`Self::error`] (a
    /// program's statements). The guide sizes a step for each term on its own, so a stiff
    /// term cannot set the pace of the others; one term by default.
    fn terms(&self, joints: Tensor<5>) -> Tensor<2> {
        self.error(joints).unsqueeze_dim(1)
    }
}

impl<F: Fn(Tensor<5>) -> Tensor<1>> MotionError for F {
    fn error(&self, joints: Tensor<5>) -> Tensor<1> {
        self(joints)
    }
}
