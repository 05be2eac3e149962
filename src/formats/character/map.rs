//! Which rig joint is which HumanML3D joint.
//!
//! In: the rig's joints and the mapping file's entries. Out: for every HumanML3D joint the
//! rig joint at its place, if any (End Sites allowed: a foot's End Site can stand for the
//! toes). The automatic part is the BVH importer's ([`crate::formats::bvh::retarget::map_partial`]:
//! mprog's own names, the rig tables of [`crate::formats::bvh::rigs`], then name matching for
//! Mixamo, SMPL, Biped, Blender `.L/.R` …); only joints it maps to one rig joint count
//! (a joint it places between two is left to the rest pose). Mapping-file entries win.
//!
//! Checked here: the joints a body needs to move ([`REQUIRED`] and one spine joint) are
//! present, else an error listing each missing joint with the rig joints whose names come
//! closest; and every mapped joint hangs below the joint mapped to its HumanML3D parent.

use super::error::{Missing, RigError, RigErrorKind};
use super::usermap::{MapEntry, edit_distance};
use crate::formats::bvh::names::split_name;
use crate::formats::bvh::retarget::{JointSource, map_partial, part_words};
use crate::formats::bvh::{Bvh, BvhJoint};
use crate::skeleton::{JOINT_NAMES, NUM_JOINTS, PARENTS};

/// Joints every rig needs: pelvis, legs down to the ankles, arms down to the wrists.
pub const REQUIRED: [usize; 13] = [0, 1, 2, 4, 5, 7, 8, 16, 17, 18, 19, 20, 21];

/// Spine joints, bottom to top; a rig needs at least one.
pub const SPINE: [usize; 4] = [3, 6, 9, 12];

/// The correspondence and how it was found.
#[derive(Clone, Debug, PartialEq)]
pub struct Correspondence {
    /// Rig joint of each HumanML3D joint.
    pub map: [Option<usize>; NUM_JOINTS],
    /// `name-matched`, a rig table's name, … plus ` and the mapping file`.
    pub mapped_by: String,
    /// What was guessed.
    pub notes: Vec<String>,
}

/// Maps the rig; `origin` names the rig in errors.
pub fn correspond(
    origin: &str,
    joints: &[BvhJoint],
    user: &[MapEntry],
) -> Result<Correspondence, RigError> {
    let bvh = Bvh {
        joints: joints.to_vec(),
        channel_count: 0,
        frame_time: 1.0,
        frame_count: 0,
        values: Vec::new(),
    };
    let partial = map_partial(&bvh);
    let mut map: [Option<usize>; NUM_JOINTS] = partial.found.map(|s| match s {
        Some(JointSource::Joint(i)) => Some(i),
        _ => None,
    });
    for e in user {
        for m in map.iter_mut() {
            if *m == Some(e.rig_joint) {
                *m = None;
            }
        }
        map[e.joint] = Some(e.rig_joint);
    }
    let mut mapped_by = partial.rig.to_string();
    if !user.is_empty() {
        mapped_by.push_str(" and the mapping file");
    }
    let spine_missing = SPINE.iter().all(|&j| map[j].is_none());
    let missing: Vec<usize> = REQUIRED
        .iter()
        .copied()
        .filter(|&j| map[j].is_none())
        .chain(spine_missing.then_some(9))
        .collect();
    if !missing.is_empty() {
        let mut raw: Vec<glam::Vec3> = Vec::with_capacity(joints.len());
        for j in joints {
            raw.push(j.parent.map_or(j.offset, |p| raw[p] + j.offset));
        }
        let guesses = super::guess::guess(joints, &raw, &map);
        let missing = missing
            .into_iter()
            .map(|j| {
                let mut candidates: Vec<(String, usize)> = guesses[j]
                    .map(|i| (joints[i].name.clone(), joints[i].line))
                    .into_iter()
                    .collect();
                for c in candidates_by_name(joints, &map, j) {
                    if candidates.len() < 3 && !candidates.contains(&c) {
                        candidates.push(c);
                    }
                }
                Missing {
                    joint: JOINT_NAMES[j],
                    candidates,
                }
            })
            .collect();
        return Err(RigError::whole(
            origin,
            RigErrorKind::Missing { missing, mapped_by },
        ));
    }
    check_hierarchy(origin, joints, &map)?;
    Ok(Correspondence {
        map,
        mapped_by,
        notes: partial.warnings,
    })
}

/// Up to three unmapped rig joints on the joint's side whose names come close to a word
/// for it (`upleg`, `thigh`, … for a hip).
fn candidates_by_name(
    joints: &[BvhJoint],
    map: &[Option<usize>; NUM_JOINTS],
    target: usize,
) -> Vec<(String, usize)> {
    let side = split_name(JOINT_NAMES[target]).side;
    let mut words: Vec<&str> = part_words(target, false).to_vec();
    words.extend(part_words(target, true));
    words.extend(
        JOINT_NAMES[target]
            .split('_')
            .filter(|w| *w != "left" && *w != "right"),
    );
    let mut scored: Vec<(usize, usize)> = joints
        .iter()
        .enumerate()
        .filter(|(i, j)| !j.end_site && !map.contains(&Some(*i)))
        .filter_map(|(i, j)| {
            let parts = split_name(&j.name);
            if parts.side != side {
                return None;
            }
            let d = words
                .iter()
                .map(|w| edit_distance(&parts.part, w))
                .min()
                .unwrap_or(usize::MAX);
            // A name containing the word (`LegUpper` for `leg`) counts as close.
            let d = if words.iter().any(|w| parts.part.contains(w)) {
                d.min(1)
            } else {
                d
            };
            (d <= 2).then_some((d, i))
        })
        .collect();
    scored.sort();
    scored
        .into_iter()
        .take(3)
        .map(|(_, i)| (joints[i].name.clone(), joints[i].line))
        .collect()
}

/// Every mapped joint must hang below the joint mapped to its nearest mapped HumanML3D
/// ancestor (so turning that one carries it).
fn check_hierarchy(
    origin: &str,
    joints: &[BvhJoint],
    map: &[Option<usize>; NUM_JOINTS],
) -> Result<(), RigError> {
    for j in 1..NUM_JOINTS {
        let Some(rig) = map[j] else { continue };
        let mut a = PARENTS[j];
        while map[a].is_none() {
            a = PARENTS[a];
        }
        let above = map[a].expect("the loop stops at a mapped joint");
        if !is_ancestor(joints, above, rig) {
            return Err(RigError::at(
                origin,
                joints[rig].line,
                RigErrorKind::NotBelow {
                    joint: JOINT_NAMES[j],
                    rig_joint: joints[rig].name.clone(),
                    above: JOINT_NAMES[a],
                    above_rig: joints[above].name.clone(),
                },
            ));
        }
    }
    Ok(())
}

/// True when `a` is a strict ancestor of `d`.
pub fn is_ancestor(joints: &[BvhJoint], a: usize, d: usize) -> bool {
    let mut p = joints[d].parent;
    while let Some(i) = p {
        if i == a {
            return true;
        }
        p = joints[i].parent;
    }
    false
}
