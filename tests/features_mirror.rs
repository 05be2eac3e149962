//! The feature-space mirror agrees with mirroring the joints and extracting again.

mod common;

use mprog::dataset::build::mirror_motion;
use mprog::features::layout::BLOCKS;
use mprog::features::{ExtractOptions, FEATURE_DIM, FeatureMirror, extract};

#[test]
fn feature_mirror_matches_mirrored_joints() {
    // A turning walk with a torso twist: nothing about it is left/right symmetric.
    let walk = common::synthetic_walk(90);
    let opts = ExtractOptions::default();
    let own = extract(&walk, &opts).unwrap().into_vec();
    let of_mirrored = extract(&mirror_motion(&walk), &opts).unwrap().into_vec();
    let via_features = FeatureMirror::humanml3d().apply(&own);
    assert_eq!(of_mirrored.len(), via_features.len());
    for (b, block) in BLOCKS.iter().enumerate() {
        let worst = of_mirrored
            .chunks_exact(FEATURE_DIM)
            .zip(via_features.chunks_exact(FEATURE_DIM))
            .flat_map(|(a, m)| block.clone().map(move |i| (a[i] - m[i]).abs()))
            .fold(0.0f32, f32::max);
        assert!(worst < 1e-4, "block {b} ({block:?}) differs by {worst}");
    }
    // The walk turns, so the check is not vacuous: its yaw velocity is not zero.
    assert!(own.chunks_exact(FEATURE_DIM).any(|r| r[0].abs() > 1e-3));
}
