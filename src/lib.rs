//! mprog: programmable human motion generation. A `.mprog` program describes what a
//! motion must satisfy; mprog parses and checks it, lowers it to a differentiable error
//! on joint positions, and uses that error to steer a motion diffusion model.
//!
//! The map of the code follows (it is `ARCHITECTURE.md` at the repository root).
#![doc = include_str!("../ARCHITECTURE.md")]

pub mod backend;
pub mod coverage;
pub mod dataset;
pub mod docgen;
pub mod features;
pub mod formats;
pub mod fsutil;
pub mod interrupt;
pub mod lang;
pub mod mcp;
pub mod metrics;
pub mod model;
pub mod motion;
pub mod objective;
pub mod render;
pub mod repl;
pub mod scene;
pub mod skeleton;
pub mod solve;
pub mod tasks;
pub mod view;
