//! Subcommands of the `mprog` binary, one file each.

pub mod bench;
pub mod check;
pub mod convert;
pub mod data;
pub mod doc;
pub mod eval;
pub mod export;
pub mod generate;
pub mod io;
pub mod repl;
pub mod run;
pub mod score;
pub mod train;
pub mod view;
