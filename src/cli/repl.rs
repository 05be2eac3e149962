//! `mprog repl`: the interactive session (see `mprog::repl`).

use miette::{IntoDiagnostic, Result};
use mprog::model::weights::default_model_dir;
use mprog::repl::Session;
use mprog::repl::frontend::{FrontendOptions, run as run_frontend};
use std::path::PathBuf;

/// Arguments of `mprog repl`.
#[derive(clap::Args, Debug)]
pub struct ReplArgs {
    /// Program to start with (as `:load`).
    pub program: Option<PathBuf>,
    /// Motion to start with (as `:motion`).
    #[arg(long)]
    pub motion: Option<PathBuf>,
    /// Model bundle folder for `:gen` (default: models/default or $MPROG_MODEL).
    #[arg(long)]
    pub model: Option<PathBuf>,
    /// Plain ASCII diagnostics without colours.
    #[arg(long)]
    pub plain: bool,
    /// Neither read nor write the history file.
    #[arg(long)]
    pub no_history: bool,
}

/// Runs `mprog repl`.
pub fn run(args: ReplArgs) -> Result<()> {
    let mut session = Session::new(Some(args.model.unwrap_or_else(default_model_dir)));
    let opts = FrontendOptions {
        plain: args.plain,
        no_history: args.no_history,
    };
    for start in [
        args.program.map(|p| format!(":load {}", p.display())),
        args.motion.map(|m| format!(":motion {}", m.display())),
    ]
    .into_iter()
    .flatten()
    {
        print!("{}", session.handle(&start).render(!args.plain));
    }
    run_frontend(session, &opts).into_diagnostic()
}
