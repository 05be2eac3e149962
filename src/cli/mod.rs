//! Subcommands of the `mprog` binary, one file each.

pub mod bench;
pub mod bench_solvers;
pub mod bench_tasks;
pub mod check;
pub mod convert;
pub mod data;
pub mod doc;
pub mod eval;
pub mod export;
pub mod generate;
pub mod io;
pub mod mcp;
pub mod repl;
pub mod run;
pub mod score;
pub mod take;
pub mod train;
pub mod train_control;
pub mod view;

/// The burn device of this command: flex, or the GPU backend named by `MPROG_DEVICE`.
pub fn device() -> miette::Result<burn::prelude::Device> {
    mprog::backend::device_from_env().map_err(|e| miette::miette!("{e}"))
}
