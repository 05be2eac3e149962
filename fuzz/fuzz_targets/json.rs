//! `.json` motion documents → validated people → resampled to 20 fps (what
//! `read_motion` does with a `.json` file).
#![no_main]

use libfuzzer_sys::fuzz_target;
use mprog::formats::json::read_json_str;
use mprog::skeleton::FPS;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    if let Ok((people, _meta)) = read_json_str("fuzz.json", text) {
        for p in people {
            let m = p.motion.resample(FPS);
            assert!(m.is_finite() && !m.is_empty());
        }
    }
});
