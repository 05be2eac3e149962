//! `mprog mcp`: serve the Model Context Protocol on stdin/stdout (see `mprog::mcp`).
//! Nothing else may write to stdout while it runs: it carries the protocol.

use miette::{Result, miette};
use std::path::PathBuf;

/// Arguments of `mprog mcp`.
#[derive(clap::Args, Debug)]
pub struct McpArgs {
    /// Folder that runs write to and `score` reads from; requests name files in it by
    /// relative path (created if missing).
    #[arg(long, default_value = "mprog-out")]
    pub out_dir: PathBuf,
    /// Longest a run may take, in seconds; a longer one is stopped.
    #[arg(long, default_value_t = 600)]
    pub time_limit: u64,
    /// Model bundle folder for runs (default: models/default or $MPROG_MODEL).
    #[arg(long)]
    pub model: Option<PathBuf>,
}

/// Runs `mprog mcp` until the client closes the connection.
pub fn run(args: McpArgs) -> Result<()> {
    let exe = std::env::current_exe().map_err(|e| miette!("cannot find this binary: {e}"))?;
    // The card lists the actions of the model the runs use.
    let model_dir = args
        .model
        .clone()
        .unwrap_or_else(mprog::model::weights::default_model_dir);
    let actions: Vec<(String, usize)> = mprog::model::weights::trained_actions(&model_dir)
        .unwrap_or_default()
        .into_iter()
        .map(|a| (a.caption, a.clips))
        .collect();
    let card = mprog::docgen::prompt::system_prompt_for(&actions);
    let config = mprog::mcp::Config {
        out_dir: args.out_dir,
        exe,
        model: args.model,
        time_limit: std::time::Duration::from_secs(args.time_limit.max(1)),
        card: Some(card),
        // `check` warns on every prompt `run` would (sentence models).
        far_prompts: super::check::sentence_reader(&model_dir)
            .map(|text| std::sync::Arc::from(super::check::prompt_report_of(text))),
        // ... and of every pose no training clip comes near.
        coverage: super::check::coverage_of(&model_dir).map(std::sync::Arc::new),
    };
    mprog::mcp::serve_stdio(&config).map_err(|e| miette!("{e}"))
}
