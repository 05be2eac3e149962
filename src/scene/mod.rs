//! Scene geometry shared by the language (which names it), the pictures and the viewer
//! (which draw it) and the solvers (which place people in it): [`Overlay`]s, [`Contact`]s
//! and each person's world [`Placement`]. Plain data on the skeleton's joint indices, in
//! metres, world coordinates, Y up.

mod contact;
mod overlay;
mod placement;

pub use contact::{Contact, JointOf};
pub use overlay::Overlay;
pub use placement::{DEFAULT_SPACING, Placement};
