//! `mprog score`: a program's error on a motion file, statement by statement, and a plot
//! of each statement's error over time.

use super::io::load_people;
use miette::{IntoDiagnostic, Result, miette};
use mprog::lang::{FrameErrors, Program};
use mprog::render::{PlotOptions, Series, plot_lines};
use std::path::PathBuf;

/// Arguments of `mprog score`.
#[derive(clap::Args)]
pub struct ScoreArgs {
    /// The program.
    program: PathBuf,
    /// The motion: .bvh, .npy or .json (one motion per person of the program).
    motion: PathBuf,
    /// Override a parameter: `--set diameter=0.5` (in the unit of its default).
    #[arg(long = "set", value_parser = super::check::parse_override)]
    set: Vec<(String, f64)>,
    /// Plot every statement's error over time to this PNG.
    #[arg(long)]
    plot: Option<PathBuf>,
}

/// Compiles a program file, printing diagnostics as `mprog check` does on failure.
pub fn compile_file(path: &std::path::Path, set: &[(String, f64)]) -> Result<Program> {
    let source = std::fs::read_to_string(path)
        .map_err(|e| miette!("cannot read {}: {e}", path.display()))?;
    let name = path.display().to_string();
    mprog::lang::compile(&source, &name, set).map_err(|diags| {
        eprint!(
            "{}",
            diags.render_for(std::io::IsTerminal::is_terminal(&std::io::stderr()))
        );
        miette!("{name} has errors")
    })
}

/// Runs `mprog score`.
pub fn run(args: ScoreArgs) -> Result<()> {
    let program = compile_file(&args.program, &args.set)?;
    let (people, _) = load_people(&args.motion)?;
    let wanted = program.people().len().max(1);
    if people.len() != wanted {
        return Err(miette!(
            "{} declares {wanted} people but {} holds {}",
            args.program.display(),
            args.motion.display(),
            people.len()
        ));
    }
    let device = super::device()?;
    let joints = mprog::view::program::people_tensor(&people, &device);
    let evaluation = program.try_evaluate(joints.clone()).into_diagnostic()?;
    let traces = program.evaluate_frames(joints).into_diagnostic()?;
    let per = evaluation
        .per_statement
        .into_data()
        .convert::<f32>()
        .try_into_vec::<f32>()
        .map_err(|e| miette!("{e:?}"))?;
    let total = evaluation.total.into_scalar::<f32>();
    println!("| line | statement | error | unit |\n| --- | --- | --- | --- |");
    for (s, e) in program.statements().iter().zip(&per) {
        let text = s
            .label
            .split_once(": ")
            .map_or(s.label.as_str(), |(_, t)| t)
            .trim();
        println!("| {} | `{text}` | {e:.4} | {} |", s.line, s.unit);
    }
    println!("| | **total** | {total:.4} | |");
    if let Some(path) = &args.plot {
        plot_traces(&program, &traces, path)?;
        eprintln!("wrote {}", path.display());
    }
    Ok(())
}

fn plot_traces(program: &Program, traces: &[FrameErrors], path: &std::path::Path) -> Result<()> {
    let series: Vec<Series> = program
        .statements()
        .iter()
        .zip(traces)
        .map(|(s, t)| Series {
            name: format!("line {}", s.line),
            points: t
                .frames
                .iter()
                .zip(&t.errors[0])
                .zip(&t.applies[0])
                .filter(|(_, a)| **a)
                .map(|((&f, &v), _)| (f as f32 / 20.0, v))
                .collect(),
        })
        .collect();
    plot_lines(
        path,
        &format!("{}: error per statement", program.name()),
        "time (s)",
        "weighted error",
        &series,
        &PlotOptions::default(),
    )
    .into_diagnostic()
}
