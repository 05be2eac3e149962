//! Which BVH joint (or blend of joints) becomes each of the 22 HumanML3D joints.
//!
//! In: a parsed [`Bvh`]. Out: a [`JointMap`]: for every HumanML3D joint either a source
//! joint or a point between two already-placed HumanML3D joints. Two ways to build it:
//! * exact tables, used when all of their names are present: the 22 HumanML3D names
//!   (mprog's own BVH export, whose zero-offset connector joints must not be taken for
//!   spine joints) and one table per rig family in [`super::rigs`] (Bandai-Namco, CMU
//!   cgspeed, CMU/HDM05 ASF names, DeepMimic);
//! * name matching for other rigs (Daz, Mixamo, SMPL, UE, Biped, Blender `.L/.R`), with the
//!   spine taken from the hierarchy between pelvis and neck.
//!
//! Joints with no counterpart are filled where that is safe: spine joints by interpolation
//! along the spine at HumanML3D's rest proportions, a missing toe by the ankle's End Site,
//! a missing collar halfway between spine3 and the shoulder (each with a warning).
//! Anything else missing is an error that lists the missing joints.

use super::error::BvhErrorKind;
use super::names::{NameParts, Side, split_name};
use super::parse::Bvh;
use super::rigs::{self, Pick};
use crate::motion::Pose;
use crate::skeleton::{BONE_LENGTHS, JOINT_NAMES, NUM_JOINTS};
use glam::Vec3;

/// Where one HumanML3D joint comes from.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum JointSource {
    /// A BVH joint (index into [`Bvh::joints`]; End Sites allowed).
    Joint(usize),
    /// `(1 − t)·target[from] + t·target[to]`, between two HumanML3D joints placed earlier
    /// (lower index or a direct joint).
    Lerp { from: usize, to: usize, t: f32 },
    /// `(1 − t)·source[a] + t·source[b]`, between two BVH joints (End Sites allowed).
    Between { a: usize, b: usize, t: f32 },
}

/// The joint map used for an import.
#[derive(Clone, Debug, PartialEq)]
pub struct JointMap {
    /// `humanml3d`, a [`rigs::RigTable`] name (`bandai-namco`, `cmu-asf`, …) or
    /// `name-matched`.
    pub rig: &'static str,
    /// Source of each HumanML3D joint, index = HumanML3D joint.
    pub sources: [JointSource; NUM_JOINTS],
    /// Source joints (not End Sites) that no HumanML3D joint uses.
    pub unused: Vec<String>,
    /// What had to be filled in or guessed.
    pub warnings: Vec<String>,
}

impl JointMap {
    /// The 22 joints of one frame from that frame's global BVH joint positions.
    pub fn pose(&self, globals: &[Vec3]) -> Pose {
        let mut pose = [Vec3::ZERO; NUM_JOINTS];
        for (j, source) in self.sources.iter().enumerate() {
            match *source {
                JointSource::Joint(index) => pose[j] = globals[index],
                JointSource::Between { a, b, t } => pose[j] = globals[a].lerp(globals[b], t),
                JointSource::Lerp { .. } => {}
            }
        }
        for (j, source) in self.sources.iter().enumerate() {
            if let JointSource::Lerp { from, to, t } = *source {
                pose[j] = pose[from].lerp(pose[to], t);
            }
        }
        pose
    }

    /// One line per HumanML3D joint: `spine2 ← 0.71 of the way spine1 → spine3`.
    pub fn describe(&self, bvh: &Bvh) -> Vec<String> {
        self.sources
            .iter()
            .enumerate()
            .map(|(j, s)| match *s {
                JointSource::Joint(i) => format!("{} ← {}", JOINT_NAMES[j], bvh.joints[i].name),
                JointSource::Lerp { from, to, t } => format!(
                    "{} ← {t:.2} of the way {} → {}",
                    JOINT_NAMES[j], JOINT_NAMES[from], JOINT_NAMES[to]
                ),
                JointSource::Between { a, b, t } => format!(
                    "{} ← {t:.2} of the way {} → {}",
                    JOINT_NAMES[j],
                    bvh.joints[a].name,
                    joint_label(bvh, b)
                ),
            })
            .collect()
    }
}

/// `name` or `name's End Site`.
fn joint_label(bvh: &Bvh, j: usize) -> String {
    let joint = &bvh.joints[j];
    match (joint.end_site, joint.parent) {
        (true, Some(p)) => format!("End Site of {}", bvh.joints[p].name),
        _ => joint.name.clone(),
    }
}

/// What [`map_partial`] found: the rig family and a source for each joint it could place.
#[derive(Clone, Debug, PartialEq)]
pub struct PartialMap {
    /// As [`JointMap::rig`].
    pub rig: &'static str,
    /// Source of each HumanML3D joint, `None` where nothing fits.
    pub found: [Option<JointSource>; NUM_JOINTS],
    /// What had to be filled in or guessed.
    pub warnings: Vec<String>,
}

/// Builds the joint map: HumanML3D's own names, else the first rig table that fits
/// ([`rigs::detect`]), else name matching.
pub fn map_joints(bvh: &Bvh) -> Result<JointMap, BvhErrorKind> {
    let PartialMap {
        rig,
        found,
        warnings,
    } = map_partial(bvh);
    complete(bvh, rig, found, warnings)
}

/// Where each HumanML3D joint comes from, as far as the names, tables and fills of
/// [`map_joints`] tell; joints with no source are `None` rather than an error.
pub fn map_partial(bvh: &Bvh) -> PartialMap {
    let mut found: [Option<JointSource>; NUM_JOINTS] = [None; NUM_JOINTS];
    let mut warnings = Vec::new();
    let humanml3d: Option<Vec<usize>> = JOINT_NAMES.iter().map(|n| bvh.joint_index(n)).collect();
    let rig = if let Some(indices) = humanml3d {
        for (target, index) in indices.into_iter().enumerate() {
            found[target] = Some(JointSource::Joint(index));
        }
        "humanml3d"
    } else if let Some(table) = rigs::detect(bvh) {
        for (target, pick) in table.picks.iter().enumerate() {
            found[target] = resolve(bvh, *pick);
        }
        table.name
    } else {
        match_by_name(bvh, &mut found, &mut warnings);
        "name-matched"
    };
    fill_spine(bvh, &mut found, &mut warnings);
    fill_extremities(bvh, &mut found, &mut warnings);
    PartialMap {
        rig,
        found,
        warnings,
    }
}

/// The joint map when every joint has a source, else the error listing the missing ones.
fn complete(
    bvh: &Bvh,
    rig: &'static str,
    found: [Option<JointSource>; NUM_JOINTS],
    warnings: Vec<String>,
) -> Result<JointMap, BvhErrorKind> {
    let missing: Vec<&'static str> = (0..NUM_JOINTS)
        .filter(|&j| found[j].is_none())
        .map(|j| JOINT_NAMES[j])
        .collect();
    if !missing.is_empty() {
        let available = bvh
            .joints
            .iter()
            .filter(|j| !j.end_site)
            .map(|j| j.name.as_str())
            .collect::<Vec<_>>()
            .join(", ");
        return Err(BvhErrorKind::Unmapped { missing, available });
    }
    let sources = found.map(|s| s.expect("checked above"));
    let used: Vec<usize> = sources
        .iter()
        .flat_map(|s| match *s {
            JointSource::Joint(i) => vec![i],
            JointSource::Between { a, b, .. } => vec![a, b],
            JointSource::Lerp { .. } => vec![],
        })
        .collect();
    let unused = bvh
        .joints
        .iter()
        .enumerate()
        .filter(|(i, j)| !j.end_site && !used.contains(i))
        .map(|(_, j)| j.name.clone())
        .collect();
    Ok(JointMap {
        rig,
        sources,
        unused,
        warnings,
    })
}

/// The source of a table pick (`None` if a name is missing: [`rigs::RigTable::fits`]
/// checked them).
fn resolve(bvh: &Bvh, pick: Pick) -> Option<JointSource> {
    Some(match pick {
        Pick::Joint(a) => JointSource::Joint(rigs::find_joint(bvh, a)?),
        Pick::OneOf(names) => {
            JointSource::Joint(names.iter().find_map(|a| rigs::find_joint(bvh, a))?)
        }
        Pick::Between(a, b, t) => JointSource::Between {
            a: rigs::find_joint(bvh, a)?,
            b: rigs::find_joint(bvh, b)?,
            t,
        },
        Pick::End(a, t) => {
            let a = rigs::find_joint(bvh, a)?;
            JointSource::Between {
                a,
                b: rigs::end_site_of(bvh, a)?,
                t,
            }
        }
    })
}

/// Body-part words per HumanML3D joint, most specific first.
pub(crate) fn part_words(target: usize, smpl_style: bool) -> &'static [&'static str] {
    match target {
        0 => &["pelvis", "hips", "hip", "root"],
        1 | 2 => &["hip", "upleg", "upperleg", "thigh"],
        4 | 5 => &["knee", "lowerleg", "leg", "calf", "shin"],
        7 | 8 => &["ankle", "foot"],
        10 | 11 => &["toebase", "toes", "toe", "ball", "foot"],
        12 => &["neck"],
        15 => &["head"],
        // `shoulder` is the collar bone in CMU/Mixamo/Bandai rigs and the arm joint in
        // SMPL-style rigs, which name the collar `collar`/`clavicle`.
        13 | 14 if smpl_style => &["collar", "clavicle"],
        13 | 14 => &["shoulder", "clavicle"],
        16 | 17 if smpl_style => &["shoulder", "upperarm", "arm", "shldr"],
        16 | 17 => &["upperarm", "arm", "shldr"],
        18 | 19 => &["elbow", "forearm", "lowerarm"],
        20 | 21 => &["wrist", "hand"],
        _ => &[],
    }
}

fn side_of(target: usize) -> Option<Side> {
    match JOINT_NAMES[target] {
        n if n.starts_with("left_") => Some(Side::Left),
        n if n.starts_with("right_") => Some(Side::Right),
        _ => None,
    }
}

fn match_by_name(
    bvh: &Bvh,
    found: &mut [Option<JointSource>; NUM_JOINTS],
    warnings: &mut Vec<String>,
) {
    let parts: Vec<Option<NameParts>> = bvh
        .joints
        .iter()
        .map(|j| (!j.end_site).then(|| split_name(&j.name)))
        .collect();
    let smpl_style = parts
        .iter()
        .flatten()
        .any(|p| p.part == "collar" || p.part == "clavicle");
    let mut used = vec![false; bvh.joints.len()];
    // Ankles before toes so that `foot` goes to the ankle when there is no `ankle`.
    let order = [
        0, 12, 15, 1, 2, 4, 5, 7, 8, 10, 11, 13, 14, 16, 17, 18, 19, 20, 21,
    ];
    for target in order {
        let side = side_of(target);
        let hit = part_words(target, smpl_style).iter().find_map(|word| {
            (0..parts.len()).find(|&i| {
                !used[i]
                    && parts[i]
                        .as_ref()
                        .is_some_and(|p| p.side == side && p.part == *word)
            })
        });
        if let Some(i) = hit {
            used[i] = true;
            found[target] = Some(JointSource::Joint(i));
        }
    }
    if let Some(JointSource::Joint(p)) = found[0]
        && parts[p].as_ref().is_some_and(|n| n.part == "root")
    {
        warnings.push(format!(
            "pelvis taken from `{}` (no joint named hips/pelvis)",
            bvh.joints[p].name
        ));
    }
}

/// Cumulative rest length along HumanML3D's spine chain pelvis–spine1–spine2–spine3–neck.
const SPINE: [usize; 5] = [0, 3, 6, 9, 12];

fn spine_position(target: usize) -> f32 {
    let k = SPINE
        .iter()
        .position(|&j| j == target)
        .expect("spine joint");
    SPINE[1..=k].iter().map(|&j| BONE_LENGTHS[j]).sum()
}

/// Assigns spine1..3 from the source joints between pelvis and neck, interpolating the
/// ones the source lacks at HumanML3D's rest proportions.
fn fill_spine(
    bvh: &Bvh,
    found: &mut [Option<JointSource>; NUM_JOINTS],
    warnings: &mut Vec<String>,
) {
    let (Some(JointSource::Joint(pelvis)), Some(JointSource::Joint(neck))) = (found[0], found[12])
    else {
        return;
    };
    if found[3].is_none() && found[6].is_none() && found[9].is_none() {
        let chain = between(bvh, pelvis, neck);
        if chain.is_none() {
            warnings
                .push("neck is not below the pelvis in the hierarchy; spine interpolated".into());
        }
        let mut chain = chain.unwrap_or_default();
        // The chest is where the collars branch off; joints above it belong to the neck.
        if let Some(Some(JointSource::Joint(collar))) = found.get(13)
            && let Some(chest) = bvh.joints[*collar].parent
            && let Some(k) = chain.iter().position(|&j| j == chest)
        {
            chain.truncate(k + 1);
        }
        match chain.len() {
            0 => {}
            1 => found[9] = Some(JointSource::Joint(chain[0])),
            2 => {
                found[3] = Some(JointSource::Joint(chain[0]));
                found[9] = Some(JointSource::Joint(chain[1]));
            }
            n => {
                found[3] = Some(JointSource::Joint(chain[0]));
                found[6] = Some(JointSource::Joint(chain[(n - 1) / 2]));
                found[9] = Some(JointSource::Joint(chain[n - 1]));
            }
        }
    }
    for gap in [3, 6, 9] {
        if found[gap].is_some() {
            continue;
        }
        let k = SPINE.iter().position(|&j| j == gap).expect("spine joint");
        let below = SPINE[..k]
            .iter()
            .rev()
            .find(|&&j| matches!(found[j], Some(JointSource::Joint(_))))
            .copied()
            .unwrap_or(0);
        let above = SPINE[k + 1..]
            .iter()
            .find(|&&j| matches!(found[j], Some(JointSource::Joint(_))))
            .copied()
            .unwrap_or(12);
        let t = (spine_position(gap) - spine_position(below))
            / (spine_position(above) - spine_position(below));
        found[gap] = Some(JointSource::Lerp {
            from: below,
            to: above,
            t,
        });
    }
}

/// Joints strictly between `ancestor` and `descendant`, top-down; `None` if `ancestor`
/// is not an ancestor of `descendant`.
fn between(bvh: &Bvh, ancestor: usize, descendant: usize) -> Option<Vec<usize>> {
    let mut chain = Vec::new();
    let mut current = bvh.joints[descendant].parent;
    while let Some(j) = current {
        if j == ancestor {
            chain.reverse();
            return Some(chain);
        }
        chain.push(j);
        current = bvh.joints[j].parent;
    }
    None
}

/// Toes from the ankle's End Site; collars halfway between spine3 and the shoulder.
fn fill_extremities(
    bvh: &Bvh,
    found: &mut [Option<JointSource>; NUM_JOINTS],
    warnings: &mut Vec<String>,
) {
    for (toe, ankle) in [(10, 7), (11, 8)] {
        if found[toe].is_none()
            && let Some(JointSource::Joint(a)) = found[ankle]
            && let Some(end) = bvh
                .joints
                .iter()
                .position(|j| j.end_site && j.parent == Some(a))
        {
            found[toe] = Some(JointSource::Joint(end));
            warnings.push(format!(
                "{} taken from the End Site of `{}`",
                JOINT_NAMES[toe], bvh.joints[a].name
            ));
        }
    }
    for (collar, shoulder) in [(13, 16), (14, 17)] {
        if found[collar].is_none() && found[shoulder].is_some() && found[9].is_some() {
            found[collar] = Some(JointSource::Lerp {
                from: 9,
                to: shoulder,
                t: 0.5,
            });
            warnings.push(format!(
                "{} placed halfway between spine3 and {}",
                JOINT_NAMES[collar], JOINT_NAMES[shoulder]
            ));
        }
    }
}
