//! `mprog data build` on a folder mixing every rig (the fixtures of `tests/fixtures/rigs/`,
//! plus a two-line CMU trial index): every file read, per-rig counts in `rigs.json`,
//! captions per source family, and the same clips in the same splits on a second build.

use mprog::dataset::build::{BuildOptions, build_dataset_report};
use mprog::dataset::{Dataset, Split};
use std::collections::BTreeMap;
use std::path::Path;

fn mixed_folder(dir: &Path) {
    let rigs = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/rigs");
    let copy = |from: &str, to: &str| {
        let to = dir.join(to);
        std::fs::create_dir_all(to.parent().unwrap()).unwrap();
        std::fs::copy(rigs.join(from), to).unwrap();
    };
    copy("cmu_cgspeed_31_01_01.bvh", "cmu/mb/01_01.bvh");
    copy("cmu_cgspeed_daz_12_01.bvh", "cmu/daz/12_01.bvh");
    copy("cmu_deepmimic13_02_01.bvh", "cmu/dm/02_01.bvh");
    // The same trial in a second rig (as the CMU archive has it).
    copy("cmu_deepmimic13_02_01.bvh", "cmu/dm/01_01.bvh");
    copy(
        "HDM_bd_squat1Reps_001_120.bvh",
        "hdm05/squat/HDM_bd_squat1Reps_001_120.bvh",
    );
    copy("humanoid3d_kick.bvh", "hdm05/dm/humanoid3d_kick.bvh");
    copy("asf/HDM_tt.asf", "amc/HDM_tt.asf");
    copy(
        "asf/HDM_tt_squat1Reps_001_120.amc",
        "amc/HDM_tt_squat1Reps_001_120.amc",
    );
    std::fs::write(
        dir.join("cmu/cmu_trial_index.csv"),
        "\"Subject\",\"Trial #\",\"Motion Description\",\"framerate\"\n\
         1,1,\"playground - forward jumps, turn around\",120\n\
         12,1,\"walk\",120\n2,1,\"walk\",120\n",
    )
    .unwrap();
    // Not a motion of any family: skipped with its reason.
    std::fs::copy(
        rigs.join("humanoid3d_kick.bvh"),
        dir.join("hdm05/dm/mystery.bvh"),
    )
    .unwrap();
}

#[test]
fn mixed_rigs_build_with_per_rig_counts_and_stable_splits() {
    let src = tempfile::tempdir().unwrap();
    mixed_folder(src.path());
    let out = tempfile::tempdir().unwrap();
    let opts = BuildOptions {
        mirror: true,
        min_frames: 1,
    };
    let set = out.path().join("set");
    let built = build_dataset_report(src.path(), &set, &opts, &|_| {}).unwrap();
    let rigs: BTreeMap<(String, String), (usize, usize)> = built
        .rigs
        .iter()
        .map(|r| ((r.family.clone(), r.rig.clone()), (r.read, r.skipped)))
        .collect();
    let want = |f: &str, r: &str| rigs.get(&(f.to_string(), r.to_string())).copied();
    assert_eq!(want("cmu", "cmu-cgspeed-31"), Some((1, 0)), "{rigs:?}");
    assert_eq!(want("cmu", "name-matched"), Some((1, 0)), "{rigs:?}");
    assert_eq!(want("cmu", "deepmimic"), Some((2, 0)), "{rigs:?}");
    assert_eq!(want("hdm05", "cmu-asf"), Some((2, 0)), "{rigs:?}");
    assert_eq!(want("deepmimic", "deepmimic"), Some((1, 0)), "{rigs:?}");
    assert_eq!(want("?", "?"), Some((0, 1)), "{rigs:?}");
    assert!(set.join("rigs.json").is_file());

    let data = Dataset::load(&set).unwrap();
    let caption = |name: &str| {
        data.index
            .clips
            .iter()
            .find(|c| c.name == name)
            .unwrap_or_else(|| panic!("no clip {name}"))
            .captions[0]
            .clone()
    };
    assert_eq!(
        caption("01_01@cmu-cgspeed-31"),
        "a person jumps forward several times and then turns around on a playground"
    );
    assert_eq!(
        caption("HDM_bd_squat1Reps_001_120"),
        "a person squats down and stands back up"
    );
    assert_eq!(caption("humanoid3d_kick"), "a person kicks forward");
    // The same trial in two rigs keeps two names.
    assert!(data.index.clips.iter().any(|c| c.name == "01_01@deepmimic"));
    assert!(
        data.index
            .clips
            .iter()
            .any(|c| c.name == "01_01@deepmimic_mirror")
    );
    assert!(data.index.clips.iter().any(|c| c.name == "02_01"));

    // A second build: same clips, same splits.
    let set2 = out.path().join("set2");
    build_dataset_report(src.path(), &set2, &opts, &|_| {}).unwrap();
    let again = Dataset::load(&set2).unwrap();
    let splits = |d: &Dataset| -> Vec<(String, Split)> {
        d.index
            .clips
            .iter()
            .map(|c| (c.name.clone(), c.split))
            .collect()
    };
    assert_eq!(splits(&data), splits(&again));
}
