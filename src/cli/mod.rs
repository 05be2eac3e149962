//! Subcommands of the `mprog` binary, one file each.

pub mod bench;
pub mod data;
pub mod train;
