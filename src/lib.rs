//! mprog: programmable human motion generation.
//!
//! A `.mprog` program describes what a motion must satisfy; mprog parses and checks it,
//! lowers it to a differentiable error on joint positions, and uses that error to steer
//! a motion diffusion model.
//!
//! | stage | module | input → output |
//! | --- | --- | --- |
//! | motion data | [`formats`], [`features`], [`dataset`] | BVH / npy → [`motion::Motion`] → 263-dim HumanML3D features → training set |
//! | model | [`model`] | features + text → denoiser, samplers, training |
//! | language | [`lang`] | source → AST → checked IR → burn error graph |
//! | solvers | [`solve`] | error graph + prompts → guided / optimised motions |
//! | pictures | [`render`] | motions, curves → GIF / PNG |
//! | interfaces | [`repl`], [`docgen`] | interactive sessions; LLM prompt card, book pages |
//! | viewer | [`view`] | motions + program geometry → one self-contained HTML page |
//!
//! Conventions everywhere: HumanML3D 22-joint skeleton ([`skeleton`]), metres, Y up,
//! 20 fps; tensors of joint positions are `[batch, people, frames, 22, 3]`.

pub mod backend;
pub mod dataset;
pub mod docgen;
pub mod eval;
pub mod features;
pub mod formats;
pub mod fsutil;
pub mod interrupt;
pub mod lang;
pub mod model;
pub mod motion;
pub mod render;
pub mod repl;
pub mod skeleton;
pub mod solve;
pub mod tasks;
pub mod view;
