//! What a clip shows, from where it came: the source family is told by the file name.
//!
//! | source | file stem | captions from |
//! | --- | --- | --- |
//! | Bandai Namco | `dataset-2_walk_normal_001` | content and style labels ([`super::captions`]) |
//! | HDM05 | `HDM_bd_squat1Reps_001_120` | the class ([`super::captions_hdm05`]) |
//! | CMU | `01_01`, `127_38` | CMU's trial description ([`super::captions_cmu`]) |
//! | DeepMimic | `humanoid3d_spinkick` | the clip name ([`deepmimic_captions`]) |

use super::captions::{Labels, captions, mirror_content, parse_labels};
use super::captions_cmu::{TrialIndex, cmu_captions, cmu_trial};
use super::captions_hdm05::{hdm05_captions, hdm05_class};

/// Labels and captions of one clip.
#[derive(Clone, Debug, PartialEq)]
pub struct ClipText {
    /// Source family: `bandai`, `hdm05`, `cmu` or `deepmimic`.
    pub family: &'static str,
    /// Motion label (a Bandai label, or the first caption's action as a slug).
    pub content: String,
    /// Style label (`normal` outside Bandai).
    pub style: String,
    /// Several phrasings of what happens.
    pub captions: Vec<String>,
}

/// Everything outside a file's name that captions need.
#[derive(Clone, Debug, Default)]
pub struct LabelContext {
    /// CMU trial descriptions, when a `cmu_trial_index.csv` was found.
    pub cmu: Option<TrialIndex>,
}

/// Labels and captions for a file stem, or why there are none.
pub fn clip_text(stem: &str, ctx: &LabelContext) -> Result<ClipText, String> {
    if let Some(labels) = parse_labels(stem) {
        let caps = captions(&labels);
        if caps.is_empty() {
            return Err(format!(
                "no captions for the motion label `{}`",
                labels.content
            ));
        }
        return Ok(ClipText {
            family: "bandai",
            content: labels.content,
            style: labels.style,
            captions: caps,
        });
    }
    let (family, caps) = if let Some(class) = hdm05_class(stem) {
        let caps = hdm05_captions(class);
        if caps.is_empty() {
            return Err(format!("no captions for the HDM05 class `{class}`"));
        }
        ("hdm05", caps)
    } else if let Some(name) = stem.strip_prefix("humanoid3d_") {
        let caps = deepmimic_captions(name);
        if caps.is_empty() {
            return Err(format!("no captions for the DeepMimic clip `{name}`"));
        }
        ("deepmimic", caps)
    } else if let Some((subject, trial)) = cmu_trial(stem) {
        let Some(index) = &ctx.cmu else {
            return Err(
                "CMU trial without a description: no cmu_trial_index.csv under the input folder"
                    .into(),
            );
        };
        let Some(description) = index.get(&(subject, trial)) else {
            return Err(format!(
                "CMU trial {subject}_{trial} is not in cmu_trial_index.csv"
            ));
        };
        let caps = cmu_captions(description);
        if caps.is_empty() {
            return Err(format!(
                "CMU trial description `{description}` names no action"
            ));
        }
        ("cmu", caps)
    } else {
        return Err(format!(
            "file name `{stem}` is none of: Bandai `dataset-N_content_style_id`, HDM05 `HDM_actor_class_nnn`, CMU `SS_TT`, DeepMimic `humanoid3d_name`"
        ));
    };
    Ok(ClipText {
        family,
        content: slug(&caps[0]),
        style: "normal".into(),
        captions: caps,
    })
}

/// The clip's text after a left/right mirror: sides swapped in labels and captions.
pub fn mirrored(text: &ClipText) -> ClipText {
    if text.family == "bandai" {
        let labels = Labels {
            content: mirror_content(&text.content),
            style: text.style.clone(),
        };
        return ClipText {
            family: text.family,
            captions: captions(&labels),
            content: labels.content,
            style: labels.style,
        };
    }
    ClipText {
        family: text.family,
        content: mirror_content(&text.content),
        style: text.style.clone(),
        captions: text.captions.iter().map(|c| swap_sides(c)).collect(),
    }
}

/// `left` ↔ `right` as whole words.
fn swap_sides(text: &str) -> String {
    text.split(' ')
        .map(|w| match w {
            "left" => "right",
            "right" => "left",
            w => w,
        })
        .collect::<Vec<_>>()
        .join(" ")
}

/// `a person kicks forward with the left leg` → `kicks-forward-with-the-left-leg`.
fn slug(caption: &str) -> String {
    let action = caption.strip_prefix("a person ").unwrap_or(caption);
    action
        .split(|c: char| !c.is_ascii_alphanumeric())
        .filter(|w| !w.is_empty())
        .collect::<Vec<_>>()
        .join("-")
}

/// DeepMimic's clip names (its `data/motions/humanoid3d_*.txt`).
pub fn deepmimic_captions(name: &str) -> Vec<String> {
    let phrases: &[&str] = match name {
        "crawl" => &["crawls forward on hands and knees", "crawls on the floor"],
        "getup_facedown" => &[
            "gets up from lying face down on the floor",
            "stands up from lying on the stomach",
        ],
        "getup_faceup" => &[
            "gets up from lying on the back",
            "stands up from lying face up on the floor",
        ],
        "kick" => &["kicks forward", "does a high front kick"],
        "spinkick" => &["does a spinning kick", "spins around and kicks"],
        "roll" => &["rolls forward on the ground", "does a forward roll"],
        "backflip" => &["does a backflip", "flips backwards"],
        "cartwheel" => &["does a cartwheel"],
        "run" => &["runs forward", "jogs forward"],
        "run_jump" => &["runs and jumps", "runs forward and leaps"],
        "run_roll" => &["runs and rolls on the ground", "runs, dives and rolls"],
        "walk" => &["walks forward"],
        "jump" => &["jumps", "jumps up"],
        "dance_a" | "dance_b" => &["dances", "is dancing"],
        _ => &[],
    };
    phrases
        .iter()
        .zip(["a person", "someone"].iter().cycle())
        .map(|(p, s)| format!("{s} {p}"))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn families_by_name() {
        let ctx = LabelContext {
            cmu: Some([((2, 6), "bend over, scoop up, rise".to_string())].into()),
        };
        let t = clip_text("HDM_bd_kickLFront1Reps_003_120", &ctx).unwrap();
        assert_eq!(t.family, "hdm05");
        assert_eq!(t.content, "kicks-forward-with-the-left-leg");
        let m = mirrored(&t);
        assert_eq!(m.content, "kicks-forward-with-the-right-leg");
        assert!(m.captions[0].contains("right leg"), "{:?}", m.captions);
        let c = clip_text("02_06", &ctx).unwrap();
        assert_eq!(c.family, "cmu");
        assert!(c.captions[0].ends_with("and then stands back up"));
        assert!(clip_text("02_07", &ctx).unwrap_err().contains("not in"));
        assert!(
            clip_text("02_06", &LabelContext::default())
                .unwrap_err()
                .contains("cmu_trial_index.csv")
        );
        assert_eq!(
            clip_text("dataset-1_walk_normal_001", &ctx).unwrap().family,
            "bandai"
        );
        assert_eq!(
            clip_text("humanoid3d_getup_faceup", &ctx).unwrap().family,
            "deepmimic"
        );
        assert!(clip_text("random", &ctx).is_err());
    }
}
