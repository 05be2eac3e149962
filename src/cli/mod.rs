//! Subcommands of the `mprog` binary, one file each.

pub mod train;
pub mod data;
pub mod bench;
