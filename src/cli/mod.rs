//! Subcommands of the `mprog` binary, one file each.

pub mod bench;
pub mod check;
pub mod convert;
pub mod data;
pub mod generate;
pub mod io;
pub mod train;
