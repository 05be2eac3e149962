//! A dip the prompt does not ask for: a person told to walk or run whose pelvis sinks far
//! below its own walking height. Guidance met a path by bending the knees late (a walk in
//! a circle dipped from 0.78 m to 0.41 m at 3.2 s, "plausible" by every other check): a
//! planted foot held in place while the pelvis is pulled away can only be reached lower.
//!
//! Real walking and running clips of `data/combined` whose captions name nothing low
//! (2,272 clips): the pelvis stays within 0.09 m of its median height on 95 % of them and
//! within 0.11 m on 99 %; [`CROUCH_DROP`] is about twice that.

use super::plausibility::{GAP, Kind, Problem, runs};
use crate::motion::Motion;

/// How far (m) below its median height the pelvis may sink in a walk or run.
pub const CROUCH_DROP: f32 = 0.2;

/// Frames the pelvis must stay that low to be flagged (0.15 s).
pub const CROUCH_FRAMES: usize = 3;

/// Words of a travelling prompt.
const TRAVEL: &[&str] = &[
    "walk", "run", "jog", "stroll", "hurr", "dash", "sprint", "march", "stride", "pace",
];

/// Word starts of a prompt that asks for the body low (no crouch check then); the
/// leading space keeps "slowly" from reading as "low" and "stroll" as "roll".
const LOW: &[&str] = &[
    " crouch",
    " squat",
    " sit",
    " lie",
    " lies",
    " lying",
    " lay",
    " kneel",
    " bend",
    " bends",
    " pick",
    " crawl",
    " duck",
    " get up",
    " gets up",
    " fall",
    " roll",
    " flip",
    " cartwheel",
    " dive",
    " climb",
    " lower",
    " ground",
    " floor",
    " slip",
    " stumble",
    " jump",
    " leap",
    " hop",
    " danc",
    " ballet",
    " handstand",
    " bow",
    " sneak",
    " low",
    " tiptoe",
    " creep",
    " limp",
    " stoop",
    " reach down",
    " lean",
    " grab",
    " kick",
    " dribble",
    " tie",
    " push",
    " pull",
];

/// Whether `prompt` asks for walking or running and nothing low.
pub fn prompt_forbids_crouch(prompt: &str) -> bool {
    let p = format!(" {}", prompt.to_lowercase());
    TRAVEL.iter().any(|w| p.contains(w)) && !LOW.iter().any(|w| p.contains(w))
}

/// Per person (their prompts: the whole-motion one and every timeline span's): whether the
/// solver keeps them upright (every prompt asks for walking or running and nothing low)
/// and whether it also steers them to face along their path (upright, and no prompt asks
/// for walking backwards or sideways); neither when `free`. Facing alone, without the
/// upright term, lowered a walk's pelvis (0.57 m against 0.75 m on a walk-then-wave
/// timeline), so it is only given with it. Feeds
/// [`crate::solve::facing::FacingAlongPath`].
pub fn prompt_steering(prompts: &[Vec<&str>], free: bool) -> Vec<(bool, bool)> {
    prompts
        .iter()
        .map(|texts| {
            let allows = texts
                .iter()
                .any(|t| super::plausibility::prompt_allows_facing(t));
            let upright = !texts.is_empty() && texts.iter().all(|t| prompt_forbids_crouch(t));
            (!free && upright && !allows, !free && upright)
        })
        .collect()
}

/// Frames where the pelvis is more than [`CROUCH_DROP`] below its median height, for at
/// least [`CROUCH_FRAMES`] frames.
pub fn crouch_check(m: &Motion, out: &mut Vec<Problem>) {
    let n = m.len();
    if n < CROUCH_FRAMES {
        return;
    }
    let mut heights: Vec<f32> = m.frames.iter().map(|f| f[0].y).collect();
    let y = heights.clone();
    heights.sort_by(f32::total_cmp);
    let median = heights[n / 2];
    let low: Vec<bool> = y.iter().map(|&h| median - h > CROUCH_DROP).collect();
    for (a, b) in runs(&low, GAP) {
        if b + 1 - a < CROUCH_FRAMES {
            continue;
        }
        let lowest = y[a..=b].iter().copied().fold(f32::INFINITY, f32::min);
        out.push(Problem {
            person: 0,
            kind: Kind::Crouch,
            part: "pelvis".into(),
            joint: Some("pelvis".into()),
            frames: [a, b],
            seconds: [0.0, 0.0],
            value: median - lowest,
            limit: CROUCH_DROP,
            unit: format!("m below its median height {median:.2} m"),
            against:
                "real walks and runs: within 0.11 m on 99 % of clips; the prompt asks for no crouch"
                    .into(),
            statements: Vec::new(),
        });
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::skeleton::NUM_JOINTS;
    use glam::Vec3;

    fn walk_with_pelvis(y: impl Fn(usize) -> f32) -> Motion {
        let frames = (0..60)
            .map(|t| {
                let mut f = [Vec3::ZERO; NUM_JOINTS];
                f[0] = Vec3::new(0.0, y(t), t as f32 * 0.06);
                f
            })
            .collect();
        Motion::new(frames)
    }

    #[test]
    fn a_dip_in_a_walk_is_flagged_and_a_gait_bob_is_not() {
        let mut out = Vec::new();
        crouch_check(
            &walk_with_pelvis(|t| 0.9 + 0.03 * (t as f32).sin()),
            &mut out,
        );
        assert!(out.is_empty(), "{out:?}");
        crouch_check(
            &walk_with_pelvis(|t| if (30..36).contains(&t) { 0.45 } else { 0.9 }),
            &mut out,
        );
        assert_eq!(out.len(), 1);
        assert_eq!(out[0].frames, [30, 35]);
        assert!((out[0].value - 0.45).abs() < 1e-5);
        // One frame low is a glitch other checks see (acceleration), not a crouch.
        let mut one = Vec::new();
        crouch_check(
            &walk_with_pelvis(|t| if t == 30 { 0.4 } else { 0.9 }),
            &mut one,
        );
        assert!(one.is_empty());
    }

    #[test]
    fn steering_follows_every_prompt_of_a_person() {
        let people = vec![
            vec!["a person walks in a circle to the right"],
            vec!["a person walks forward", "a person walks backwards"],
            vec!["a person walks forward", "a person sits down"],
        ];
        assert_eq!(
            prompt_steering(&people, false),
            vec![(true, true), (false, true), (false, false)]
        );
        assert!(
            prompt_steering(&people, true)
                .iter()
                .all(|&s| s == (false, false))
        );
    }

    #[test]
    fn only_walking_prompts_forbid_it() {
        assert!(prompt_forbids_crouch(
            "a person walks in a circle to the right"
        ));
        assert!(prompt_forbids_crouch("A man runs forward"));
        assert!(!prompt_forbids_crouch("a person walks and then sits down"));
        assert!(!prompt_forbids_crouch("a person squats"));
        assert!(!prompt_forbids_crouch("a person waves"));
        assert!(!prompt_forbids_crouch(
            "a person walks and picks something up"
        ));
        assert!(prompt_forbids_crouch("a person walks slowly"));
        assert!(prompt_forbids_crouch("someone strolls"));
    }
}
