//! HDM05's "cut" files split one recording into repetitions: `HDM_bd_squat1Reps_001` to
//! `_004` are one take, and each cut starts on the very frame the previous one ended with.
//! A single cut is short (a hop is 13 frames at 20 fps, a squat 23), and a short clip is
//! mostly padding in a 120-frame training batch, so the prior rarely learns it and never
//! at the lengths it is asked for. The build therefore joins a run of cuts back into the
//! take they came from, but only where the evidence says they are one take: the same
//! actor, class and hierarchy, consecutive numbers, and the first frame of each cut equal
//! to the last frame of the one before (every channel value). Joined takes also keep all
//! repetitions of one recording in one split.

use crate::dataset::captions_hdm05::hdm05_class;
use crate::formats::bvh::parse::{Bvh, ParseLimits, parse_bvh};
use crate::formats::bvh::text::decode;
use rayon::prelude::*;
use std::path::{Path, PathBuf};

/// What the build converts: one file, or several cuts joined into their take.
pub enum Unit {
    /// A file converted on its own.
    File(PathBuf),
    /// Cuts of one take, in order, and their frames joined (the shared boundary frames
    /// kept once).
    Take {
        /// The cut files.
        files: Vec<PathBuf>,
        /// The joined motion.
        bvh: Bvh,
    },
}

impl Unit {
    /// The first file: its name gives the captions and its path the split.
    pub fn first(&self) -> &Path {
        match self {
            Unit::File(p) => p,
            Unit::Take { files, .. } => &files[0],
        }
    }

    /// The files read into this unit.
    pub fn files(&self) -> &[PathBuf] {
        match self {
            Unit::File(p) => std::slice::from_ref(p),
            Unit::Take { files, .. } => files,
        }
    }

    /// Files read into this unit.
    pub fn file_count(&self) -> usize {
        self.files().len()
    }

    /// The clip's name: the file stem, or for a take its first and last cut numbers
    /// (`HDM_bd_squat1Reps_001-004_120`).
    pub fn name(&self) -> String {
        let stem = |p: &Path| {
            p.file_stem()
                .map(|s| s.to_string_lossy().to_string())
                .unwrap_or_default()
        };
        match self {
            Unit::File(p) => stem(p),
            Unit::Take { files, .. } => {
                let last = files.last().and_then(|p| cut_id(p)).map_or(0, |id| id.2);
                take_name(&stem(&files[0]), last)
            }
        }
    }
}

/// `(actor, class, number)` of an HDM05 cut `HDM_<actor>_<class>_<nnn>[_<fps>].bvh`.
fn cut_id(path: &Path) -> Option<(String, String, u32)> {
    if !path
        .extension()
        .is_some_and(|x| x.eq_ignore_ascii_case("bvh"))
    {
        return None;
    }
    let stem = path.file_stem()?.to_str()?;
    let class = hdm05_class(stem)?;
    let mut parts = stem.split('_');
    let actor = parts.nth(1)?;
    let number = parts.nth(1)?.parse().ok()?;
    Some((actor.to_string(), class.to_string(), number))
}

/// The name of a take joined from cuts `first..=last`: `HDM_bd_squat1Reps_001-004_120`.
fn take_name(first_stem: &str, last_number: u32) -> String {
    let parts: Vec<&str> = first_stem.split('_').collect();
    match parts.get(3) {
        Some(num) => {
            let width = num.len();
            let mut out = parts[..3].join("_");
            out.push_str(&format!("_{num}-{last_number:0width$}"));
            for p in &parts[4..] {
                out.push('_');
                out.push_str(p);
            }
            out
        }
        None => format!("{first_stem}+"),
    }
}

/// True when `next` continues `prev`: the same hierarchy and frame time, and its first
/// frame equal to `prev`'s last.
fn continues(prev: &Bvh, next: &Bvh) -> bool {
    prev.joints == next.joints
        && prev.frame_time == next.frame_time
        && prev.frame_count > 0
        && next.frame_count > 0
        && prev.frame(prev.frame_count - 1) == next.frame(0)
}

/// `a` with `b` appended, `b`'s first frame (the shared boundary) dropped.
fn append(mut a: Bvh, b: &Bvh) -> Bvh {
    a.values.extend_from_slice(&b.values[b.channel_count..]);
    a.frame_count += b.frame_count - 1;
    a
}

fn read(path: &Path) -> Option<Bvh> {
    let bytes = std::fs::read(path).ok()?;
    let origin = path.display().to_string();
    let text = decode(&origin, &bytes).ok()?;
    parse_bvh(&origin, text, ParseLimits::default()).ok()
}

/// Runs of candidate cuts (same actor and class, consecutive numbers), in file order;
/// every other file is a run of one.
fn candidate_runs(files: &[PathBuf]) -> Vec<Vec<PathBuf>> {
    let mut runs: Vec<Vec<PathBuf>> = Vec::new();
    let mut last: Option<(String, String, u32)> = None;
    for f in files {
        let id = cut_id(f);
        let extends = match (&last, &id) {
            (Some((a, c, n)), Some((a2, c2, n2))) => a == a2 && c == c2 && *n2 == n + 1,
            _ => false,
        };
        match runs.last_mut() {
            Some(run) if extends => run.push(f.clone()),
            _ => runs.push(vec![f.clone()]),
        }
        last = id;
    }
    runs
}

/// Splits a run of candidate cuts where the frames do not continue (or a file does not
/// parse; it is then converted alone, and reports its own error).
fn join_run(run: Vec<PathBuf>) -> Vec<Unit> {
    if run.len() == 1 {
        return run.into_iter().map(Unit::File).collect();
    }
    let mut units = Vec::new();
    let mut open: Option<(Vec<PathBuf>, Bvh)> = None;
    let close = |open: Option<(Vec<PathBuf>, Bvh)>, units: &mut Vec<Unit>| {
        if let Some((mut files, bvh)) = open {
            units.push(if files.len() == 1 {
                Unit::File(files.remove(0))
            } else {
                Unit::Take { files, bvh }
            });
        }
    };
    for path in run {
        let Some(bvh) = read(&path) else {
            close(open.take(), &mut units);
            units.push(Unit::File(path));
            continue;
        };
        open = match open.take() {
            Some((mut files, joined)) if continues(&joined, &bvh) => {
                files.push(path);
                Some((files, append(joined, &bvh)))
            }
            other => {
                close(other, &mut units);
                Some((vec![path], bvh))
            }
        };
    }
    close(open, &mut units);
    units
}

/// The build's units for a sorted file list: HDM05 cuts joined into takes where their
/// frames continue, every other file alone.
pub fn plan_units(files: &[PathBuf]) -> Vec<Unit> {
    candidate_runs(files)
        .into_par_iter()
        .map(join_run)
        .collect::<Vec<_>>()
        .into_iter()
        .flatten()
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    const HEADER: &str = "HIERARCHY\nROOT hip\n{\n  OFFSET 0 0 0\n  CHANNELS 3 Xposition Yposition Zposition\n  End Site\n  {\n    OFFSET 0 1 0\n  }\n}\nMOTION\n";

    fn write(dir: &Path, name: &str, frames: &[[f32; 3]]) -> PathBuf {
        let mut text = format!("{HEADER}Frames: {}\nFrame Time: 0.008333\n", frames.len());
        for f in frames {
            text.push_str(&format!("{} {} {}\n", f[0], f[1], f[2]));
        }
        let p = dir.join(name);
        std::fs::write(&p, text).unwrap();
        p
    }

    #[test]
    fn names_of_joined_takes() {
        assert_eq!(
            take_name("HDM_bd_squat1Reps_001_120", 4),
            "HDM_bd_squat1Reps_001-004_120"
        );
        assert_eq!(
            take_name("HDM_bd_squat1Reps_009", 12),
            "HDM_bd_squat1Reps_009-012"
        );
    }

    #[test]
    fn continuous_cuts_join_and_others_stay_alone() {
        let dir = tempfile::tempdir().unwrap();
        let d = dir.path();
        let files = vec![
            write(d, "HDM_bd_hop_001_120.bvh", &[[0., 0., 0.], [1., 0., 0.]]),
            write(d, "HDM_bd_hop_002_120.bvh", &[[1., 0., 0.], [2., 0., 0.]]),
            write(d, "HDM_bd_hop_003_120.bvh", &[[2., 0., 0.], [3., 0., 0.]]),
            // Consecutive number, but a new recording: its first frame is elsewhere.
            write(d, "HDM_bd_hop_004_120.bvh", &[[9., 0., 0.], [8., 0., 0.]]),
            // Same frames, but another actor.
            write(d, "HDM_mm_hop_005_120.bvh", &[[8., 0., 0.], [7., 0., 0.]]),
            write(d, "walk_001.bvh", &[[7., 0., 0.], [6., 0., 0.]]),
        ];
        let units = plan_units(&files);
        assert_eq!(units.len(), 4);
        let Unit::Take { files: cuts, bvh } = &units[0] else {
            panic!("the first three cuts are one take");
        };
        assert_eq!(cuts.len(), 3);
        assert_eq!(bvh.frame_count, 4);
        assert_eq!(
            bvh.values,
            vec![0., 0., 0., 1., 0., 0., 2., 0., 0., 3., 0., 0.]
        );
        assert_eq!(units[0].file_count(), 3);
        assert_eq!(units[0].name(), "HDM_bd_hop_001-003_120");
        for (u, f) in units[1..].iter().zip(&files[3..]) {
            assert!(matches!(u, Unit::File(p) if p == f));
        }
    }

    #[test]
    fn an_unreadable_cut_breaks_the_take_and_stays_alone() {
        let dir = tempfile::tempdir().unwrap();
        let d = dir.path();
        let a = write(d, "HDM_bd_hop_001_120.bvh", &[[0., 0., 0.], [1., 0., 0.]]);
        let bad = d.join("HDM_bd_hop_002_120.bvh");
        std::fs::write(&bad, "HIERARCHY\nROOT").unwrap();
        let c = write(d, "HDM_bd_hop_003_120.bvh", &[[1., 0., 0.], [2., 0., 0.]]);
        let units = plan_units(&[a.clone(), bad.clone(), c.clone()]);
        let alone: Vec<&Path> = units.iter().map(Unit::first).collect();
        assert_eq!(alone, vec![a.as_path(), bad.as_path(), c.as_path()]);
        assert!(units.iter().all(|u| u.file_count() == 1));
    }
}
