//! The head-height tasks (PMG HSI-1 on test clips) are met by the clips they come from.
//! Needs the built dataset (`mprog data build --out data/humanml`); skips without it.

use burn::prelude::*;
use mprog::dataset::{Dataset, FEATURE_DIM};
use mprog::features::recover_from_ric;
use mprog::tasks::head_height;
use mprog::tasks::suite::Goal;
use std::path::Path;

#[test]
fn each_clip_meets_its_own_head_heights() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("data/humanml");
    let Ok(data) = Dataset::load(&dir) else {
        eprintln!("skipped: no built dataset at {}", dir.display());
        return;
    };
    let clips = head_height::clips(&data, 6);
    let tasks = head_height::suite(&data, 6, 1).expect("tasks build");
    assert_eq!(tasks.len(), 6);
    let device = Default::default();
    for (clip, task) in clips.iter().zip(&tasks) {
        assert_eq!(task.frames, clip.frames);
        let motion = recover_from_ric(&data.clip_features(clip)[..clip.frames * FEATURE_DIM])
            .expect("recovers");
        let joints = Tensor::<5>::from_data(
            TensorData::new(motion.to_flat(), [1, 1, clip.frames, 22, 3]),
            &device,
        );
        let Goal::Program(program) = &task.goal else {
            panic!("a program goal")
        };
        let own: f32 = program.evaluate(joints.clone()).total.into_scalar();
        assert!(own < 1e-3, "{}: its own motion is {own} m off", clip.name);
        // Lowered by 20 cm, every keyframe misses by 20 cm.
        let lowered = joints.clone()
            - Tensor::<1>::from_floats([0.0, 0.2, 0.0], &device).reshape([1, 1, 1, 1, 3]);
        let off: f32 = program.evaluate(lowered).total.into_scalar();
        assert!((off - 0.6).abs() < 2e-3, "{}: {off}", clip.name);
    }
}
