//! `.npy` bytes → float array → joints or features (the `read_motion` path).
#![no_main]

use libfuzzer_sys::fuzz_target;
use mprog::formats::npy::{MotionFile, classify, read_npy_bytes};

fuzz_target!(|data: &[u8]| {
    let Ok(array) = read_npy_bytes("fuzz.npy", data) else {
        return;
    };
    let elements: usize = array.shape.iter().product();
    assert_eq!(elements, array.data.len());
    if let Ok(MotionFile::Joints(people)) = classify("fuzz.npy", array) {
        assert!(people.iter().all(|m| m.is_finite() && !m.is_empty()));
    }
});
