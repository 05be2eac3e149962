//! `mprog score`: a program's error on a motion file, statement by statement, a plot of
//! each statement's error over time (the prompt timeline's spans shaded), and how well
//! each prompt span matches its prompt by the learned evaluator
//! ([`mprog::metrics::text_match`]: motions of any length, spans longer than the
//! evaluator reads scored in overlapping windows and averaged).

use super::io::load_people;
use miette::{IntoDiagnostic, Result, miette};
use mprog::formats::Meta;
use mprog::lang::{FrameErrors, Program};
use mprog::metrics::text_match::{PromptSpan, SpanMatch, text_match};
use mprog::motion::Motion;
use mprog::render::{Band, PlotOptions, Series, plot_lines};
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
    /// The evaluator that scores each prompt span against its prompt (default: the
    /// shipped one, `models/evaluator`).
    #[arg(long)]
    evaluator: Option<PathBuf>,
    /// Leave out the evaluator's text match.
    #[arg(long)]
    no_text_match: bool,
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
    let (people, meta) = load_people(&args.motion)?;
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
    let spans = prompt_spans(&program, &people, &meta);
    if let Some(path) = &args.plot {
        plot_traces(&program, &traces, &spans, path)?;
        eprintln!("wrote {}", path.display());
    }
    if !args.no_text_match {
        print_text_match(&args, &people, &spans, &device)?;
    }
    Ok(())
}

/// The prompt spans to score: the program's timelines (a span ending at the program's
/// length runs to the motion's end), else the motion's `meta.timeline` (as `mprog run`
/// writes it), else its `meta.text` (as `mprog gen` writes it) over the whole motion.
fn prompt_spans(program: &Program, people: &[Motion], meta: &Meta) -> Vec<PromptSpan> {
    let len = |p: usize| people.get(p).map_or(0, Motion::len);
    let from_program: Vec<PromptSpan> = program
        .timelines()
        .into_iter()
        .enumerate()
        .flat_map(|(person, line)| {
            line.into_iter().map(move |t| PromptSpan {
                person,
                from: t.from,
                to: if t.to >= program.length() {
                    usize::MAX
                } else {
                    t.to
                },
                prompt: t.text,
            })
        })
        .collect();
    let spans = if !from_program.is_empty() {
        from_program
    } else if let Ok(lines) = mprog::view::timeline_from_meta(
        meta,
        people.len(),
        people.iter().map(Motion::len).max().unwrap_or(0),
    ) && !lines.is_empty()
    {
        lines
            .into_iter()
            .enumerate()
            .flat_map(|(person, line)| {
                line.into_iter().map(move |s| PromptSpan {
                    person,
                    from: s.from,
                    to: s.to,
                    prompt: s.prompt,
                })
            })
            .collect()
    } else if let Some(text) = meta.get("text").and_then(|t| t.as_str()) {
        vec![PromptSpan {
            person: 0,
            from: 0,
            to: usize::MAX,
            prompt: text.to_string(),
        }]
    } else {
        Vec::new()
    };
    spans
        .into_iter()
        .map(|s| PromptSpan {
            to: s.to.min(len(s.person)),
            ..s
        })
        .filter(|s| s.from + 2 <= s.to)
        .collect()
}

/// The evaluator's similarity of each span to its prompt, as a table.
fn print_text_match(
    args: &ScoreArgs,
    people: &[Motion],
    spans: &[PromptSpan],
    device: &burn::prelude::Device,
) -> Result<()> {
    if spans.is_empty() {
        eprintln!("no text match: neither the program nor the motion's meta names a prompt");
        return Ok(());
    }
    let dir = args
        .evaluator
        .clone()
        .unwrap_or_else(mprog::metrics::default_evaluator_dir);
    let evaluator = match mprog::metrics::Evaluator::load(&dir, device) {
        Ok(e) => e,
        Err(e) if args.evaluator.is_none() => {
            eprintln!("no text match: {e}");
            return Ok(());
        }
        Err(e) => return Err(e).into_diagnostic(),
    };
    let matches = text_match(&evaluator, people, spans, device).into_diagnostic()?;
    let window = evaluator.manifest.config.max_frames;
    let several = matches.iter().any(|m| m.closest.is_some());
    println!(
        "\ntext match (the evaluator's cosine similarity of motion and prompt, 1 = perfect; a span longer than {:.1} s is the mean over windows of {:.1} s at most {:.1} s apart)\n",
        window as f32 / 20.0,
        window as f32 / 20.0,
        (window / 2) as f32 / 20.0
    );
    let person_col = people.len() > 1;
    println!(
        "|{} span | prompt | similarity | windows |{}\n|{} --- | --- | --- | --- |{}",
        if person_col { " person |" } else { "" },
        if several { " closest prompt |" } else { "" },
        if person_col { " --- |" } else { "" },
        if several { " --- |" } else { "" },
    );
    for m in &matches {
        println!("{}", text_match_row(m, person_col, several));
    }
    for m in matches.iter().filter(|m| !m.unknown_words.is_empty()) {
        eprintln!(
            "the evaluator does not know {} of \"{}\" (left out)",
            m.unknown_words.join(", "),
            m.span.prompt
        );
    }
    Ok(())
}

fn text_match_row(m: &SpanMatch, person_col: bool, several: bool) -> String {
    let s = &m.span;
    let sim = m
        .similarity
        .map_or("– (no known word)".to_string(), |v| format!("{v:.3}"));
    let closest = match &m.closest {
        Some((p, v)) if *p == s.prompt => format!(" its own ({v:.3}) |"),
        Some((p, v)) => format!(" \"{p}\" ({v:.3}) |"),
        None if several => " |".to_string(),
        None => String::new(),
    };
    format!(
        "|{} {:.2}–{:.2} s | \"{}\" | {sim} | {} |{closest}",
        if person_col {
            format!(" {} |", s.person + 1)
        } else {
            String::new()
        },
        s.from as f32 / 20.0,
        s.to as f32 / 20.0,
        s.prompt,
        m.windows,
    )
}

/// The prompt spans of the first person with several, as plot bands (seconds).
fn plot_bands(spans: &[PromptSpan]) -> Vec<Band> {
    let count = |p: usize| spans.iter().filter(|s| s.person == p).count();
    let Some(person) = spans.iter().map(|s| s.person).find(|&p| count(p) > 1) else {
        return Vec::new();
    };
    spans
        .iter()
        .filter(|s| s.person == person)
        .map(|s| Band {
            from: s.from as f32 / 20.0,
            to: s.to as f32 / 20.0,
            label: s.prompt.clone(),
        })
        .collect()
}

fn plot_traces(
    program: &Program,
    traces: &[FrameErrors],
    spans: &[PromptSpan],
    path: &std::path::Path,
) -> Result<()> {
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
        &PlotOptions {
            bands: plot_bands(spans),
            ..PlotOptions::default()
        },
    )
    .into_diagnostic()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn spans_come_from_the_program_then_the_meta_and_reach_the_motion_end() {
        let walk = |n| Motion::new(vec![mprog::skeleton::rest_pose(); n]);
        let program = mprog::lang::compile(
            "length 10s\nprompt 0s..4s \"a person walks forward\"\nprompt 4s..end \"a person sits down\"\nalways { pelvis.y > 0.5 m }\n",
            "t.mprog",
            &[],
        )
        .unwrap();
        // A 30 s motion: the last span runs to its end.
        let spans = prompt_spans(&program, &[walk(600)], &Meta::new());
        let got: Vec<(usize, usize)> = spans.iter().map(|s| (s.from, s.to)).collect();
        assert_eq!(got, [(0, 80), (80, 600)]);
        let bands = plot_bands(&spans);
        assert_eq!(bands.len(), 2);
        assert_eq!((bands[1].from, bands[1].to), (4.0, 30.0));
        // No prompt in the program: the meta's timeline, else its text.
        let bare =
            mprog::lang::compile("length 10s\nalways { pelvis.y > 0.5 m }\n", "t.mprog", &[])
                .unwrap();
        let meta: Meta = serde_json::from_value(serde_json::json!({
            "timeline": [[{"from": 0, "to": 100, "prompt": "a"}, {"from": 100, "to": 200, "prompt": "b"}]],
            "text": "c"
        }))
        .unwrap();
        let spans = prompt_spans(&bare, &[walk(200)], &meta);
        assert_eq!(spans.len(), 2);
        assert_eq!(spans[1].prompt, "b");
        let text_only: Meta = serde_json::from_value(serde_json::json!({"text": "c"})).unwrap();
        let spans = prompt_spans(&bare, &[walk(200)], &text_only);
        assert_eq!((spans.len(), spans[0].to), (1, 200));
        assert!(plot_bands(&spans).is_empty());
        assert!(prompt_spans(&bare, &[walk(200)], &Meta::new()).is_empty());
    }
}
