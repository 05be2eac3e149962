//! `.mprog` source → parse + check (all diagnostics rendered) → compile → evaluate on a
//! tiny motion when it compiles and its estimated cost is small.
#![no_main]

use burn::tensor::{Device, Tensor, TensorData};
use libfuzzer_sys::fuzz_target;
use mprog::lang::{check_source, compile};
use mprog::skeleton::{NUM_JOINTS, rest_pose};

/// Frames of the motion the compiled programs are evaluated on.
const FRAMES: usize = 6;
/// Element budget of one fuzz evaluation (keeps executions fast; the library's own
/// refusal of costly evaluations is exercised by the tests).
const MAX_FUZZ_ELEMENTS: usize = 200_000;

fuzz_target!(|data: &[u8]| {
    let Ok(source) = std::str::from_utf8(data) else {
        return;
    };
    let diags = check_source(source, "fuzz.mprog", &[("x".into(), 2.0)]);
    let _ = diags.render_plain();
    let Ok(program) = compile(source, "fuzz.mprog", &[]) else {
        return;
    };
    let people = program.people().len();
    let frames = program.length().clamp(1, FRAMES);
    if program.ir().cost_estimate_at(frames).elements_per_sample > MAX_FUZZ_ELEMENTS {
        return;
    }
    let rest = rest_pose();
    let data: Vec<f32> = (0..people * frames)
        .flat_map(|i| {
            (0..NUM_JOINTS).flat_map(move |j| {
                let w = 0.01 * (i as f32 + j as f32).sin();
                [rest[j].x + w, rest[j].y, rest[j].z + 0.05 * i as f32]
            })
        })
        .collect();
    let device = Device::flex();
    let x = Tensor::<5>::from_data(
        TensorData::new(data, [1, people, frames, NUM_JOINTS, 3]),
        &device,
    );
    let e = program
        .try_evaluate(x)
        .expect("a compiled program evaluates on a motion of its people");
    let total = e
        .total
        .into_data()
        .try_into_vec::<f32>()
        .expect("f32 total");
    assert_eq!(total.len(), 1);
});
