//! BVH bytes → import (UTF-8 check, parse, forward kinematics, retarget, units, resample).
#![no_main]

use libfuzzer_sys::fuzz_target;
use mprog::formats::BvhImportOptions;
use mprog::formats::bvh::{ParseLimits, import_bvh_bytes};

fuzz_target!(|data: &[u8]| {
    // Smaller limits than the default keep each execution fast; the checks are the same.
    let opts = BvhImportOptions {
        limits: ParseLimits {
            max_values: 200_000,
        },
        ..BvhImportOptions::default()
    };
    if let Ok(out) = import_bvh_bytes("fuzz.bvh", data, &opts) {
        assert!(
            out.motion.is_finite(),
            "imported motion has non-finite values"
        );
        assert!(!out.motion.is_empty());
    }
});
