//! Runs the solvers with a real model bundle on three hand-written error functions, prints
//! errors before/after and wall times, and writes PNG strips to look at.
//!
//! ```text
//! cargo run --example solve_demo -- <bundle dir> <out dir> <mode> [iterations] [ddim steps]
//! ```
//! Modes: `guide` (unguided DDPM-1000 vs guide at OmniControl's schedule, the time ratio),
//! `latent` (PMG latent optimisation; iterations and DDIM steps default to 100 and 100),
//! `memory` (two latent iterations at 120 frames, 100 DDIM steps: time per iteration and
//! peak RSS), `lbfgs`, `ik`.

use burn::prelude::*;
use glam::Vec3;
use mprog::model::ModelBundle;
use mprog::model::sampler::SamplerKind;
use mprog::render::{Overlay, RenderOptions, render_to_path};
use mprog::solve::*;
use std::path::{Path, PathBuf};

type ErrFn = fn(Tensor<5>) -> Tensor<1>;

/// Pelvis at (0, 0.9, 3) on the last frame (metres).
fn pelvis_at_3m(j: Tensor<5>) -> Tensor<1> {
    let [b, _, n, _, _] = j.dims();
    let target = Tensor::<1>::from_floats([0.0, 0.9, 3.0], &j.device()).reshape([1, 1, 1, 1, 3]);
    let d = j.narrow(3, 0, 1).narrow(2, n - 1, 1) - target;
    (d.square().sum_dim(4) + 1e-12).sqrt().reshape([b])
}

/// Left wrist above 1.6 m on every frame (mean hinge, metres).
fn wrist_up(j: Tensor<5>) -> Tensor<1> {
    let [b, _, n, _, _] = j.dims();
    let y = j.narrow(3, 20, 1).narrow(4, 1, 1);
    (y.neg() + 1.6)
        .clamp_min(0.0)
        .reshape([b, n])
        .mean_dim(1)
        .reshape([b])
}

/// Two people's right wrists within 5 cm at frame 60.
fn wrists_touch(j: Tensor<5>) -> Tensor<1> {
    let [b, _, _, _, _] = j.dims();
    let w = j.narrow(3, 21, 1).narrow(2, 60, 1);
    let d = w.clone().narrow(1, 0, 1) - w.narrow(1, 1, 1);
    ((d.square().sum_dim(4) + 1e-12).sqrt() - 0.05)
        .clamp_min(0.0)
        .reshape([b])
}

struct Task {
    name: &'static str,
    prompts: &'static [&'static str],
    error: ErrFn,
    overlays: Vec<Overlay>,
}

fn tasks() -> Vec<Task> {
    vec![
        Task {
            name: "pelvis_at_3m",
            prompts: &["a person walks forward"],
            error: pelvis_at_3m,
            overlays: vec![Overlay::Point {
                at: Vec3::new(0.0, 0.9, 3.0),
                label: Some("pelvis target".into()),
            }],
        },
        Task {
            name: "wrist_up",
            prompts: &["a person waves with the left hand"],
            error: wrist_up,
            overlays: vec![Overlay::HorizontalPlane { height: 1.6 }],
        },
        Task {
            name: "wrists_touch",
            prompts: &["a person walks forward", "a person walks forward"],
            error: wrists_touch,
            overlays: vec![],
        },
    ]
}

fn peak_rss_mib() -> f64 {
    let status = std::fs::read_to_string("/proc/self/status").unwrap_or_default();
    status
        .lines()
        .find(|l| l.starts_with("VmHWM:"))
        .and_then(|l| l.split_whitespace().nth(1))
        .and_then(|kb| kb.parse::<f64>().ok())
        .map_or(f64::NAN, |kb| kb / 1024.0)
}

fn render(out: &Path, task: &Task, label: &str, r: &SolveResult) {
    let mut opts = RenderOptions::titled(format!(
        "{} — {label}: error {:.3}",
        task.prompts.join(" / "),
        r.error[0]
    ));
    opts.overlays = task.overlays.clone();
    let path = out.join(format!("{}_{label}.png", task.name));
    render_to_path(&r.motions[0], &opts, &path).expect("render");
    println!("  wrote {}", path.display());
}

fn go(bundle: &ModelBundle, task: &Task, solver: Solver, frames: usize) -> SolveResult {
    let req = SolveRequest::new(
        task.prompts.iter().map(|s| s.to_string()).collect(),
        frames,
        3,
        solver,
    );
    let mut last = 0;
    let out = solve(
        &Prior::from_bundle(bundle),
        &req,
        &task.error,
        &Device::flex(),
        |p| {
            if p.done * 10 / p.total != last {
                last = p.done * 10 / p.total;
                eprint!(" {}%", last * 10);
            }
        },
    )
    .expect("solve");
    eprintln!();
    out
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let bundle_dir = PathBuf::from(args.get(1).map_or("/work/main/runs/main/bundle", |s| s));
    let out = PathBuf::from(args.get(2).map_or("out/solve", |s| s));
    let mode = args.get(3).map_or("guide", |s| s.as_str());
    let iterations: usize = args.get(4).map_or(100, |s| s.parse().expect("iterations"));
    let ddim: usize = args.get(5).map_or(100, |s| s.parse().expect("ddim steps"));
    std::fs::create_dir_all(&out).expect("out dir");
    let bundle = ModelBundle::load(&bundle_dir, &Device::flex()).expect("bundle");
    println!(
        "bundle {} ({} steps)",
        bundle.manifest.weights_id, bundle.manifest.steps
    );
    let frames = 120;
    match mode {
        "guide" => {
            for task in tasks() {
                println!("{}:", task.name);
                let plain = go(
                    &bundle,
                    &task,
                    Solver::plain(SamplerKind::Ddpm(1000)),
                    frames,
                );
                let guided = go(&bundle, &task, Solver::new(GuideConfig::default()), frames);
                println!(
                    "  unguided DDPM-1000: error {:.4} in {:.1} s; guide: error {:.4} in {:.1} s; time ratio {:.3}",
                    plain.error[0],
                    plain.seconds,
                    guided.error[0],
                    guided.seconds,
                    guided.seconds / plain.seconds
                );
                render(&out, &task, "unguided", &plain);
                render(&out, &task, "guide", &guided);
            }
        }
        "latent" | "memory" | "lbfgs" | "ik" => {
            let (iterations, ddim) = if mode == "memory" {
                (2, 100)
            } else {
                (iterations, ddim)
            };
            for task in tasks() {
                if mode == "memory" && task.prompts.len() > 1 {
                    continue;
                }
                println!("{}:", task.name);
                let solver = match mode {
                    "lbfgs" => Solver::new(LbfgsConfig::default()),
                    "ik" => Solver::new(IkConfig::ik_reg()),
                    _ => Solver::new(LatentConfig {
                        iterations,
                        ddim_steps: ddim,
                        ..LatentConfig::default()
                    }),
                };
                let name = solver.name();
                let r = go(&bundle, &task, solver, frames);
                let per_it = r.seconds / r.trace.len().max(1) as f64;
                println!(
                    "  {name}: error {:.4} -> {:.4} in {:.1} s ({:.2} s per iteration/step unit), peak RSS {:.0} MiB",
                    r.trace.first().map_or(f32::NAN, |t| t[0]),
                    r.error[0],
                    r.seconds,
                    per_it,
                    peak_rss_mib()
                );
                if mode == "memory" {
                    return;
                }
                render(&out, &task, name, &r);
            }
        }
        other => panic!("unknown mode {other}"),
    }
}
