//! Timing of every program: evaluation, and evaluation + gradient, at batch 1 and 32 with
//! 196 frames on `Device::flex()`. Ignored by default; run with
//! `cargo test --release --test lang_bench -- --ignored --nocapture`.

mod lang_common;

use burn::tensor::{Device, Tensor, TensorData};
use lang_common::*;
use std::time::Instant;

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

fn time(runs: usize, mut f: impl FnMut()) -> f64 {
    f();
    median(
        (0..runs)
            .map(|_| {
                let t = Instant::now();
                f();
                t.elapsed().as_secs_f64() * 1e6
            })
            .collect(),
    )
}

/// Programs that compute exactly what a function of the PyTorch yardstick
/// (`../shared/bench/pmg_torch_ref.py`) computes, where the task's own program does more.
/// `hold_ball` is 2 of HOI-2's 4 terms: the wrists 0.4 m apart and their midpoint at least
/// 0.3 m from the chest, without HOI-2's facing frame and sides.
const YARDSTICK_TWINS: [(&str, &str); 1] = [(
    "twin_hold_ball",
    "length 196 frames\nalways {\n    dist(l_hand, r_hand) == 0.4 m\n    \
     dist(midPoint(l_hand, r_hand), chest) > 0.3 m\n}\n",
)];

#[test]
#[ignore]
fn bench_programs() {
    // Time what the binary runs: `mprog` tunes glibc's allocator first thing and runs
    // on a thread of the compute pool.
    mprog::backend::tune_allocator();
    mprog::backend::on_compute_pool(bench_programs_on_pool);
}

fn bench_programs_on_pool() {
    let dir = std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("programs");
    let mut files: Vec<_> = std::fs::read_dir(dir)
        .unwrap()
        .filter_map(|e| e.ok().map(|e| e.path()))
        .collect();
    files.sort();
    let mut sources: Vec<(String, String)> = files
        .iter()
        .map(|path| {
            let name = path.file_stem().unwrap().to_string_lossy().to_string();
            (name, std::fs::read_to_string(path).unwrap())
        })
        .collect();
    sources.extend(
        YARDSTICK_TWINS
            .iter()
            .map(|(name, src)| (name.to_string(), src.to_string())),
    );
    println!(
        "| program | stmts | ops | eval B=1 µs | eval+grad B=1 µs | eval B=32 µs | eval+grad B=32 µs |"
    );
    println!("|---|---|---|---|---|---|---|");
    // `MPROG_BENCH_ONLY=hsc1` times only the programs whose name contains it, and
    // `MPROG_BENCH_REPEAT=k` runs each timing k times as often (for a profiler).
    let only = std::env::var("MPROG_BENCH_ONLY").unwrap_or_default();
    for (name, source) in sources {
        if !name.contains(&only) {
            continue;
        }
        let prog = program(&source);
        let m = motion(prog.people().len(), 196);
        let (one, [_, people, frames, j, c]) = flat(&m);
        let mut row = Vec::new();
        for batch in [1usize, 32] {
            let data: Vec<f32> = (0..batch).flat_map(|_| one.iter().copied()).collect();
            let shape = [batch, people, frames, j, c];
            let repeat: usize = std::env::var("MPROG_BENCH_REPEAT")
                .ok()
                .and_then(|v| v.parse().ok())
                .unwrap_or(1);
            let runs = repeat * if batch == 1 { 50 } else { 10 };
            let plain = Device::flex();
            let x = Tensor::<5>::from_data(TensorData::new(data.clone(), shape), &plain);
            let eval_us = time(runs, || {
                let e = prog.evaluate(x.clone());
                let _ = e.total.into_data();
            });
            let ad = Device::flex().autodiff();
            // Timed like the PyTorch yardstick (`pmg_torch_ref.py`): the input exists
            // before the clock starts, and the clock stops when the gradient is there
            // (flex computes it in `backward`), not after copying it out.
            let base = Tensor::<5>::from_data(TensorData::new(data.clone(), shape), &ad);
            let grad_us = time(runs, || {
                let x = base.clone().require_grad();
                let e = prog.evaluate(x.clone());
                let g = e.total.sum().backward();
                assert!(x.grad(&g).is_some(), "no gradient reached the motion");
            });
            row.push((eval_us, grad_us));
        }
        println!(
            "| {name} | {} | {} | {:.0} | {:.0} | {:.0} | {:.0} |",
            prog.statements().len(),
            prog.cost_estimate().ops,
            row[0].0,
            row[0].1,
            row[1].0,
            row[1].1
        );
    }
}
