//! Deterministic train/val/test split by source file (80/5/15, as HumanML3D), so a clip
//! and its mirrored copy always land in the same split.

use super::store::Split;

/// FNV-1a: stable across platforms and Rust versions (unlike `DefaultHasher`).
fn fnv1a(text: &str) -> u64 {
    text.bytes().fold(0xcbf2_9ce4_8422_2325, |h, b| {
        (h ^ b as u64).wrapping_mul(0x0100_0000_01b3)
    })
}

/// Split of a source file, from its path relative to the BVH folder.
pub fn split_of(source: &str) -> Split {
    let name = source.rsplit(['/', '\\']).next().unwrap_or(source);
    match fnv1a(name) % 100 {
        0..80 => Split::Train,
        80..85 => Split::Val,
        _ => Split::Test,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn split_is_stable_and_roughly_80_5_15() {
        assert_eq!(
            split_of("a/dataset-2_walk_normal_001.bvh"),
            split_of("b/dataset-2_walk_normal_001.bvh")
        );
        let mut counts = [0usize; 3];
        for i in 0..3000 {
            let s = split_of(&format!("dataset-2_walk_normal_{i:03}.bvh"));
            counts[s as usize] += 1;
        }
        assert!((2250..2550).contains(&counts[0]), "{counts:?}");
        assert!((80..250).contains(&counts[1]), "{counts:?}");
        assert!((300..600).contains(&counts[2]), "{counts:?}");
    }
}
