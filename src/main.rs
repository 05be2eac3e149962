//! The `mprog` command line.

mod cli;

use clap::{Parser, Subcommand};

/// Programmable human motion generation.
#[derive(Parser)]
#[command(name = "mprog", version, about)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Print the joint names and aliases of the skeleton.
    Joints,
    /// Generate motions from text with the shipped model.
    Gen(cli::generate::GenArgs),
    /// Convert a motion file to other formats (each output's extension picks its kind).
    Convert(cli::convert::ConvertArgs),
    /// Render a motion file as an animated GIF or a PNG strip.
    Render(cli::convert::RenderArgs),
    /// Write a self-contained HTML page that plays a motion in 3-D (overlays, contacts and
    /// per-statement error charts from the file's meta).
    View(cli::view::ViewArgs),
    /// Build a training set from BVH files.
    #[command(subcommand)]
    Data(cli::data::DataCommand),
    /// Timing benchmarks printed as markdown tables.
    #[command(subcommand)]
    Bench(cli::bench::BenchCommand),
    /// Train the denoiser on a dataset built by `mprog data build`.
    Train(cli::train::TrainArgs),
    /// Train a realism ControlNet (OmniControl) on a frozen base bundle, resumable.
    TrainControl(cli::train_control::TrainControlArgs),
    /// Run a program: generate with the model, steered by the program's error.
    Run(cli::run::RunArgs),
    /// A program's error on a motion file, per statement, with an optional plot over time.
    Score(cli::score::ScoreArgs),
    /// Serve the Model Context Protocol on stdin/stdout: tools check, score, run, joints
    /// and library, and the prompt card, for LLM agents.
    Mcp(cli::mcp::McpArgs),
    /// Check `.mprog` programs and print their diagnostics.
    Check(cli::check::CheckArgs),
    /// Evaluate a model against real test clips (metrics, FID, R-precision), or train
    /// the evaluator (`mprog eval train-encoder`).
    Eval(cli::eval::EvalArgs),
    /// Interactive session: type constraints, score them on a motion, see gradients.
    Repl(cli::repl::ReplArgs),
    /// Print a self-contained system prompt for an LLM that writes `.mprog` programs.
    Prompt,
    /// Generate documentation pages (the library reference, the cookbook).
    #[command(subcommand)]
    Doc(cli::doc::DocCommand),
}

fn main() -> miette::Result<()> {
    mprog::backend::tune_allocator();
    let cli = Cli::parse();
    mprog::backend::on_compute_pool(|| run(cli))
}

fn run(cli: Cli) -> miette::Result<()> {
    match cli.command {
        Command::Joints => print_joints(),
        Command::Gen(args) => cli::generate::run(args)?,
        Command::Data(cmd) => cli::data::run(cmd)?,
        Command::Convert(args) => cli::convert::convert(args)?,
        Command::Render(args) => cli::convert::render(args)?,
        Command::View(args) => cli::view::run(args)?,
        Command::Train(args) => cli::train::run(args)?,
        Command::TrainControl(args) => cli::train_control::run(args)?,
        Command::Bench(cmd) => cli::bench::run(cmd)?,
        Command::Score(args) => cli::score::run(args)?,
        Command::Run(args) => cli::run::run(args)?,
        Command::Repl(args) => cli::repl::run(args)?,
        Command::Prompt => print!(
            "{}",
            mprog::docgen::prompt::system_prompt_for(&mprog::model::weights::shipped_actions())
        ),
        Command::Doc(cmd) => cli::doc::run(cmd)?,
        Command::Check(args) => {
            if !cli::check::run(&args)? {
                std::process::exit(1);
            }
        }
        Command::Eval(args) => cli::eval::run(args)?,
        Command::Mcp(args) => cli::mcp::run(args)?,
    }
    Ok(())
}

fn print_joints() {
    for (i, name) in mprog::skeleton::JOINT_NAMES.iter().enumerate() {
        let aliases: Vec<&str> = mprog::skeleton::ALIASES
            .iter()
            .filter(|(_, j)| *j == i)
            .map(|(a, _)| *a)
            .collect();
        println!("{i:2} {name:15} {}", aliases.join(", "));
    }
}
