//! Captions from the labels in Bandai Namco file names (`dataset-N_{content}_{style}_{id}`):
//! several phrasings per clip, so the text encoder learns words rather than label ids.

/// Content and style parsed from a file stem.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Labels {
    /// Motion label, e.g. `walk-turn-left`.
    pub content: String,
    /// Style label, e.g. `tired`.
    pub style: String,
}

/// Parses `dataset-2_walk-turn-left_elderly_003` into labels; None for other names.
pub fn parse_labels(stem: &str) -> Option<Labels> {
    let mut parts = stem.split('_');
    let dataset = parts.next()?;
    if !dataset.starts_with("dataset-") {
        return None;
    }
    let content = parts.next()?.to_string();
    let style = parts.next()?.to_string();
    parts.next()?; // id
    Some(Labels { content, style })
}

/// The content label of the left/right mirrored motion.
pub fn mirror_content(content: &str) -> String {
    let swapped: Vec<&str> = content
        .split('-')
        .map(|w| match w {
            "left" => "right",
            "right" => "left",
            w => w,
        })
        .collect();
    swapped.join("-")
}

/// Verb phrases for a motion label (third person singular).
fn actions(content: &str) -> Vec<&'static str> {
    match content {
        "walk" => vec![
            "walks forward",
            "walks straight ahead",
            "is walking forward",
        ],
        "run" => vec!["runs forward", "jogs forward", "is running"],
        "dash" => vec!["dashes forward", "sprints forward", "runs forward fast"],
        "walk-back" => vec!["walks backwards", "steps backwards", "walks back"],
        "walk-left" => vec![
            "walks to the left",
            "moves sideways to the left",
            "steps to the left",
        ],
        "walk-right" => vec![
            "walks to the right",
            "moves sideways to the right",
            "steps to the right",
        ],
        "walk-turn-left" => vec![
            "walks and turns left",
            "turns left while walking",
            "walks in a left turn",
        ],
        "walk-turn-right" => vec![
            "walks and turns right",
            "turns right while walking",
            "walks in a right turn",
        ],
        "bow" => vec!["bows", "takes a bow", "bends forward in a bow"],
        "bye" => vec![
            "waves goodbye",
            "waves a hand to say bye",
            "says goodbye with a wave",
        ],
        "byebye" => vec![
            "waves goodbye with both hands",
            "waves both hands to say goodbye",
            "says bye bye",
        ],
        "guide" => vec![
            "guides someone with a hand",
            "points the way with a hand",
            "shows the way",
        ],
        "respond" => vec![
            "responds with a gesture",
            "answers with a nod and a gesture",
            "reacts to someone",
        ],
        "call" => vec![
            "calls someone over",
            "beckons someone to come",
            "calls out to someone",
        ],
        "punch" => vec!["punches", "throws a punch", "punches forward"],
        "kick" => vec!["kicks", "kicks forward", "does a kick"],
        "slash" => vec![
            "slashes with a sword",
            "swings a sword",
            "makes a slashing attack",
        ],
        "dance-long" | "dance-short" => vec!["dances", "is dancing", "dances energetically"],
        "wave-both-hands" => vec![
            "waves both hands",
            "waves with both arms",
            "raises both hands and waves",
        ],
        "wave-left-hand" => vec![
            "waves the left hand",
            "waves with the left arm",
            "raises the left hand and waves",
        ],
        "wave-right-hand" => vec![
            "waves the right hand",
            "waves with the right arm",
            "raises the right hand and waves",
        ],
        "raise-up-both-hands" => vec![
            "raises both hands",
            "lifts both arms above the head",
            "puts both hands up",
        ],
        "raise-up-left-hand" => vec![
            "raises the left hand",
            "lifts the left arm above the head",
            "puts the left hand up",
        ],
        "raise-up-right-hand" => vec![
            "raises the right hand",
            "lifts the right arm above the head",
            "puts the right hand up",
        ],
        _ => vec![],
    }
}

/// How a style reads as an adjective and as a manner ("in a … way").
fn style_words(style: &str) -> Option<(&'static str, &'static str)> {
    Some(match style {
        "normal" => return None,
        "happy" => ("happy", "happy"),
        "sad" => ("sad", "sad"),
        "angry" => ("angry", "angry"),
        "proud" => ("proud", "proud"),
        "not-confident" => ("shy", "unconfident"),
        "masculinity" | "masculine" => ("masculine", "masculine"),
        "feminine" => ("feminine", "feminine"),
        "childish" | "children" | "youthful" => ("young", "childish"),
        "old" | "elderly" => ("old", "elderly"),
        "tired" | "exhausted" => ("tired", "exhausted"),
        "active" => ("energetic", "active"),
        "musical" => ("theatrical", "musical"),
        "giant" => ("giant", "heavy"),
        "chimpira" => ("swaggering", "thuggish"),
        _ => return None,
    })
}

/// Several captions for a clip; empty when the content label is unknown.
pub fn captions(labels: &Labels) -> Vec<String> {
    let acts = actions(&labels.content);
    let mut out = Vec::new();
    for (i, act) in acts.iter().enumerate() {
        match style_words(&labels.style) {
            None => {
                let subject = ["a person", "someone", "a man"][i % 3];
                out.push(format!("{subject} {act}"));
            }
            Some((adj, manner)) => {
                out.push(format!("a {adj} person {act}"));
                out.push(format!("someone {act} in a {manner} way"));
                // Every content gets every plain subject: when only style-less clips (the
                // standing hand raises, mostly) said "a man", the bag-of-words model read
                // "a man walks forwards" as standing still.
                match i {
                    0 => out.push(format!("a person {act}")),
                    1 => out.push(format!("a man {act}")),
                    _ => {}
                }
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_file_names() {
        let l = parse_labels("dataset-2_walk-turn-left_elderly_003").unwrap();
        assert_eq!(l.content, "walk-turn-left");
        assert_eq!(l.style, "elderly");
        assert!(parse_labels("walk").is_none());
        assert!(parse_labels("dataset-1_walk").is_none());
    }

    #[test]
    fn mirrors_sides() {
        assert_eq!(mirror_content("wave-left-hand"), "wave-right-hand");
        assert_eq!(mirror_content("walk-turn-right"), "walk-turn-left");
        assert_eq!(mirror_content("bow"), "bow");
    }

    #[test]
    fn captions_mention_action_and_style() {
        let c = captions(&Labels {
            content: "run".into(),
            style: "tired".into(),
        });
        assert!(c.iter().any(|s| s == "a tired person runs forward"));
        assert!(c.iter().any(|s| s.contains("exhausted way")));
        assert!(c.len() >= 3);
        let n = captions(&Labels {
            content: "walk".into(),
            style: "normal".into(),
        });
        assert!(n.contains(&"a person walks forward".to_string()));
        assert!(
            captions(&Labels {
                content: "fly".into(),
                style: "normal".into()
            })
            .is_empty()
        );
    }

    #[test]
    fn styled_and_plain_clips_share_the_plain_subjects() {
        // "a man" must not be a word of the style-less (mostly standing) clips alone.
        for style in ["normal", "tired", "happy"] {
            for content in ["walk", "run", "raise-up-both-hands"] {
                let c = captions(&Labels {
                    content: content.into(),
                    style: style.into(),
                });
                for subject in ["a person ", "a man "] {
                    assert!(
                        c.iter().any(|s| s.starts_with(subject)),
                        "{content}/{style}: no caption starts with {subject:?}: {c:?}"
                    );
                }
            }
        }
    }
}
