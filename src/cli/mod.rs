//! Subcommands of the `mprog` binary, one file each.

pub mod bench;
pub mod data;
pub mod train;
pub mod convert;
pub mod export;
pub mod io;
pub mod view;
