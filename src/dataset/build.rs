//! `mprog data build`: every BVH (and ASF/AMC) file under a folder → one training set.
//!
//! Per file: import (22 joints, metres, 20 fps) → HumanML3D features on the uniform
//! skeleton (plus a left/right mirrored copy) → joints recovered from those features.
//! Captions come from the file name's source family ([`super::labels`]). Files that cannot
//! be read are reported and skipped; `rigs.json` counts files read and skipped and minutes
//! per source family and rig. The whole set is written into a fresh folder beside the
//! target and renamed into place at the end, so an interrupted build never leaves a
//! half-written training set.

use super::captions_cmu::read_trial_index;
use super::labels::{ClipText, LabelContext, clip_text, mirrored};
use super::split::split_of;
use super::stats::feature_stats;
use super::store::{
    ClipInfo, DATASET_VERSION, DatasetIndex, FEATURE_DIM, Split, SplitStats, write_f32_npy,
};
use super::takes::{Unit, plan_units};
use crate::features::{ExtractOptions, extract, recover_from_ric};
use crate::formats::bvh::{BvhImport, BvhImportOptions, import_bvh, import_parsed};
use crate::motion::Motion;
use crate::skeleton::{FPS, NUM_JOINTS, mirror_joint};
use rayon::prelude::*;
use serde::Serialize;
use std::collections::{BTreeMap, HashMap};
use std::path::{Path, PathBuf};
use std::time::Instant;

/// Settings of a build.
#[derive(Clone, Debug)]
pub struct BuildOptions {
    /// Add a left/right mirrored copy of every clip (captions mirrored too).
    pub mirror: bool,
    /// Clips shorter than this many feature frames are skipped.
    pub min_frames: usize,
}

impl Default for BuildOptions {
    fn default() -> Self {
        BuildOptions {
            mirror: true,
            min_frames: 20,
        }
    }
}

/// Errors that stop a build (unreadable single files only skip).
#[derive(Debug, thiserror::Error)]
pub enum BuildError {
    /// Nothing to build from.
    #[error("no .bvh files (nor .amc) under {0}")]
    NoFiles(PathBuf),
    /// Every file failed.
    #[error("none of the {0} BVH files could be converted; first error: {1}")]
    NothingConverted(usize, String),
    /// Writing the output failed.
    #[error("cannot write {path}: {source}")]
    Write {
        /// The file or folder.
        path: PathBuf,
        /// Why.
        source: std::io::Error,
    },
}

/// One converted clip before it is placed in the arrays.
struct Converted {
    info: ClipInfo,
    features: Vec<f32>,
    joints: Vec<f32>,
}

/// Files read and skipped, and minutes of motion, of one source family and rig.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct RigStats {
    /// Source family from the file name (`bandai`, `hdm05`, `cmu`, `deepmimic`, `?`).
    pub family: String,
    /// Rig from the joint map (`bandai-namco`, `cmu-cgspeed-31`, …; `?` if unread).
    pub rig: String,
    /// Files converted.
    pub read: usize,
    /// Files skipped.
    pub skipped: usize,
    /// Minutes of motion read (20 fps, mirrored copies not counted).
    pub minutes: f64,
    /// Skip reasons (the message without the file name) and how often each came.
    pub reasons: BTreeMap<String, usize>,
}

/// What [`build_dataset_report`] made.
#[derive(Clone, Debug)]
pub struct Built {
    /// The index written to `clips.json`.
    pub index: DatasetIndex,
    /// Per family and rig, sorted; also written to `rigs.json`.
    pub rigs: Vec<RigStats>,
}

/// Lists `.bvh` files under `dir`, sorted so the build is deterministic.
pub fn find_bvh_files(dir: &Path) -> Vec<PathBuf> {
    find_files(dir, &["bvh"])
}

/// Lists the motion files a build reads (`.bvh`, `.amc`) under `dir`, sorted.
pub fn find_motion_files(dir: &Path) -> Vec<PathBuf> {
    find_files(dir, &["bvh", "amc"])
}

/// The first `cmu_trial_index.csv` under `dir` (sorted walk), if any.
pub fn find_trial_index(dir: &Path) -> Option<PathBuf> {
    find_files(dir, &["csv"])
        .into_iter()
        .find(|p| p.file_name().is_some_and(|n| n == "cmu_trial_index.csv"))
}

fn find_files(dir: &Path, extensions: &[&str]) -> Vec<PathBuf> {
    let mut out = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        let Ok(entries) = std::fs::read_dir(&d) else {
            continue;
        };
        for e in entries.flatten() {
            let p = e.path();
            if p.is_dir() {
                stack.push(p);
            } else if p
                .extension()
                .is_some_and(|x| extensions.iter().any(|e| x.eq_ignore_ascii_case(e)))
            {
                out.push(p);
            }
        }
    }
    out.sort();
    out
}

/// Mirrors a motion left/right: negate x, swap left and right joints.
pub fn mirror_motion(m: &Motion) -> Motion {
    let frames = m
        .frames
        .iter()
        .map(|p| {
            std::array::from_fn(|j| {
                let mut v = p[mirror_joint(j)];
                v.x = -v.x;
                v
            })
        })
        .collect();
    Motion { frames, fps: m.fps }
}

fn to_clip(
    motion: &Motion,
    name: String,
    source: &str,
    text: &ClipText,
    mirrored: bool,
) -> Result<Converted, String> {
    let features = extract(
        motion,
        &ExtractOptions {
            uniform_skeleton: true,
        },
    )
    .map_err(|e| e.to_string())?;
    let frames = features.frames();
    let features = features.into_vec();
    if features.iter().any(|v| !v.is_finite()) {
        return Err("features contain NaN or infinite values".into());
    }
    let joints = recover_from_ric(&features)
        .map_err(|e| e.to_string())?
        .to_flat();
    Ok(Converted {
        info: ClipInfo {
            name,
            source: source.to_string(),
            content: text.content.clone(),
            style: text.style.clone(),
            mirrored,
            split: split_of(source),
            offset: 0,
            frames,
            captions: text.captions.clone(),
        },
        features,
        joints,
    })
}

/// A converted file (or joined take, see [`super::takes`]): its clips, family and rig.
struct FileResult {
    family: &'static str,
    rig: Option<&'static str>,
    clips: Result<Vec<Converted>, String>,
    /// Files read into it.
    files: usize,
}

/// Imports one motion file by its extension (`.amc` with the `.asf` beside it).
fn import_file(path: &Path) -> Result<BvhImport, String> {
    let opts = BvhImportOptions::default();
    let amc = path
        .extension()
        .is_some_and(|x| x.eq_ignore_ascii_case("amc"));
    if amc {
        crate::formats::asf::import_amc_beside_asf(path, &opts).map_err(|e| e.to_string())
    } else {
        import_bvh(path, &opts).map_err(|e| e.to_string())
    }
}

/// Converts one file, or one take joined from cuts, into its clip (and mirrored clip).
/// A take is captioned by its first cut's name and split by its first cut's path.
fn convert_unit(unit: Unit, root: &Path, ctx: &LabelContext, opts: &BuildOptions) -> FileResult {
    let path = unit.first();
    let source = path
        .strip_prefix(root)
        .unwrap_or(path)
        .to_string_lossy()
        .to_string();
    let stem = path
        .file_stem()
        .map(|s| s.to_string_lossy().to_string())
        .unwrap_or_default();
    let files = unit.file_count();
    let name = unit.name();
    let text = clip_text(&stem, ctx);
    let family = text.as_ref().map_or("?", |t| t.family);
    let import = match unit {
        Unit::File(path) => import_file(&path),
        Unit::Take { files, bvh } => {
            let origin = format!("{} (+{} cuts)", files[0].display(), files.len() - 1);
            import_parsed(&origin, bvh, &BvhImportOptions::default()).map_err(|e| e.to_string())
        }
    };
    let (rig, clips) = match text.and_then(|t| import.map(|i| (t, i))) {
        Err(e) => (None, Err(e)),
        Ok((text, import)) => (
            Some(import.joint_map.rig),
            clips_of(&import.motion, &name, &source, &text, opts),
        ),
    };
    FileResult {
        family,
        rig,
        clips,
        files,
    }
}

fn clips_of(
    motion: &Motion,
    stem: &str,
    source: &str,
    text: &ClipText,
    opts: &BuildOptions,
) -> Result<Vec<Converted>, String> {
    if motion.len() < opts.min_frames + 1 {
        return Err(format!(
            "only {} frames at 20 fps (need {})",
            motion.len(),
            opts.min_frames + 1
        ));
    }
    let mut out = vec![to_clip(motion, stem.to_string(), source, text, false)?];
    if opts.mirror {
        out.push(to_clip(
            &mirror_motion(motion),
            format!("{stem}_mirror"),
            source,
            &mirrored(text),
            true,
        )?);
    }
    Ok(out)
}

/// Builds the training set from `bvh_dir` into `out` (see [`build_dataset_report`]).
pub fn build_dataset(
    bvh_dir: &Path,
    out: &Path,
    opts: &BuildOptions,
    tick: &(dyn Fn(&Path) + Sync),
) -> Result<DatasetIndex, BuildError> {
    build_dataset_report(bvh_dir, out, opts, tick).map(|b| b.index)
}

/// Clip names must be unique: the same CMU trial comes in several rigs (`02_01` in the
/// cgspeed and DeepMimic folders), so repeated names get `@rig`, and `@rig-2`, `@rig-3`…
/// if that still repeats (files are in sorted order, so names are stable).
fn unique_names(results: &mut [(PathBuf, FileResult)]) {
    let mut count: HashMap<String, usize> = HashMap::new();
    for (_, r) in results.iter() {
        for c in r.clips.iter().flatten().filter(|c| !c.info.mirrored) {
            *count.entry(c.info.name.clone()).or_default() += 1;
        }
    }
    let mut taken: HashMap<String, usize> = HashMap::new();
    for (_, r) in results.iter_mut() {
        let rig = r.rig.unwrap_or("?");
        let Ok(clips) = r.clips.as_mut() else {
            continue;
        };
        let Some(stem) = clips.first().map(|c| c.info.name.clone()) else {
            continue;
        };
        if count[&stem] < 2 {
            continue;
        }
        let base = format!("{stem}@{rig}");
        let seen = taken.entry(base.clone()).or_default();
        *seen += 1;
        let name = if *seen == 1 {
            base
        } else {
            format!("{base}-{seen}")
        };
        for c in clips.iter_mut() {
            c.info.name = if c.info.mirrored {
                format!("{name}_mirror")
            } else {
                name.clone()
            };
        }
    }
}

fn rig_stats(results: &[(PathBuf, FileResult)]) -> Vec<RigStats> {
    let mut stats: BTreeMap<(String, String), RigStats> = BTreeMap::new();
    for (path, r) in results {
        let (family, rig) = (r.family.to_string(), r.rig.unwrap_or("?").to_string());
        let s = stats
            .entry((family.clone(), rig.clone()))
            .or_insert_with(|| RigStats {
                family,
                rig,
                ..RigStats::default()
            });
        match &r.clips {
            Ok(clips) => {
                s.read += r.files;
                let frames: usize = clips
                    .iter()
                    .filter(|c| !c.info.mirrored)
                    .map(|c| c.info.frames)
                    .sum();
                s.minutes += frames as f64 / FPS as f64 / 60.0;
            }
            Err(reason) => {
                s.skipped += r.files;
                // Reasons name the file; count them without it.
                let shown = path.display().to_string();
                let short = reason.replace(&shown, "<file>");
                *s.reasons.entry(short).or_default() += 1;
            }
        }
    }
    stats.into_values().collect()
}

/// Builds the training set from every `.bvh` and `.amc` under `bvh_dir` into `out`,
/// calling `tick` after each file; CMU captions need a `cmu_trial_index.csv` under it.
pub fn build_dataset_report(
    bvh_dir: &Path,
    out: &Path,
    opts: &BuildOptions,
    tick: &(dyn Fn(&Path) + Sync),
) -> Result<Built, BuildError> {
    let start = Instant::now();
    let files = find_motion_files(bvh_dir);
    if files.is_empty() {
        return Err(BuildError::NoFiles(bvh_dir.to_path_buf()));
    }
    let mut ctx = LabelContext::default();
    let mut notes = Vec::new();
    if let Some(csv) = find_trial_index(bvh_dir) {
        match read_trial_index(&csv) {
            Ok(index) => ctx.cmu = Some(index),
            Err(e) => notes.push((csv.display().to_string(), e)),
        }
    }
    let mut results: Vec<(PathBuf, FileResult)> = plan_units(&files)
        .into_par_iter()
        .map(|unit| {
            let paths = unit.files().to_vec();
            let r = convert_unit(unit, bvh_dir, &ctx, opts);
            paths.iter().for_each(|p| tick(p));
            (paths[0].clone(), r)
        })
        .collect();
    unique_names(&mut results);
    let rigs = rig_stats(&results);
    let mut clips = Vec::new();
    let mut features = Vec::new();
    let mut joints = Vec::new();
    let mut skipped = notes;
    for (path, result) in results {
        match result.clips {
            Ok(converted) => {
                for mut c in converted {
                    c.info.offset = features.len() / FEATURE_DIM;
                    features.extend_from_slice(&c.features);
                    joints.extend_from_slice(&c.joints);
                    clips.push(c.info);
                }
            }
            Err(reason) => skipped.push((path.display().to_string(), reason)),
        }
    }
    if clips.is_empty() {
        let first = skipped
            .first()
            .map(|s| format!("{}: {}", s.0, s.1))
            .unwrap_or_default();
        return Err(BuildError::NothingConverted(files.len(), first));
    }
    let train_rows: Vec<&[f32]> = clips
        .iter()
        .filter(|c| c.split == Split::Train)
        .map(|c| &features[c.offset * FEATURE_DIM..(c.offset + c.frames) * FEATURE_DIM])
        .collect();
    let (mean, std) = feature_stats(&train_rows);
    let stats = [Split::Train, Split::Val, Split::Test].map(|s| {
        let frames: usize = clips
            .iter()
            .filter(|c| c.split == s)
            .map(|c| c.frames)
            .sum();
        SplitStats {
            clips: clips.iter().filter(|c| c.split == s).count(),
            frames,
            hours: frames as f64 / FPS as f64 / 3600.0,
        }
    });
    let index = DatasetIndex {
        version: DATASET_VERSION,
        fps: FPS,
        clips,
        stats,
        skipped,
        build_seconds: start.elapsed().as_secs_f64(),
    };
    write_dataset(out, &index, &rigs, &features, &joints, &mean, &std)?;
    Ok(Built { index, rigs })
}

fn write_dataset(
    out: &Path,
    index: &DatasetIndex,
    rigs: &[RigStats],
    features: &[f32],
    joints: &[f32],
    mean: &[f32],
    std: &[f32],
) -> Result<(), BuildError> {
    let werr = |path: &Path| {
        let path = path.to_path_buf();
        move |source| BuildError::Write { path, source }
    };
    let name = out
        .file_name()
        .map(|n| n.to_string_lossy().to_string())
        .unwrap_or_else(|| "dataset".into());
    let staging = out.with_file_name(format!(".{name}.building"));
    if staging.exists() {
        std::fs::remove_dir_all(&staging).map_err(werr(&staging))?;
    }
    std::fs::create_dir_all(&staging).map_err(werr(&staging))?;
    let frames = (features.len() / FEATURE_DIM) as u64;
    let put = |file: &str, shape: &[u64], data: &[f32]| {
        let p = staging.join(file);
        write_f32_npy(&p, shape, data).map_err(werr(&p))
    };
    put("features.npy", &[frames, FEATURE_DIM as u64], features)?;
    put("joints.npy", &[frames, NUM_JOINTS as u64, 3], joints)?;
    put("mean.npy", &[FEATURE_DIM as u64], mean)?;
    put("std.npy", &[FEATURE_DIM as u64], std)?;
    let p = staging.join("clips.json");
    let json = serde_json::to_vec_pretty(index).expect("index serialises");
    crate::fsutil::write_bytes_atomic(&p, &json).map_err(werr(&p))?;
    let p = staging.join("rigs.json");
    let json = serde_json::to_vec_pretty(rigs).expect("rig stats serialise");
    crate::fsutil::write_bytes_atomic(&p, &json).map_err(werr(&p))?;
    let old = out.with_file_name(format!(".{name}.old"));
    if out.exists() {
        if old.exists() {
            std::fs::remove_dir_all(&old).map_err(werr(&old))?;
        }
        std::fs::rename(out, &old).map_err(werr(out))?;
    }
    std::fs::rename(&staging, out).map_err(werr(out))?;
    if old.exists() {
        std::fs::remove_dir_all(&old).map_err(werr(&old))?;
    }
    Ok(())
}
