//! PMG's HSI-1 the way its Table 1 evaluates it (`eval_task_hsi1_config.py`): a held-out
//! test clip gives the prompt (its caption), the length and the targets (its head heights
//! on the first, central and last frames, t = 0, L//2, L−1). Every goal is then a pose the
//! data has, so the task measures the solver, not the data's range; the program
//! `programs/hsi1_head_height.mprog` asks for a squat, which this data never shows.
//!
//! The goal is an ordinary program, written out per clip: each keyframe's statement is
//! `head.y == h` (error |head y − h| in metres), so the total is the sum of the three
//! absolute errors (PMG's C.Err, a mean absolute error, is a third of it) and the
//! unsuccess rate counts any keyframe more than 5 cm off.

use super::suite::{Family, Goal, Task};
use crate::dataset::{ClipInfo, Dataset, FEATURE_DIM, Split};
use crate::features::recover_from_ric;
use crate::lang::check::MODEL_MAX_FRAMES;

/// The head joint (HumanML3D index).
const HEAD: usize = 15;

/// Shortest clip used: PMG's lengths start at 40 frames (2 s).
const MIN_FRAMES: usize = 40;

/// The keyframes PMG constrains in a motion of `frames` frames.
pub fn keyframes(frames: usize) -> [usize; 3] {
    [0, frames / 2, frames - 1]
}

/// A caption as a program string: only letters, digits, spaces and plain punctuation
/// survive (a quote or backslash would end or escape the literal).
fn prompt_text(caption: &str) -> String {
    caption
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || " ,.'-!?".contains(c) {
                c
            } else {
                ' '
            }
        })
        .collect::<String>()
        .trim()
        .to_string()
}

/// The program of one clip: its caption, its length, its three head heights (m).
pub fn program_source(name: &str, caption: &str, frames: usize, heights: [f32; 3]) -> String {
    let [a, b, c] = keyframes(frames);
    format!(
        "# PMG HSI-1 on test clip {}: head heights of its frames {a}, {b}, {c}.\n\
         prompt \"{}\"\n\
         length {frames} frames\n\
         at {a} {{ head.y == {:.4} m }}\n\
         at {b} {{ head.y == {:.4} m }}\n\
         at {c} {{ head.y == {:.4} m }}\n",
        prompt_text(name),
        prompt_text(caption),
        heights[0],
        heights[1],
        heights[2]
    )
}

/// Test clips for the task: not mirrored, captioned, 40–196 frames, spread evenly over the
/// split's name order so different actions come up.
pub fn clips(data: &Dataset, count: usize) -> Vec<&ClipInfo> {
    let mut eligible: Vec<&ClipInfo> = data
        .clips(Split::Test)
        .filter(|c| {
            !c.mirrored
                && !c.captions.is_empty()
                && (MIN_FRAMES..=MODEL_MAX_FRAMES).contains(&c.frames)
        })
        .collect();
    eligible.sort_by(|a, b| a.name.cmp(&b.name));
    let k = count.min(eligible.len());
    (0..k).map(|i| eligible[i * eligible.len() / k]).collect()
}

/// One task per chosen test clip, `samples` samples each.
pub fn suite(data: &Dataset, count: usize, samples: usize) -> Result<Vec<Task>, String> {
    clips(data, count)
        .into_iter()
        .map(|clip| {
            let features = &data.clip_features(clip)[..clip.frames * FEATURE_DIM];
            let motion = recover_from_ric(features).map_err(|e| format!("{}: {e}", clip.name))?;
            let flat = motion.to_flat();
            let height = |t: usize| flat[(t * 22 + HEAD) * 3 + 1];
            let [a, b, c] = keyframes(clip.frames);
            let source = program_source(
                &clip.name,
                &clip.captions[0],
                clip.frames,
                [height(a), height(b), height(c)],
            );
            let program = crate::lang::compile(&source, &clip.name, &[]).map_err(|d| {
                format!(
                    "head-height task of {} does not compile:\n{}",
                    clip.name,
                    d.render_plain()
                )
            })?;
            Ok(Task {
                family: Family::HeadHeight,
                name: clip.name.clone(),
                prompts: vec![prompt_text(&clip.captions[0])],
                frames: clip.frames,
                samples,
                goal: Goal::Program(Box::new(program)),
            })
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use burn::prelude::*;

    #[test]
    fn keyframes_are_pmgs() {
        assert_eq!(keyframes(100), [0, 50, 99]);
        assert_eq!(keyframes(41), [0, 20, 40]);
    }

    #[test]
    fn captions_cannot_break_out_of_the_string() {
        let src = program_source(
            "clip",
            "a man \"walks\" \\ away\nlength 3 frames",
            60,
            [1.5, 1.2, 1.5],
        );
        assert!(src.contains("prompt \"a man  walks    away length 3 frames\""));
        assert!(crate::lang::compile(&src, "clip", &[]).is_ok());
    }

    /// A motion whose head is at 1.6 m on every frame but 1.0 m on the central one misses
    /// only the central target, by its distance, in metres.
    #[test]
    fn error_is_the_sum_of_absolute_height_errors() {
        let n = 60;
        let src = program_source("clip", "a person bows", n, [1.6, 1.0, 1.6]);
        let program = crate::lang::compile(&src, "clip", &[]).expect("compiles");
        let device = Default::default();
        let mut flat = vec![0.0f32; n * 22 * 3];
        for t in 0..n {
            for j in 0..22 {
                flat[(t * 22 + j) * 3 + 1] = if t == n / 2 { 1.25 } else { 1.6 };
            }
        }
        let joints = Tensor::<5>::from_data(TensorData::new(flat, [1, 1, n, 22, 3]), &device);
        let e = program.evaluate(joints);
        let total = e.total.into_data().try_into_vec::<f32>().unwrap()[0];
        let per = e.per_statement.into_data().try_into_vec::<f32>().unwrap();
        assert!((total - 0.25).abs() < 1e-4, "{total}");
        assert!(per[0].abs() < 1e-5 && (per[1] - 0.25).abs() < 1e-4 && per[2].abs() < 1e-5);
    }
}
