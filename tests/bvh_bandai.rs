//! Imports real Bandai-Namco BVH files and checks the result is a plausible human in
//! mprog's conventions: 22 joints at 20 fps, metres, standing height, left on the left,
//! rigid bones, feet on the floor.
//!
//! Needs the unpacked dataset: `$MPROG_BVH_DIR`, else `<crate root>/data/raw`; skips
//! with a message when neither exists. `import_all_files` (ignored by default: run with
//! `--ignored`) imports every file with rayon and prints the time taken.

use glam::Vec3;
use mprog::formats::bvh::{BvhImportOptions, import_bvh};
use mprog::motion::{Motion, Pose};
use mprog::skeleton::{NUM_JOINTS, PARENTS};
use rayon::prelude::*;
use std::path::{Path, PathBuf};
use std::time::Instant;

fn data_dir() -> Option<PathBuf> {
    let dir = std::env::var_os("MPROG_BVH_DIR")
        .map(PathBuf::from)
        .unwrap_or_else(|| Path::new(env!("CARGO_MANIFEST_DIR")).join("data/raw"));
    if dir.is_dir() {
        Some(dir)
    } else {
        eprintln!(
            "SKIPPED: no BVH data at {} (set MPROG_BVH_DIR to the unpacked Bandai-Namco dataset)",
            dir.display()
        );
        None
    }
}

fn bvh_files(dir: &Path) -> Vec<PathBuf> {
    let mut out = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for entry in std::fs::read_dir(&d).unwrap().flatten() {
            let p = entry.path();
            if p.is_dir() {
                stack.push(p);
            } else if p.extension().is_some_and(|e| e.eq_ignore_ascii_case("bvh")) {
                out.push(p);
            }
        }
    }
    out.sort();
    out
}

/// `dataset-2_walk-turn-left_happy_003.bvh` → `dataset-2_walk-turn-left`.
fn label(path: &Path) -> String {
    let stem = path.file_stem().unwrap().to_string_lossy();
    let parts: Vec<&str> = stem.split('_').collect();
    parts[..2.min(parts.len())].join("_")
}

/// One file per content label, alternating styles: 26 files across both datasets.
fn sample(files: &[PathBuf]) -> Vec<PathBuf> {
    let mut seen = std::collections::BTreeMap::new();
    for f in files {
        seen.entry(label(f))
            .or_insert_with(Vec::new)
            .push(f.clone());
    }
    seen.values()
        .enumerate()
        .map(|(i, group)| group[(i * 7) % group.len()].clone())
        .collect()
}

fn horizontal(v: Vec3) -> Vec3 {
    Vec3::new(v.x, 0.0, v.z).normalize_or_zero()
}

/// A forward direction that does not depend on the left/right labels: for forward
/// locomotion (`walk`, `run`, `dash`) the pelvis velocity when faster than 0.5 m/s;
/// otherwise the feet (ankle → toe) when both are level, not pointing down or up.
fn reference_forward(label: &str, m: &Motion, i: usize) -> Option<Vec3> {
    let content = label.split('_').nth(1).unwrap_or("");
    if ["walk", "run", "dash"].contains(&content) {
        let (a, b) = (i.saturating_sub(3), (i + 3).min(m.len() - 1));
        let velocity = (m.frames[b][0] - m.frames[a][0]) * m.fps / (b - a).max(1) as f32;
        let v = Vec3::new(velocity.x, 0.0, velocity.z);
        return (v.length() > 0.5).then(|| v.normalize());
    }
    let p = &m.frames[i];
    let level = |a: Vec3, b: Vec3| horizontal(b - a).dot(b - a) > 0.5 * (b - a).length();
    (level(p[7], p[10]) && level(p[8], p[11])).then(|| horizontal((p[10] - p[7]) + (p[11] - p[8])))
}

/// Facing from hips and shoulders, HumanML3D's rule: up × ((r_hip − l_hip) + (r_sh − l_sh)).
fn forward_from_hips(p: &Pose) -> Vec3 {
    horizontal(Vec3::Y.cross((p[2] - p[1]) + (p[17] - p[16])))
}

fn check_file(path: &Path) -> Result<String, String> {
    let out = import_bvh(path, &BvhImportOptions::default()).map_err(|e| e.to_string())?;
    let m = &out.motion;
    let name = path.file_name().unwrap().to_string_lossy().to_string();
    let fail = |what: String| Err(format!("{name}: {what}"));
    if out.joint_map.rig != "bandai-namco" || out.unit_scale != 0.01 || out.source_fps != 30.0 {
        return fail(format!(
            "rig {} scale {} fps {}",
            out.joint_map.rig, out.unit_scale, out.source_fps
        ));
    }
    let expected_frames = (out.source_frames - 1) * 2 / 3 + 1;
    if m.fps != 20.0 || m.len() != expected_frames || !m.is_finite() {
        return fail(format!(
            "{} frames at {} fps, expected {expected_frames} at 20",
            m.len(),
            m.fps
        ));
    }
    // Standing height: the frame where the head is highest above the lowest foot joint.
    let height = m
        .frames
        .iter()
        .map(|p| {
            p[15].y
                - [p[7].y, p[8].y, p[10].y, p[11].y]
                    .into_iter()
                    .fold(f32::MAX, f32::min)
        })
        .fold(f32::MIN, f32::max);
    if !(1.2..=2.0).contains(&height) {
        return fail(format!("head {height:.3} m above the lowest foot"));
    }
    // Sides: turn each pose to face +Z by a direction that does not use the left/right
    // labels; the left hip and shoulder must then have the larger X, and HumanML3D's
    // hip/shoulder facing must agree with that direction.
    let references: Vec<(usize, Vec3)> = (0..m.len())
        .filter_map(|i| reference_forward(&label(path), m, i).map(|f| (i, f)))
        .collect();
    let n = references.len();
    let sides_ok = references
        .iter()
        .filter(|(i, f)| {
            let (p, left) = (&m.frames[*i], Vec3::Y.cross(*f)); // left = +X when f = +Z
            (p[1] - p[2]).dot(left) > 0.0 && (p[16] - p[17]).dot(left) > 0.0
        })
        .count();
    let facing_ok = references
        .iter()
        .filter(|(i, f)| forward_from_hips(&m.frames[*i]).dot(*f) > 0.5)
        .count();
    // 80 %: dancers turn their feet out; a mirrored or side-swapped import scores ~10 %.
    if n < 10 || sides_ok * 10 < n * 8 || facing_ok * 10 < n * 8 {
        return fail(format!(
            "left side on the left in {sides_ok}, facings agree in {facing_ok} of {n} frames with a reference direction"
        ));
    }
    // Feet: the lowest foot joint is near the floor in most frames.
    let floor = m
        .frames
        .iter()
        .flat_map(|p| [p[7].y, p[8].y, p[10].y, p[11].y])
        .fold(f32::MAX, f32::min);
    if !(-0.05..=0.15).contains(&floor) {
        return fail(format!("lowest foot joint at y = {floor:.3} m"));
    }
    let grounded = m
        .frames
        .iter()
        .filter(|p| {
            [p[7].y, p[8].y, p[10].y, p[11].y]
                .into_iter()
                .fold(f32::MAX, f32::min)
                < floor + 0.15
        })
        .count();
    if grounded * 10 < m.len() * 7 {
        return fail(format!(
            "a foot is near the floor in only {grounded} of {} frames",
            m.len()
        ));
    }
    Ok(format!(
        "{name}: {} → {} frames, height {height:.2} m, floor {floor:.3} m, sides right in {sides_ok} of {n} frames",
        out.source_frames,
        m.len()
    ))
}

/// Largest relative change of any bone length over the motion.
fn bone_length_drift(m: &Motion) -> f32 {
    (1..NUM_JOINTS)
        .map(|j| {
            let lengths: Vec<f32> = m
                .frames
                .iter()
                .map(|p| p[j].distance(p[PARENTS[j]]))
                .collect();
            let (lo, hi) = lengths
                .iter()
                .fold((f32::MAX, f32::MIN), |(lo, hi), &l| (lo.min(l), hi.max(l)));
            (hi - lo) / hi
        })
        .fold(0.0, f32::max)
}

#[test]
fn bandai_sample_imports_as_plausible_humans() {
    let Some(dir) = data_dir() else { return };
    let files = bvh_files(&dir);
    assert!(
        files.len() > 100,
        "expected the Bandai dataset under {}",
        dir.display()
    );
    let chosen = sample(&files);
    assert!(chosen.len() >= 20, "only {} labels", chosen.len());
    let results: Vec<Result<String, String>> = chosen.par_iter().map(|f| check_file(f)).collect();
    let mut failures = Vec::new();
    for r in results {
        match r {
            Ok(line) => println!("{line}"),
            Err(e) => failures.push(e),
        }
    }
    assert!(
        failures.is_empty(),
        "{} of {} files failed:\n{}",
        failures.len(),
        chosen.len(),
        failures.join("\n")
    );
}

#[test]
fn bandai_bones_are_rigid() {
    let Some(dir) = data_dir() else { return };
    let files = bvh_files(&dir);
    for path in sample(&files).iter().take(8) {
        // At the source rate the bones are exactly rigid …
        let native = BvhImportOptions {
            fps: 30.0,
            ..Default::default()
        };
        let drift = bone_length_drift(&import_bvh(path, &native).unwrap().motion);
        assert!(
            drift < 1e-3,
            "{}: bone length drift {drift}",
            path.display()
        );
        // … and resampling by linear interpolation shortens fast-turning bones a little.
        let drift = bone_length_drift(
            &import_bvh(path, &BvhImportOptions::default())
                .unwrap()
                .motion,
        );
        assert!(
            drift < 0.05,
            "{}: bone length drift {drift} at 20 fps",
            path.display()
        );
    }
}

#[test]
#[ignore = "imports every file (minutes); run with --ignored to measure"]
fn import_all_files() {
    let Some(dir) = data_dir() else { return };
    let files = bvh_files(&dir);
    let start = Instant::now();
    let results: Vec<Result<(usize, usize), String>> = files
        .par_iter()
        .map(|f| {
            import_bvh(f, &BvhImportOptions::default())
                .map(|out| (out.source_frames, out.motion.len()))
                .map_err(|e| e.to_string())
        })
        .collect();
    let elapsed = start.elapsed().as_secs_f32();
    let errors: Vec<&String> = results.iter().filter_map(|r| r.as_ref().err()).collect();
    let (source, resampled) = results
        .iter()
        .flatten()
        .fold((0, 0), |(a, b), (s, r)| (a + s, b + r));
    println!(
        "imported {} files in {elapsed:.1} s on {} threads: {source} frames at 30 fps → {resampled} at 20 fps = {:.2} h; {} errors",
        files.len(),
        rayon::current_num_threads(),
        resampled as f32 / 20.0 / 3600.0,
        errors.len()
    );
    for e in errors.iter().take(10) {
        println!("  {e}");
    }
    assert!(errors.is_empty());
}
