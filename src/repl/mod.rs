//! The interactive REPL (`mprog repl`), split like Nickel's: a backend that knows nothing
//! of terminals and a rustyline frontend.
//!
//! | file | role |
//! | --- | --- |
//! | [`session`] | [`Session`]: the program typed or loaded so far, the current motion, the model bundle; `handle(input) -> Reply` |
//! | [`command`] | `:command` parsing and the command table (`:help`, completion) |
//! | [`probe`] | `:eval`, `:grad`, `:score`: the input compiled against the session's program |
//! | [`summary`] | min/mean/max, sparklines and bars |
//! | [`reply`] | [`Reply`]: text, diagnostics and errors, rendered fancy or plain |
//! | [`input`] | when multi-line input is complete |
//! | [`complete`] | completion candidates |
//! | [`frontend`] | rustyline editor, history file, the read–eval–print loop |

pub mod command;
pub mod complete;
pub mod frontend;
pub mod input;
pub mod probe;
pub mod reply;
pub mod session;
pub mod summary;

pub use reply::{Item, Reply};
pub use session::{CurrentMotion, Session};
