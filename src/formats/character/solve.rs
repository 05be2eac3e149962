//! Putting a motion on the rig: in, joint positions (metres, Y up); out, a [`Posed`] of the
//! rig's joints (local rotations per frame, the mover's translation).
//!
//! 1. **Scale.** The motion is scaled about the origin by the ratio of leg lengths (rig over
//!    motion, hip–knee–ankle, mean of both legs; the motion's over all frames). The floor
//!    stays at y = 0, the path and heights scale with the legs.
//! 2. **Pelvis.** Its rotation is the best fit ([`fit::best_rotation`]) of its rest vectors
//!    to the hips and spine onto the motion's; it is placed so that the midpoint of the rig's
//!    hips lies on the (scaled) midpoint of the motion's.
//! 3. **Down the hierarchy**, parents first: a joint with one target turns by the smallest
//!    rotation taking its rest vector (as its parent now carries it) to the motion's bone
//!    direction, so no twist is added; a joint with several (the chest) takes their best fit;
//!    a joint with none keeps its rest pose relative to its parent.
//! 4. **Legs.** The thigh and shin are solved by two-bone IK ([`fit::knee_position`]) so that
//!    each ankle lands on the motion's ankle, the knee bending the way the motion's does:
//!    feet stay on the floor and planted feet stay planted whatever the rig's proportions.
//!
//! The rest pose may be a T-pose, an A-pose or anything else: only directions from the
//! rest pose are used, never rest angles.

use super::Character;
use super::fit;
use crate::features::kinematics;
use crate::formats::posed::{Posed, PosedJoint};
use crate::formats::rig;
use crate::motion::Motion;
use crate::skeleton::NUM_JOINTS;
use glam::{DQuat, DVec3};

/// Leg length of the motion (m): hip–knee–ankle, mean of both legs and all frames.
pub fn motion_leg(poses: &[kinematics::Pose64]) -> f64 {
    let l = rig::mean_bone_lengths(poses);
    0.5 * (l[4] + l[7] + l[5] + l[8])
}

/// `m` on the rig of `ch` (see the module docs).
pub fn retarget(ch: &Character, m: &Motion) -> Result<Posed, String> {
    if m.is_empty() {
        return Err("the motion has no frames".into());
    }
    let poses = kinematics::poses_f64(m).map_err(|e| e.to_string())?;
    let leg = motion_leg(&poses);
    if !(leg.is_finite() && leg > 1e-6) {
        return Err("the motion's legs have no length".into());
    }
    let scale = ch.leg / leg;
    let mut rotations = Vec::with_capacity(poses.len());
    let mut translations = Vec::with_capacity(poses.len());
    for pose in &poses {
        let target: [DVec3; NUM_JOINTS] = pose.map(|p| p * scale);
        let (r, t) = frame(ch, &target);
        rotations.push(r);
        translations.push(t);
    }
    crate::formats::posed::keep_hemisphere(&mut rotations);
    let joints = ch
        .joints
        .iter()
        .enumerate()
        .map(|(i, j)| PosedJoint {
            name: j.name.clone(),
            parent: j.parent,
            offset: ch.offsets[i],
            end_site: j.end_site,
            body: ch.plan.joint_of[i],
        })
        .collect();
    Ok(Posed {
        joints,
        fps: m.fps,
        rotations,
        mover: ch.plan.mover,
        translations,
        size: ch.leg / crate::formats::bvh::units::TYPICAL_LEG as f64,
    })
}

/// One frame: every joint's local rotation and the mover's translation.
fn frame(ch: &Character, t: &[DVec3; NUM_JOINTS]) -> (Vec<DQuat>, DVec3) {
    let plan = &ch.plan;
    let n = ch.joints.len();
    let (pelvis, mover) = (plan.pelvis, plan.mover);
    // The pelvis's ancestors keep their rest pose, so its rotation is its global one.
    let pelvis_rot = aim(ch, pelvis, DQuat::IDENTITY, t);
    let [left, right] = plan.legs;
    let rest_mid = 0.5 * (ch.rest[left.hip] + ch.rest[right.hip]) - ch.rest[pelvis];
    let pelvis_at = 0.5 * (t[1] + t[2]) - pelvis_rot * rest_mid;
    let translation = ch.offsets[mover] + (pelvis_at - ch.rest[pelvis]);

    let mut pos = vec![DVec3::ZERO; n];
    let mut rot = vec![DQuat::IDENTITY; n];
    let mut local = vec![DQuat::IDENTITY; n];
    for i in 0..n {
        let parent = ch.joints[i].parent;
        let base = parent.map_or(DQuat::IDENTITY, |p| rot[p]);
        let offset = if i == mover {
            translation
        } else {
            ch.offsets[i]
        };
        pos[i] = parent.map_or(offset, |p| pos[p] + base * offset);
        if ch.joints[i].end_site || plan.euler[i].is_none() {
            rot[i] = base;
            continue;
        }
        let global = if i == pelvis {
            pelvis_rot
        } else if let Some(side) = plan.legs.iter().position(|l| l.hip == i) {
            let (hip, knee, ankle) = if side == 0 { (1, 4, 7) } else { (2, 5, 8) };
            let leg = plan.legs[side];
            let knee_at = fit::knee_position(
                pos[i],
                t[ankle],
                pole(t, hip, knee, ankle, leg.thigh),
                leg.thigh,
                leg.shin,
            );
            let rest = base * (ch.rest[leg.knee] - ch.rest[i]);
            kinematics::rotation_between(rest, knee_at - pos[i]) * base
        } else if let Some(side) = plan.legs.iter().position(|l| l.knee == i) {
            let ankle = if side == 0 { 7 } else { 8 };
            let rest = base * (ch.rest[plan.legs[side].ankle] - ch.rest[i]);
            kinematics::rotation_between(rest, t[ankle] - pos[i]) * base
        } else {
            aim(ch, i, base, t)
        };
        rot[i] = global;
        local[i] = (base.inverse() * global).normalize();
    }
    (local, translation)
}

/// The global rotation of joint `i`, whose parent's is `base`, that points its rest vectors
/// to its targets along the motion's bones.
fn aim(ch: &Character, i: usize, base: DQuat, t: &[DVec3; NUM_JOINTS]) -> DQuat {
    let targets = &ch.plan.targets[i];
    let Some(from) = ch.plan.joint_of[i] else {
        return base;
    };
    let pairs: Vec<(DVec3, DVec3)> = targets
        .iter()
        .map(|&(d, k)| (ch.rest[d] - ch.rest[i], t[k] - t[from]))
        .collect();
    if pairs.len() > 1
        && let Some(q) = fit::best_rotation(&pairs)
    {
        return q;
    }
    match pairs.first() {
        Some(&(rest, now)) => kinematics::rotation_between(base * rest, now) * base,
        None => base,
    }
}

/// Which way the knee bends: the motion knee's offset from its hip–ankle line, with a
/// small forward lean so a straight leg still bends forward.
fn pole(t: &[DVec3; NUM_JOINTS], hip: usize, knee: usize, ankle: usize, thigh: f64) -> DVec3 {
    let line = (t[ankle] - t[hip]).try_normalize().unwrap_or(DVec3::NEG_Y);
    let k = t[knee] - t[hip];
    let across = k - line * k.dot(line);
    let forward = (t[1] - t[2])
        .cross(DVec3::Y)
        .try_normalize()
        .unwrap_or(DVec3::Z);
    across + forward * (0.01 * thigh)
}
