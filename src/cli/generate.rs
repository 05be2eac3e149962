//! `mprog gen`: text-to-motion with the shipped model, no program.

use super::io::{check_outputs, numbered, write_outputs_with};
use indicatif::{ProgressBar, ProgressStyle};
use miette::{IntoDiagnostic, Result, WrapErr};
use mprog::formats::Meta;
use mprog::interrupt::Interrupt;
use mprog::metrics::per_motion::MotionMetrics;
use mprog::metrics::table::motions_markdown;
use mprog::model::ModelBundle;
use mprog::model::generate::{GenerateError, GenerateRequest, generate_interruptible};
use mprog::model::sampler::SamplerKind;
use mprog::model::weights::default_model_dir;
use mprog::solve::cleanup::{FootCleanup, clean_generated};
use std::path::PathBuf;
use std::time::Instant;

/// Arguments of `mprog gen`.
#[derive(clap::Args)]
pub struct GenArgs {
    /// What the person does.
    #[arg(long)]
    text: String,
    /// Length in seconds (20 fps). Default: as long as the training clips of the nearest
    /// known caption (sentence-encoder models), else 6 s.
    #[arg(long, conflicts_with = "frames")]
    seconds: Option<f32>,
    /// Length in frames (instead of --seconds).
    #[arg(long)]
    frames: Option<usize>,
    /// Seed of the noise: the same seed, text and weights give the same motion.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Number of motions, generated as one batch (outputs get `_0`, `_1`, … suffixes).
    #[arg(long, default_value_t = 1)]
    count: usize,
    /// Sampler: `ddim` (deterministic), `ddpm`, or `lcm` (a consistency-distilled
    /// model's few-step chain; such a model's default). Default: ddim.
    #[arg(long)]
    sampler: Option<String>,
    /// Denoising steps (DDIM default 50; DDPM 1000 is the full chain; lcm 4).
    #[arg(long)]
    steps: Option<usize>,
    /// Classifier-free guidance scale (default 2.5; 1 for a consistency-distilled model,
    /// whose teacher's guidance is in its weights).
    #[arg(long, value_parser = super::parse_guidance, allow_hyphen_values = true)]
    guidance: Option<f32>,
    /// Average every denoising step with its left/right mirror (swapped sides in the
    /// motion and the prompt): left and right turns become exact mirrors; twice the work.
    #[arg(long)]
    mirror_average: bool,
    /// Model bundle folder (default: models/default).
    #[arg(long)]
    model: Option<PathBuf>,
    /// Outputs; each one's extension picks its kind (`--help` lists them).
    #[arg(short, long, num_args = 1.., required = true, long_help = super::io::outputs_help())]
    out: Vec<PathBuf>,
    /// Keep the model's samples as they are: no foot cleanup (by default planted feet are
    /// held in place after sampling, the path unchanged).
    #[arg(long)]
    raw: bool,
    /// Give the model the prompt as written, even when it lies far from every training
    /// caption (by default such a prompt is replaced by the mean of its nearest captions).
    #[arg(long)]
    literal_prompt: bool,
    /// Motions longer than the model makes are made in windows: seconds each window keeps
    /// from the one before.
    #[arg(long, default_value_t = mprog::solve::long::DEFAULT_CONTEXT as f32 / 20.0)]
    seam_context: f32,
    /// RePaint resampling rounds of each window after the first (each round costs about
    /// one more chain).
    #[arg(long, default_value_t = mprog::solve::long::DEFAULT_WINDOW_RESAMPLE)]
    seam_resample: usize,
    /// Exit non-zero when a motion's plausibility report finds a problem (a snap, the
    /// floor, foot skating, a deformed body, walking backwards); every motion is written
    /// all the same, with its report in the meta.
    #[arg(long)]
    strict: bool,
    #[command(flatten)]
    export: super::export::ExportArgs,
}

/// Length when neither the user nor the model's length prior gives one (6 s).
const DEFAULT_FRAMES: usize = 120;

/// `--seconds` in frames at 20 fps; refused when not a positive finite number.
pub(super) fn seconds_to_frames(seconds: f32) -> Result<usize> {
    if seconds.is_finite() && seconds > 0.0 {
        Ok(((seconds * 20.0).round() as usize).max(1))
    } else {
        Err(miette::miette!(
            help = "give a length such as --seconds 4",
            "--seconds must be a positive number of seconds, got {seconds}: the motion would have no frames"
        ))
    }
}

/// `--seam-context` in frames: at least one frame.
pub(super) fn seam_context_frames(seconds: f32) -> Result<usize> {
    if seconds.is_finite() && seconds >= 0.05 {
        Ok((seconds * 20.0).round() as usize)
    } else {
        Err(miette::miette!(
            help = "give a context such as --seam-context 1",
            "--seam-context must be at least one frame (0.05 s), got {seconds}"
        ))
    }
}

/// The windows of a long motion as `[start, cut, end]` frames, for the meta.
pub(super) fn windows_meta(windows: &[mprog::solve::long::Window]) -> serde_json::Value {
    serde_json::json!(
        windows
            .iter()
            .map(|w| [w.start, w.cut, w.end])
            .collect::<Vec<_>>()
    )
}

/// Checks a `--sampler` name before anything is loaded.
pub fn check_sampler_name(name: Option<&str>) -> Result<()> {
    match name {
        None | Some("ddim" | "ddpm" | "lcm") => Ok(()),
        Some(other) => Err(miette::miette!(
            help = "use ddim, ddpm, or lcm (for a consistency-distilled model)",
            "unknown sampler `{other}`"
        )),
    }
}

/// The chain and guidance scale for `--sampler`/`--steps`/`--guidance` and a bundle: a
/// consistency-distilled bundle samples its few-step chain (4 steps) at scale 1 (its
/// teacher's guidance is in the weights); any other bundle DDIM-50 at 2.5.
pub fn sampling_for(
    bundle: &mprog::model::weights::Manifest,
    name: Option<&str>,
    steps: Option<usize>,
    guidance: Option<f32>,
) -> Result<(SamplerKind, f32)> {
    check_sampler_name(name)?;
    let (default_kind, default_scale) = mprog::model::sampler::default_chain(bundle);
    let kind = match (name, &bundle.consistency) {
        (None | Some("lcm"), Some(c)) => {
            default_kind.with_steps(steps.unwrap_or(default_kind.steps()).min(c.grid))
        }
        (Some("lcm"), None) => {
            return Err(miette::miette!(
                help =
                    "pass --model with a bundle written by a `[distil]` training run, or use ddim",
                "--sampler lcm needs a consistency-distilled model; {} is a diffusion model",
                bundle.weights_id
            ));
        }
        (Some("ddpm"), _) => SamplerKind::Ddpm(steps.unwrap_or(1000)),
        _ => SamplerKind::Ddim(steps.unwrap_or(50)),
    };
    Ok((kind, guidance.unwrap_or(default_scale)))
}

/// A `gen` longer than the model makes: the unguided chain window by window
/// ([`mprog::solve::long`]), each window continuing the last second of the one before.
fn generate_long(
    bundle: &ModelBundle,
    req: &mprog::solve::long::LongRequest,
    device: &burn::prelude::Device,
    bar: &ProgressBar,
    interrupt: &Interrupt,
) -> Result<mprog::model::generate::Generated> {
    use mprog::solve::long::{LongProgress, solve_long};
    let nothing =
        |j: burn::tensor::Tensor<5>| burn::tensor::Tensor::<1>::zeros([j.dims()[0]], &j.device());
    let out = solve_long(
        &mprog::solve::Prior::from_bundle(bundle),
        req,
        &nothing,
        device,
        |p: LongProgress| {
            if interrupt.is_requested() {
                bar.finish_and_clear();
                eprintln!(
                    "interrupted in window {} of {}: nothing was written",
                    p.window + 1,
                    p.windows
                );
                std::process::exit(130);
            }
            let (done, total) = p.overall();
            bar.set_length(total as u64);
            bar.set_position(done as u64);
        },
    )
    .into_diagnostic()?;
    Ok(mprog::model::generate::Generated {
        motions: out.motions.into_iter().flatten().collect(),
        features: out.features,
        unknown_words: out.unknown_words,
    })
}

/// `gen`'s timeline: one person, one prompt over the whole motion.
fn one_prompt(text: &str, frames: usize) -> Vec<Vec<mprog::solve::long::PromptSpan>> {
    vec![vec![mprog::solve::long::PromptSpan {
        from: 0,
        to: frames,
        prompt: text.to_string(),
    }]]
}

/// Runs `mprog gen`.
pub fn run(mut args: GenArgs) -> Result<()> {
    let started = Instant::now();
    check_sampler_name(args.sampler.as_deref())?;
    check_outputs(&args.out)?;
    args.export.prepare(&args.out)?;
    let device = super::device()?;
    let dir = args.model.clone().unwrap_or_else(default_model_dir);
    let mut bundle = ModelBundle::load(&dir, &device)
        .into_diagnostic()
        .wrap_err("cannot load the model (train one with `mprog train`, or pass --model)")?;
    if args.literal_prompt {
        bundle.text.read_literally();
    }
    let frames = match (args.frames, args.seconds) {
        (Some(f), _) => f,
        (None, Some(s)) => seconds_to_frames(s)?,
        (None, None) => match bundle
            .text
            .natural_frames(&args.text, bundle.config.max_frames)
        {
            Some((frames, nearest)) => {
                eprintln!(
                    "length {:.1} s: the median length of the training clips captioned nearest to the prompt (nearest: \"{}\", cosine {:.2}); --seconds sets it",
                    frames as f32 / 20.0,
                    nearest.caption,
                    nearest.cosine
                );
                frames
            }
            None => DEFAULT_FRAMES,
        },
    };
    let (sampler, guidance) = sampling_for(
        &bundle.manifest,
        args.sampler.as_deref(),
        args.steps,
        args.guidance,
    )?;
    let req = GenerateRequest {
        prompts: vec![args.text.clone(); args.count.max(1)],
        frames,
        seed: args.seed,
        sampler,
        guidance_scale: guidance,
        mirror_average: args.mirror_average,
    };
    let bar = ProgressBar::new(0);
    bar.set_style(
        ProgressStyle::with_template("{bar:30} {pos}/{len} denoising steps [{elapsed}]")
            .expect("template"),
    );
    // Ctrl-C stops between denoising steps; nothing is written then.
    let interrupt = Interrupt::on_signals()
        .into_diagnostic()
        .wrap_err("cannot install the Ctrl-C handler")?;
    let progress = |done, total| {
        bar.set_length(total as u64);
        bar.set_position(done as u64);
    };
    if frames > mprog::lang::check::MAX_LENGTH {
        return Err(miette::miette!(
            help = format!("ask for at most {} s", mprog::lang::check::MAX_LENGTH / 20),
            "{frames} frames asked ({:.0} s); the longest motion mprog makes is {} frames",
            frames as f32 / 20.0,
            mprog::lang::check::MAX_LENGTH
        ));
    }
    // Longer than the model makes, or an action asked for over much more than its clips'
    // length: in windows of that length (`solve::long::ACTION_STRETCH`).
    let line = one_prompt(&args.text, frames);
    let actions = mprog::solve::long::action_frames(&bundle.text, &line, bundle.config.max_frames);
    let stretched =
        !args.mirror_average && mprog::solve::long::stretches_an_action(&line, &actions);
    let long = frames > bundle.config.max_frames || stretched;
    let windows = if long {
        let w = mprog::solve::long::plan_windows(
            &line,
            frames,
            bundle.config.max_frames,
            seam_context_frames(args.seam_context)?,
            &actions,
        )
        .into_diagnostic()?;
        Some(w)
    } else {
        None
    };
    let mut out = if long {
        if args.mirror_average {
            return Err(miette::miette!(
                help = format!(
                    "drop --mirror-average, or ask for at most {:.1} s",
                    bundle.config.max_frames as f32 / 20.0
                ),
                "--mirror-average is not available for motions made in windows"
            ));
        }
        let req = mprog::solve::long::LongRequest {
            samples: args.count.max(1),
            guidance_scale: guidance,
            clean_feet: !args.raw,
            context: seam_context_frames(args.seam_context)?,
            resample: args.seam_resample,
            action_frames: actions,
            ..mprog::solve::long::LongRequest::new(
                vec![args.text.clone()],
                frames,
                args.seed,
                mprog::solve::Solver::plain(sampler),
            )
        };
        generate_long(&bundle, &req, &device, &bar, &interrupt)?
    } else {
        match generate_interruptible(&bundle, &req, &device, progress, &interrupt) {
            Err(e @ GenerateError::Interrupted { .. }) => {
                bar.finish_and_clear();
                eprintln!("{e}");
                std::process::exit(130);
            }
            other => other.into_diagnostic()?,
        }
    };
    bar.finish_and_clear();
    if let Some(windows) = &windows {
        let longest = windows.iter().map(|w| w.len()).max().unwrap_or(frames);
        eprintln!(
            "{:.1} s made in windows of at most {:.1} s{}, each keeping {:.1} s of the one before{}",
            frames as f32 / 20.0,
            longest as f32 / 20.0,
            if stretched {
                " (the prompt's training clips are shorter than the motion asked for)"
            } else {
                ""
            },
            mprog::solve::long::DEFAULT_CONTEXT as f32 / 20.0,
            if args.raw {
                ""
            } else {
                "; feet cleaned in every window (--raw skips it)"
            }
        );
    } else if !args.raw {
        let report =
            clean_generated(&mut out, frames, &FootCleanup::default()).into_diagnostic()?;
        eprintln!(
            "foot cleanup: {} planted toe-frame pairs, slide {:.1} → {:.1} mm/frame (--raw skips it)",
            report.planted,
            report.slide_before * 1000.0,
            report.slide_after * 1000.0
        );
    }
    for line in bundle.text.report(&args.text) {
        eprintln!("{line}");
    }
    let mut meta = Meta::new();
    meta.insert("text".into(), args.text.clone().into());
    meta.insert("seed".into(), args.seed.into());
    meta.insert("sampler".into(), format!("{sampler:?}").into());
    meta.insert("guidance_scale".into(), (guidance as f64).into());
    meta.insert("foot_cleanup".into(), (!args.raw).into());
    if let Some(windows) = &windows {
        meta.insert("windows".into(), windows_meta(windows));
        meta.insert("seam_resample".into(), args.seam_resample.into());
    }
    if let Some(snapped) = bundle.text.snapped(&args.text) {
        meta.insert("conditioned_on".into(), snapped.neighbours.into());
    }
    meta.insert(
        "weights_id".into(),
        bundle.manifest.weights_id.clone().into(),
    );
    let envelope = super::plausible::envelope(&dir)?;
    let reports: Vec<_> = out
        .motions
        .iter()
        .map(|m| {
            mprog::metrics::plausibility::check(
                std::slice::from_ref(m),
                &[Some(args.text.clone())],
                &envelope,
            )
        })
        .collect();
    let count = out.motions.len();
    for (i, motion) in out.motions.iter().enumerate() {
        if interrupt.is_requested() {
            eprintln!(
                "interrupted: {i} of {count} motion(s) written, each complete; the rest were not written"
            );
            std::process::exit(130);
        }
        let mut m = meta.clone();
        m.insert("sample".into(), i.into());
        m.insert("plausibility".into(), reports[i].to_json());
        write_outputs_with(
            &numbered(&args.out, i, count),
            std::slice::from_ref(motion),
            &m,
            &args.text,
            &args.export,
        )?;
    }
    let metrics: Vec<MotionMetrics> = out.motions.iter().map(MotionMetrics::of).collect();
    eprint!("{}", motions_markdown(&metrics));
    for (i, r) in reports.iter().enumerate() {
        for line in r.lines() {
            if count > 1 {
                eprintln!("motion {i}: {line}");
            } else {
                eprintln!("{line}");
            }
        }
    }
    eprintln!(
        "generated {count} motion(s) of {frames} frames in {:.1} s (weights {})",
        started.elapsed().as_secs_f64(),
        bundle.manifest.weights_id
    );
    let bad: usize = reports.iter().filter(|r| !r.ok).count();
    if args.strict && bad > 0 {
        return Err(miette::miette!(
            help =
                "the motions were written; the problems are listed above and in meta.plausibility",
            "implausible result (--strict): {bad} of {count} motion(s) have problems"
        ));
    }
    Ok(())
}
