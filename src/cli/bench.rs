//! `mprog bench`: timing tables (medians over repeated runs) printed as markdown.

use burn::prelude::*;
use miette::{IntoDiagnostic, Result, WrapErr};
use mprog::model::denoiser::{Denoiser, DenoiserInput, Mdm};
use mprog::model::noise::NoiseSource;
use mprog::model::prompt::PromptEncoder;
use mprog::model::sampler::{Condition, SamplerKind, sample_chain, schedule_for};
use mprog::model::schedule::{DIFFUSION_STEPS, NoiseSchedule};
use mprog::model::text::Vocabulary;
use mprog::model::{ModelBundle, ModelConfig};
use std::path::PathBuf;
use std::time::Instant;

/// `mprog bench …`
#[derive(clap::Subcommand)]
pub enum BenchCommand {
    /// Denoiser forward / forward+backward and DDIM sampling times.
    Model(ModelBenchArgs),
    /// The task suite: every solver on PMG's tasks, keyframe control of test clips and
    /// two-person contacts; writes a markdown table.
    Tasks(super::bench_tasks::TaskBenchArgs),
    /// What steering costs: each solver at the papers' defaults on one program next to its
    /// unguided sampler (time ratios, latent seconds per motion).
    Solvers(super::bench_solvers::SolverBenchArgs),
    /// What the prior does with named actions: jump, kick, crouch, pick up, lie down, run,
    /// walk, turns, paraphrases, hand raises (seeds 1 and 2, one number each, ✗ below threshold).
    Actions(ActionBenchArgs),
    /// The held-out paraphrase set: each caption and its other wordings generated with
    /// each seed and judged; exact against paraphrase success, with `gen`'s
    /// nearest-caption conditioning and literal (`bench/paraphrases.toml`).
    Paraphrases(super::bench_paraphrases::ParaphraseBenchArgs),
    /// Sentence-level tasks judged like a reviewer (`bench/sentences/`): each program run as
    /// `mprog run` runs it; per task met, plausible, inside the measured envelope, and right
    /// by a judge written from the sentence.
    Sentences(super::bench_sentences::SentenceBenchArgs),
}

/// Arguments of `mprog bench actions`.
#[derive(clap::Args)]
pub struct ActionBenchArgs {
    /// Model bundle (default: the shipped model).
    #[arg(long)]
    model: Option<PathBuf>,
    /// Generate every prompt this long (default: each as long as `mprog gen` makes it:
    /// the model's length prior, the walk 6 s).
    #[arg(long)]
    seconds: Option<f32>,
    /// Classifier-free guidance scale (`mprog gen`'s default: 2.5, 1 for a few-step model).
    #[arg(long, value_parser = super::parse_guidance, allow_hyphen_values = true)]
    guidance: Option<f32>,
}

fn bench_actions(args: ActionBenchArgs) -> Result<()> {
    let device = super::device()?;
    let dir = args
        .model
        .unwrap_or_else(mprog::model::weights::default_model_dir);
    let bundle = ModelBundle::load(&dir, &device)
        .into_diagnostic()
        .wrap_err_with(|| format!("cannot load the model {}", dir.display()))?;
    if let Some(s) = args.seconds {
        super::generate::seconds_to_frames(s)?;
    }
    // `gen`'s chain for this bundle: DDIM 50, or a few-step model's own.
    let (sampler, guidance) =
        super::generate::sampling_for(&bundle.manifest, None, None, args.guidance)?;
    let rows =
        mprog::metrics::actions::measure_actions(&bundle, &device, args.seconds, sampler, guidance)
            .into_diagnostic()?;
    let length = match args.seconds {
        Some(s) => format!("{s} s"),
        None => "each prompt as long as `gen` makes it".to_string(),
    };
    println!(
        "model {} ({}): {length}, {}, guidance {guidance}, no cleanup; heights above the motion's lowest foot joint\n",
        bundle.manifest.weights_id,
        dir.display(),
        mprog::metrics::table::sampler_name(sampler),
    );
    print!("{}", mprog::metrics::actions::actions_table(&rows));
    Ok(())
}

/// Arguments of `mprog bench model`.
#[derive(clap::Args)]
pub struct ModelBenchArgs {
    /// Model bundle (its config sets the shape; default: the shipped model, else the
    /// default config with random weights).
    #[arg(long)]
    model: Option<PathBuf>,
    /// Repetitions per cell (the median is reported).
    #[arg(long, default_value_t = 3)]
    reps: usize,
    /// Frames per motion.
    #[arg(long, default_value_t = 120)]
    frames: usize,
}

/// Runs `mprog bench …`.
pub fn run(cmd: BenchCommand) -> Result<()> {
    match cmd {
        BenchCommand::Model(args) => bench_model(args),
        BenchCommand::Tasks(args) => super::bench_tasks::run(args),
        BenchCommand::Solvers(args) => super::bench_solvers::run(args),
        BenchCommand::Actions(args) => bench_actions(args),
        BenchCommand::Paraphrases(args) => super::bench_paraphrases::run(args),
        BenchCommand::Sentences(args) => super::bench_sentences::run(args),
    }
}

/// Waits for the device's queued work (a no-op on the CPU).
fn sync(device: &Device) {
    if let Err(e) = device.sync() {
        eprintln!("(device sync failed: {e:?})");
    }
}

fn median_ms(reps: usize, mut f: impl FnMut()) -> f64 {
    f(); // warm-up
    let mut times: Vec<f64> = (0..reps)
        .map(|_| {
            let t = Instant::now();
            f();
            t.elapsed().as_secs_f64() * 1e3
        })
        .collect();
    times.sort_by(f64::total_cmp);
    times[times.len() / 2]
}

fn bench_model(args: ModelBenchArgs) -> Result<()> {
    let plain = super::device()?;
    let dir = args
        .model
        .clone()
        .unwrap_or_else(mprog::model::weights::default_model_dir);
    let (config, text, model) = match ModelBundle::load(&dir, &plain) {
        Ok(b) => (b.config, b.text, b.model),
        Err(e) => {
            eprintln!("({e}; timing the default config with random weights)");
            let config = ModelConfig::default();
            let vocab = Vocabulary::from_captions(["a person walks forward"], 16);
            let model = Mdm::new(&config, vocab.len(), &plain);
            (config, PromptEncoder::Words(vocab), model)
        }
    };
    let vocab_size = text.vocab_size();
    let n = args.frames;
    println!(
        "denoiser d_model {} × {} layers, {} params, {n} frames, {} backend on {}, median of {} runs\n",
        config.d_model,
        config.layers,
        model.num_params(),
        mprog::backend::backend_name(),
        mprog::backend::machine_description(),
        args.reps
    );
    println!("| measurement | batch 1 | batch 32 |\n| --- | --- | --- |");
    let input = |b: usize, dev: &Device| DenoiserInput {
        x_t: NoiseSource::new(1).tensor([b, n, config.features], dev),
        timesteps: vec![500; b],
        text: text.batch(&vec!["a person walks forward"; b], dev),
        keep_text: Tensor::ones([b], dev),
        padding: None,
    };
    let inference = model.valid();
    let fwd: Vec<f64> = [1, 32]
        .iter()
        .map(|&b| {
            let inp = input(b, &plain);
            median_ms(args.reps, || {
                let _ = inference.predict_x0(&inp).into_data();
            })
        })
        .collect();
    println!(
        "| forward (inference) | {:.1} ms | {:.1} ms |",
        fwd[0], fwd[1]
    );
    let ad = plain.clone().autodiff();
    // A fresh training module: loaded weights do not track gradients, and timing does
    // not depend on the values.
    let train = Mdm::new(&config, vocab_size, &ad);
    let fb: Vec<f64> = [1, 32]
        .iter()
        .map(|&b| {
            let inp = input(b, &ad);
            median_ms(args.reps, || {
                let loss = train.predict_x0(&inp).powi_scalar(2).mean();
                // Read the loss and wait for the backward: a GPU backend runs both
                // asynchronously, and an unread result is never waited for.
                let _ = loss.clone().into_scalar::<f32>();
                let _grads = loss.backward();
                sync(&ad);
            })
        })
        .collect();
    println!(
        "| forward + backward (training) | {:.1} ms | {:.1} ms |",
        fb[0], fb[1]
    );
    let base = NoiseSchedule::cosine(DIFFUSION_STEPS);
    let cond = Condition::new(&text, &["a person walks forward"], 2.5, &plain);
    for steps in [50, 100] {
        let kind = SamplerKind::Ddim(steps);
        let s = schedule_for(&base, kind);
        let ms = median_ms(1.max(args.reps / 2), || {
            let x = NoiseSource::new(1).tensor([1, n, config.features], &plain);
            let _ = sample_chain(
                &inference,
                &s,
                kind,
                x,
                &cond,
                &mut NoiseSource::new(2),
                |_, _| {},
            )
            .into_data();
        });
        println!(
            "| DDIM {steps} steps, CFG 2.5 (1 motion) | {:.2} s | |",
            ms / 1e3
        );
    }
    Ok(())
}
