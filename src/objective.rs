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

    /// [`Self::error`] counting only frames before `until`: a long motion is made window
    /// by window, and frames from `until` on are placeholders not made yet. The default
    /// counts every frame (an error with no notion of time).
    fn error_until(&self, joints: Tensor<5>, until: usize) -> Tensor<1> {
        let _ = until;
        self.error(joints)
    }

    /// [`Self::terms`] counting only frames before `until` (see [`Self::error_until`]).
    fn terms_until(&self, joints: Tensor<5>, until: usize) -> Tensor<2> {
        let _ = until;
        self.terms(joints)
    }

    /// Per frame of a motion of `frames` frames, whether the error reads it at all (a
    /// statement's window, with the neighbours its velocities read), met or not; frames
    /// it never reads are untouched time, which an edit of a take holds. `None` (the
    /// default): every frame may count.
    fn active_frames(&self, frames: usize) -> Option<Vec<bool>> {
        let _ = frames;
        None
    }
}

impl<F: Fn(Tensor<5>) -> Tensor<1>> MotionError for F {
    fn error(&self, joints: Tensor<5>) -> Tensor<1> {
        self(joints)
    }
}
