//! Pose coverage: which poses the training data holds, measured once on a training set
//! and shipped in the model bundle (`<bundle>/coverage.bin`), so `mprog check` and
//! `mprog run` can say when a program asks for a pose no training clip comes near
//! (`mprog::unseen_pose`, `lang::unseen`).
//!
//! The set is a greedy cover of every frame of the training clips: each frame, made
//! canonical (pelvis over the origin, facing +Z, heights kept; [`pose::canonical`]), is
//! within [`Coverage::cover`] (largest joint distance) of one kept pose, and each clip
//! keeps, per frame, which pose stands for it, so how long a pose is held survives
//! (standing on one leg for 5 s against the longest one-leg support recorded). Mirrored
//! copies are not stored: with [`Coverage::mirrored`] every pose is also read mirrored.
//! `mprog data coverage` builds it ([`build::build`]); [`Coverage::builtin`] is the one
//! the binary was built with (the shipped `models/default/coverage.bin`), the fallback for
//! a bundle without its own.

pub mod build;
pub mod file;
pub mod measure;
pub mod pose;
pub mod search;

pub use pose::Pose;
use std::path::Path;

/// The file a model bundle keeps its coverage set in.
pub const COVERAGE_FILE: &str = "coverage.bin";

/// A frame that had no finite pose (breaks runs).
pub const NO_POSE: u32 = u32::MAX;

/// One training clip: its name, what it shows, and the pose of each frame.
#[derive(Clone, Debug, PartialEq)]
pub struct Clip {
    /// Name in the training set.
    pub name: String,
    /// Its first caption.
    pub caption: String,
    /// Per frame (20 fps), the index of the pose standing for it ([`NO_POSE`]: none).
    pub frames: Vec<u32>,
}

/// The poses a training set holds (see the module documentation).
#[derive(Clone, Debug, PartialEq)]
pub struct Coverage {
    /// What it was built from.
    pub source: String,
    /// Every training frame lies within this distance of a pose of the set: the largest
    /// distance between corresponding joints (m).
    pub cover: f32,
    /// The training set held each clip's mirror image too: read every pose mirrored.
    pub mirrored: bool,
    /// The poses, canonical.
    pub poses: Vec<Pose>,
    /// The clips (mirrored copies left out).
    pub clips: Vec<Clip>,
    /// Per pose, the first (clip, frame) it stands for.
    first: Vec<(u32, u32)>,
}

/// Where a pose comes from, for messages.
#[derive(Clone, Debug, PartialEq)]
pub struct Origin {
    /// The clip's name (`…_mirror` for a mirrored pose).
    pub clip: String,
    /// Its first caption.
    pub caption: String,
    /// The frame.
    pub frame: usize,
}

impl Coverage {
    /// A coverage set from its parts; works out where each pose first occurs.
    pub fn new(
        source: String,
        cover: f32,
        mirrored: bool,
        poses: Vec<Pose>,
        clips: Vec<Clip>,
    ) -> Coverage {
        let mut first = vec![(u32::MAX, 0); poses.len()];
        for (c, clip) in clips.iter().enumerate() {
            for (t, &p) in clip.frames.iter().enumerate() {
                if let Some(f) = first.get_mut(p as usize)
                    && f.0 == u32::MAX
                {
                    *f = (c as u32, t as u32);
                }
            }
        }
        Coverage {
            source,
            cover,
            mirrored,
            poses,
            clips,
            first,
        }
    }

    /// Frames of the clips, mirrored copies not counted.
    pub fn frames(&self) -> usize {
        self.clips.iter().map(|c| c.frames.len()).sum()
    }

    /// Poses the search reads: each stored pose, then (when [`Coverage::mirrored`]) each
    /// one mirrored.
    pub fn variants(&self) -> usize {
        self.poses.len() * if self.mirrored { 2 } else { 1 }
    }

    /// Variant `v` of [`Coverage::variants`].
    pub fn variant(&self, v: usize) -> Pose {
        let n = self.poses.len();
        if v < n {
            self.poses[v]
        } else {
            pose::mirrored(&self.poses[v - n])
        }
    }

    /// Where variant `v` comes from.
    pub fn origin(&self, v: usize) -> Origin {
        let n = self.poses.len();
        let (c, t) = self.first[v % n.max(1)];
        let clip = self.clips.get(c as usize);
        let name = clip.map_or("?", |c| c.name.as_str());
        Origin {
            clip: if v >= n {
                format!("{name}_mirror")
            } else {
                name.to_string()
            },
            caption: clip.map_or(String::new(), |c| c.caption.clone()),
            frame: t as usize,
        }
    }

    /// The set this binary was built with (`models/default/coverage.bin` at build time):
    /// what a bundle without its own is searched.
    pub fn builtin() -> Coverage {
        let mut c = file::decode(BUILTIN).expect("the shipped coverage set reads");
        c.source = format!("built in: {}", c.source);
        c
    }

    /// The set of the bundle in `dir`: its own `coverage.bin`, else the built-in one
    /// (which its `source` says). Err: the bundle's file is there but unreadable.
    pub fn for_bundle(dir: &Path) -> Result<Coverage, String> {
        let p = dir.join(COVERAGE_FILE);
        if !p.exists() {
            let mut c = Coverage::builtin();
            c.source = format!("{} (the model has no {COVERAGE_FILE})", c.source);
            return Ok(c);
        }
        file::load(&p)
    }
}

/// The coverage set the binary was built with.
const BUILTIN: &[u8] = include_bytes!("../../models/default/coverage.bin");
