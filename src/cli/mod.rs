//! Subcommands of the `mprog` binary, one file each.

pub mod bench;
pub mod check;
pub mod convert;
pub mod data;
pub mod eval;
pub mod generate;
pub mod io;
pub mod score;
pub mod train;
pub mod repl;
pub mod doc;
pub mod run;
