//! Subcommands of the `mprog` binary, one file each.

pub mod bench;
pub mod data;
pub mod train;
pub mod convert;
pub mod io;
pub mod check;
pub mod generate;
pub mod repl;
pub mod doc;
