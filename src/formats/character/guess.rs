//! Suggestions for joints a rig's names do not give away, from its shape: the chains that
//! hang from the pelvis and go down are legs (hip, knee, ankle, toes), the chains that leave
//! the chest sideways are arms (collar if the chain is long enough, shoulder, elbow,
//! wrist), the chain that leaves the pelvis upwards is the spine; the body's left is where
//! the left shoulder or left-named joints are, else +X.
//!
//! Only suggestions: an error names them (and the mapping-file lines that would use them);
//! mprog never maps a joint by shape alone.

use crate::formats::bvh::BvhJoint;
use crate::formats::bvh::names::{Side, split_name};
use crate::skeleton::NUM_JOINTS;
use glam::Vec3;

/// A guess for every HumanML3D joint `map` lacks (None where the shape says nothing).
pub fn guess(
    joints: &[BvhJoint],
    raw: &[Vec3],
    map: &[Option<usize>; NUM_JOINTS],
) -> [Option<usize>; NUM_JOINTS] {
    let mut out = [None; NUM_JOINTS];
    let Some(pelvis) = map[0].or_else(|| joints.iter().position(|j| j.parent.is_none())) else {
        return out;
    };
    if map[0].is_none() {
        out[0] = Some(pelvis);
    }
    let children = children(joints);
    let up = up_axis(raw);
    let left = left_direction(joints, raw, map, up);
    let taken = |i: usize, out: &[Option<usize>; NUM_JOINTS]| {
        map.contains(&Some(i)) || out.contains(&Some(i))
    };
    // Legs: children of the pelvis whose subtree reaches well below it.
    for (side_sign, chain) in [(1.0, [1, 4, 7, 10]), (-1.0, [2, 5, 8, 11])] {
        let start = children[pelvis]
            .iter()
            .copied()
            .filter(|&c| !taken(c, &out) && !joints[c].end_site)
            .filter(|&c| lowest(&children, raw, c, up) < raw[pelvis].dot(up) - 0.3 * size(raw, up))
            .find(|&c| (raw[c] - raw[pelvis]).dot(left) * side_sign > 0.0);
        if let Some(c) = start {
            fill_chain(&mut out, map, &children, joints, c, &chain);
        }
    }
    // The spine: the pelvis's child that goes up; the chest is where the arms branch.
    let spine_start = children[pelvis]
        .iter()
        .copied()
        .filter(|&c| !taken(c, &out) && !joints[c].end_site)
        .max_by(|&a, &b| raw[a].dot(up).total_cmp(&raw[b].dot(up)));
    if map[3].is_none()
        && map[6].is_none()
        && map[9].is_none()
        && map[12].is_none()
        && let Some(s) = spine_start
        && farthest(&children, raw, s).dot(up) > raw[pelvis].dot(up)
    {
        // The chest: where the spine branches.
        out[9] = Some(branching_above(&children, s));
    }
    // Arms: from the highest branching joint of the spine, the chains going sideways.
    let chest = [9, 6, 3, 12]
        .iter()
        .find_map(|&j| map[j].or(out[j]))
        .map(|c| branching_above(&children, c));
    if let Some(chest) = chest {
        for (side_sign, chain) in [(1.0, [13, 16, 18, 20]), (-1.0, [14, 17, 19, 21])] {
            let start = children[chest]
                .iter()
                .copied()
                .filter(|&c| !taken(c, &out) && !joints[c].end_site)
                .find(|&c| {
                    let reach = farthest(&children, raw, c) - raw[chest];
                    reach.dot(left) * side_sign > 0.3 * size(raw, up)
                });
            if let Some(c) = start {
                let long = chain_joints(&children, joints, c).len() >= 4;
                let chain: &[usize] = if long { &chain } else { &chain[1..] };
                fill_chain(&mut out, map, &children, joints, c, chain);
            }
        }
    }
    out
}

fn children(joints: &[BvhJoint]) -> Vec<Vec<usize>> {
    let mut c = vec![Vec::new(); joints.len()];
    for (i, j) in joints.iter().enumerate() {
        if let Some(p) = j.parent {
            c[p].push(i);
        }
    }
    c
}

/// Extent of the rig along `axis`.
fn extent(raw: &[Vec3], axis: Vec3) -> f32 {
    let (lo, hi) = raw.iter().fold((f32::MAX, f32::MIN), |(lo, hi), p| {
        (lo.min(p.dot(axis)), hi.max(p.dot(axis)))
    });
    (hi - lo).max(1e-6)
}

/// Y or Z, whichever the rig is taller along (a T-pose is as wide as it is tall, but
/// never deep).
fn up_axis(raw: &[Vec3]) -> Vec3 {
    if extent(raw, Vec3::Z) > extent(raw, Vec3::Y) {
        Vec3::Z
    } else {
        Vec3::Y
    }
}

/// Height of the rig (for thresholds).
fn size(raw: &[Vec3], up: Vec3) -> f32 {
    extent(raw, up)
}

/// The rig's left: from the shoulders if mapped, else from left/right names, else +X.
fn left_direction(
    joints: &[BvhJoint],
    raw: &[Vec3],
    map: &[Option<usize>; NUM_JOINTS],
    up: Vec3,
) -> Vec3 {
    if let (Some(l), Some(r)) = (map[16], map[17]) {
        return (raw[l] - raw[r]).normalize_or(Vec3::X);
    }
    let mut sum = Vec3::ZERO;
    for (i, j) in joints.iter().enumerate() {
        match split_name(&j.name).side {
            Some(Side::Left) => sum += raw[i],
            Some(Side::Right) => sum -= raw[i],
            None => {}
        }
    }
    (sum - up * sum.dot(up)).normalize_or(Vec3::X)
}

/// Lowest height in the subtree of `i`.
fn lowest(children: &[Vec<usize>], raw: &[Vec3], i: usize, up: Vec3) -> f32 {
    let mut low = raw[i].dot(up);
    let mut stack = vec![i];
    while let Some(k) = stack.pop() {
        low = low.min(raw[k].dot(up));
        stack.extend(&children[k]);
    }
    low
}

/// The point of the subtree of `i` farthest from `i`.
fn farthest(children: &[Vec<usize>], raw: &[Vec3], i: usize) -> Vec3 {
    let mut best = raw[i];
    let mut stack = vec![i];
    while let Some(k) = stack.pop() {
        if raw[k].distance(raw[i]) > best.distance(raw[i]) {
            best = raw[k];
        }
        stack.extend(&children[k]);
    }
    best
}

/// Follows single children up from `i` to the first joint with several.
fn branching_above(children: &[Vec<usize>], mut i: usize) -> usize {
    while children[i].len() == 1 {
        i = children[i][0];
    }
    i
}

/// The chain from `i` down its largest subtrees (End Sites excluded).
fn chain_joints(children: &[Vec<usize>], joints: &[BvhJoint], mut i: usize) -> Vec<usize> {
    let count = |c: usize| {
        let mut n = 0;
        let mut stack = vec![c];
        while let Some(k) = stack.pop() {
            n += 1;
            stack.extend(&children[k]);
        }
        n
    };
    let mut out = vec![i];
    loop {
        let next = children[i]
            .iter()
            .copied()
            .filter(|&c| !joints[c].end_site)
            .max_by_key(|&c| count(c));
        match next {
            Some(c) => {
                out.push(c);
                i = c;
            }
            None => return out,
        }
    }
}

/// Puts the chain from `start` on the HumanML3D joints `chain`, where `map` has none.
fn fill_chain(
    out: &mut [Option<usize>; NUM_JOINTS],
    map: &[Option<usize>; NUM_JOINTS],
    children: &[Vec<usize>],
    joints: &[BvhJoint],
    start: usize,
    chain: &[usize],
) {
    for (&j, i) in chain.iter().zip(chain_joints(children, joints, start)) {
        if map[j].is_none() {
            out[j] = Some(i);
        }
    }
}
