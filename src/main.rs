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
    /// Convert a motion file to other formats (by extension: bvh, npy, json, gif, png).
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
}

fn main() -> miette::Result<()> {
    let cli = Cli::parse();
    match cli.command {
        Command::Joints => print_joints(),
        Command::Data(cmd) => cli::data::run(cmd)?,
        Command::Convert(args) => cli::convert::convert(args)?,
        Command::Render(args) => cli::convert::render(args)?,
        Command::View(args) => cli::view::run(args)?,
        Command::Train(args) => cli::train::run(args)?,
        Command::Bench(cmd) => cli::bench::run(cmd)?,
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
