//! `mprog data build`: every BVH file under a folder → one training set.
//!
//! Per file: import (22 joints, metres, 20 fps) → HumanML3D features on the uniform
//! skeleton (plus a left/right mirrored copy) → joints recovered from those features.
//! Files that cannot be read are reported and skipped. The whole set is written into a
//! fresh folder beside the target and renamed into place at the end, so an interrupted
//! build never leaves a half-written training set.

use super::captions::{Labels, captions, mirror_content, parse_labels};
use super::split::split_of;
use super::stats::feature_stats;
use super::store::{
    ClipInfo, DATASET_VERSION, DatasetIndex, FEATURE_DIM, Split, SplitStats, write_f32_npy,
};
use crate::features::{ExtractOptions, extract, recover_from_ric};
use crate::formats::bvh::{BvhImportOptions, import_bvh};
use crate::motion::Motion;
use crate::skeleton::{FPS, NUM_JOINTS, mirror_joint};
use rayon::prelude::*;
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
    #[error("no .bvh files under {0}")]
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

/// Lists `.bvh` files under `dir`, sorted so the build is deterministic.
pub fn find_bvh_files(dir: &Path) -> Vec<PathBuf> {
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
            } else if p.extension().is_some_and(|x| x.eq_ignore_ascii_case("bvh")) {
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
    labels: &Labels,
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
    let caps = captions(labels);
    if caps.is_empty() {
        return Err(format!(
            "no captions for the motion label `{}`",
            labels.content
        ));
    }
    Ok(Converted {
        info: ClipInfo {
            name,
            source: source.to_string(),
            content: labels.content.clone(),
            style: labels.style.clone(),
            mirrored,
            split: split_of(source),
            offset: 0,
            frames,
            captions: caps,
        },
        features,
        joints,
    })
}

/// Converts one file into its clip (and mirrored clip).
fn convert_file(path: &Path, root: &Path, opts: &BuildOptions) -> Result<Vec<Converted>, String> {
    let source = path
        .strip_prefix(root)
        .unwrap_or(path)
        .to_string_lossy()
        .to_string();
    let stem = path
        .file_stem()
        .map(|s| s.to_string_lossy().to_string())
        .unwrap_or_default();
    let labels = parse_labels(&stem)
        .ok_or_else(|| format!("file name `{stem}` has no `dataset-N_content_style_id` labels"))?;
    let import = import_bvh(path, &BvhImportOptions::default()).map_err(|e| e.to_string())?;
    let motion = import.motion;
    if motion.len() < opts.min_frames + 1 {
        return Err(format!(
            "only {} frames at 20 fps (need {})",
            motion.len(),
            opts.min_frames + 1
        ));
    }
    let mut out = vec![to_clip(&motion, stem.clone(), &source, &labels, false)?];
    if opts.mirror {
        let mirrored = Labels {
            content: mirror_content(&labels.content),
            style: labels.style.clone(),
        };
        out.push(to_clip(
            &mirror_motion(&motion),
            format!("{stem}_mirror"),
            &source,
            &mirrored,
            true,
        )?);
    }
    Ok(out)
}

/// Builds the training set from `bvh_dir` into `out`, calling `tick` after each file.
pub fn build_dataset(
    bvh_dir: &Path,
    out: &Path,
    opts: &BuildOptions,
    tick: &(dyn Fn(&Path) + Sync),
) -> Result<DatasetIndex, BuildError> {
    let start = Instant::now();
    let files = find_bvh_files(bvh_dir);
    if files.is_empty() {
        return Err(BuildError::NoFiles(bvh_dir.to_path_buf()));
    }
    let results: Vec<(PathBuf, Result<Vec<Converted>, String>)> = files
        .par_iter()
        .map(|p| {
            let r = convert_file(p, bvh_dir, opts);
            tick(p);
            (p.clone(), r)
        })
        .collect();
    let mut clips = Vec::new();
    let mut features = Vec::new();
    let mut joints = Vec::new();
    let mut skipped = Vec::new();
    for (path, result) in results {
        match result {
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
    write_dataset(out, &index, &features, &joints, &mean, &std)?;
    Ok(index)
}

fn write_dataset(
    out: &Path,
    index: &DatasetIndex,
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
