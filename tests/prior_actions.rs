//! Issue 28's "done when" on the shipped model (or `$MPROG_MODEL`): jumps, kicks, crouches,
//! pick-ups, lying down, runs, and that walks, paraphrases and hand raises still work. The
//! same table is `mprog bench actions`.
//!
//! ```text
//! cargo test --release --test prior_actions -- --ignored --nocapture
//! ```

use burn::prelude::*;
use mprog::metrics::actions::{actions_table, measure_actions};
use mprog::model::ModelBundle;
use mprog::model::sampler::SamplerKind;
use mprog::model::weights::default_model_dir;

#[test]
#[ignore = "slow: 20 generations with the shipped model"]
fn the_prior_performs_the_wider_actions() {
    let dir = default_model_dir();
    let device = Device::flex();
    let bundle = match ModelBundle::load(&dir, &device) {
        Ok(b) => b,
        Err(e) => {
            eprintln!("skipping: no model bundle at {} ({e})", dir.display());
            return;
        }
    };
    let rows = measure_actions(&bundle, &device, None, SamplerKind::Ddim(50), 2.5).unwrap();
    let table = actions_table(&rows);
    println!("model {}\n\n{table}", bundle.manifest.weights_id);
    let failed: Vec<&str> = rows
        .iter()
        .filter(|r| !r.passed())
        .map(|r| r.case.prompt)
        .collect();
    assert!(failed.is_empty(), "not met: {failed:?}\n{table}");
}
