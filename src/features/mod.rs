//! HumanML3D 263-dim features: extraction from joint positions and `recover_from_ric`.
//!
//! In: a [`Motion`](crate::motion::Motion) (global joint positions, metres, Y up, 20 fps).
//! Out: [`Features`], `[frames − 1, 263]` rows in HumanML3D's layout ([`layout`]), and back:
//! [`recover_from_ric`] (plain `f32`) and [`recover_from_ric_tensor`] (burn, batched,
//! differentiable) turn de-normalised features into joint positions again.
//!
//! | step | function | what it does |
//! | --- | --- | --- |
//! | retarget (optional) | [`uniform_skeleton`] | every bone set to HumanML3D's length, root scaled by leg length |
//! | canonicalise | [`canonicalize`] | floor at y = 0, frame-0 root XZ at the origin, frame 0 faces +Z |
//! | rotations | [`kinematics`] | per-bone rotations from positions, HumanML3D's local rotations, facing |
//! | features | [`extract`] | the seven blocks of [`layout`] |
//! | back to joints | [`recover_from_ric`], [`recover_from_ric_tensor`] | integrate the root, un-rotate the ric block |
//!
//! The reference is HumanML3D's `motion_representation.ipynb` and `common/skeleton.py`,
//! described in `reference-algorithms.md` §5, quirks included (the sign-flipped hip term and
//! the Gaussian smoothing of the per-frame facing, the half-angle yaw velocity).

mod canonical;
mod error;
mod extract;
pub mod kinematics;
pub mod layout;
mod mirror;
mod norm;
mod recover;
mod retarget;
mod smooth;
mod tensor;

pub use canonical::canonicalize;
pub use error::FeatureError;
pub use extract::{ExtractOptions, FOOT_CONTACT_THRESHOLD, extract};
pub use layout::{FEATURE_DIM, Features};
pub use mirror::FeatureMirror;
pub use norm::{denormalize_slice, normalize_slice};
pub use recover::recover_from_ric;
pub use retarget::uniform_skeleton;
pub use tensor::{denormalize, normalize, recover_from_ric_tensor};
