//! Cooperative interruption of long commands (training, generation).
//!
//! An [`Interrupt`] is a shared flag. [`Interrupt::on_signals`] sets it on SIGINT (Ctrl-C)
//! and SIGTERM through `signal-hook`; long loops ([`crate::model::train::TrainRun::run`],
//! [`crate::model::generate::generate_interruptible`]) read it between steps and stop
//! cleanly: training saves a checkpoint first, generation writes nothing. A second signal
//! while the first is being handled ends the process at once (exit status 130); outputs
//! are written atomically and checkpoints are swapped in by renames, so even that leaves
//! no half-written file under its final name.

use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};

/// A stop request shared between a signal handler (or a test) and a long loop.
#[derive(Clone, Debug, Default)]
pub struct Interrupt(Arc<AtomicBool>);

impl Interrupt {
    /// A flag nobody sets unless [`Interrupt::request`] is called.
    pub fn new() -> Self {
        Self::default()
    }

    /// A flag set by SIGINT and SIGTERM; a second signal exits with status 130.
    pub fn on_signals() -> std::io::Result<Self> {
        use signal_hook::consts::{SIGINT, SIGTERM};
        let flag = Arc::new(AtomicBool::new(false));
        for signal in [SIGINT, SIGTERM] {
            // Order matters: the shutdown is armed only once the flag is already set.
            signal_hook::flag::register_conditional_shutdown(signal, 130, flag.clone())?;
            signal_hook::flag::register(signal, flag.clone())?;
        }
        Ok(Interrupt(flag))
    }

    /// Asks the loop to stop.
    pub fn request(&self) {
        self.0.store(true, Ordering::SeqCst);
    }

    /// Whether a stop was asked for.
    pub fn is_requested(&self) -> bool {
        self.0.load(Ordering::SeqCst)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn clones_share_the_flag() {
        let a = Interrupt::new();
        let b = a.clone();
        assert!(!b.is_requested());
        a.request();
        assert!(b.is_requested());
        assert!(!Interrupt::new().is_requested());
    }
}
