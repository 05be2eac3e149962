//! ASF/AMC text → skeleton, motion and import. The input is an ASF, then an AMC after a
//! line `---`; without one, the bytes are an AMC for the test skeleton of
//! `tests/fixtures/rigs/asf/HDM_tt.asf`.
#![no_main]

use libfuzzer_sys::fuzz_target;
use mprog::formats::BvhImportOptions;
use mprog::formats::asf::{asf_amc_to_bvh, parse_asf};
use mprog::formats::bvh::{ParseLimits, import_parsed};

const SKELETON: &str = include_str!("../../tests/fixtures/rigs/asf/HDM_tt.asf");

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    let (asf_text, amc_text) = text.split_once("\n---\n").unwrap_or((SKELETON, text));
    let Ok(asf) = parse_asf("fuzz.asf", asf_text) else {
        return;
    };
    let opts = BvhImportOptions {
        limits: ParseLimits {
            max_values: 200_000,
        },
        ..BvhImportOptions::default()
    };
    let Ok(bvh) = asf_amc_to_bvh("fuzz.amc", &asf, amc_text, 120.0, &opts) else {
        return;
    };
    if let Ok(out) = import_parsed("fuzz.amc", bvh, &opts) {
        assert!(out.motion.is_finite(), "imported motion has non-finite values");
        assert!(!out.motion.is_empty());
    }
});
