//! The `mprog` command line.

mod check_cmd;

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
    /// Check `.mprog` programs and print their diagnostics.
    Check(check_cmd::CheckArgs),
}

fn main() -> miette::Result<()> {
    let cli = Cli::parse();
    match cli.command {
        Command::Check(args) => {
            if !check_cmd::run(&args)? {
                std::process::exit(1);
            }
        }
        Command::Joints => {
            for (i, name) in mprog::skeleton::JOINT_NAMES.iter().enumerate() {
                let aliases: Vec<&str> = mprog::skeleton::ALIASES
                    .iter()
                    .filter(|(_, j)| *j == i)
                    .map(|(a, _)| *a)
                    .collect();
                println!("{i:2} {name:15} {}", aliases.join(", "));
            }
        }
    }
    Ok(())
}
