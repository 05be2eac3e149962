//! Rule-made paraphrases of training captions, for caption augmentation: the model
//! learns that "a man lifts his left arm" means what "a person raises the left hand"
//! means. The rules only swap wordings of the same meaning: side words (left, right),
//! direction words (forward, backwards, to the left) and speed words (runs, walks
//! slowly, dashes) are kept exact or replaced by a word of the same side, direction
//! and speed. [`super::augment`] then keeps the ones the sentence encoder places near
//! their caption.

/// Style adjectives of the captions ("a tired person …") and same-meaning words.
const STYLES: &[(&str, &[&str])] = &[
    ("energetic", &["energetic", "lively"]),
    ("tired", &["tired", "exhausted", "weary"]),
    ("old", &["old", "elderly"]),
    ("young", &["young", "youthful"]),
    ("feminine", &["feminine"]),
    ("masculine", &["masculine", "manly"]),
    ("happy", &["happy", "cheerful"]),
    ("sad", &["sad", "gloomy"]),
    ("angry", &["angry", "furious"]),
    ("proud", &["proud"]),
    ("shy", &["shy", "timid"]),
    ("swaggering", &["swaggering", "cocky"]),
    ("theatrical", &["theatrical", "dramatic"]),
    ("giant", &["giant", "huge"]),
];

/// Phrase substitutions of the same meaning (matched on whole words, first match per
/// position). Each keeps side, direction and speed.
const PHRASES: &[(&str, &[&str])] = &[
    (
        "walks forward",
        &["walks ahead", "walks straight ahead", "walks forwards"],
    ),
    (
        "runs forward",
        &["runs ahead", "runs forwards", "runs straight ahead"],
    ),
    ("jogs forward", &["jogs ahead", "jogs forwards"]),
    ("dashes forward", &["dashes ahead", "sprints forward"]),
    ("jumps forward", &["jumps ahead", "jumps forwards"]),
    (
        "walks backwards",
        &["walks backward", "walks in reverse", "steps backwards"],
    ),
    (
        "walks to the left",
        &["walks toward the left", "walks leftward"],
    ),
    (
        "walks to the right",
        &["walks toward the right", "walks rightward"],
    ),
    (
        "runs to the right",
        &["runs toward the right", "runs rightward"],
    ),
    ("turns left", &["turns to the left", "makes a left turn"]),
    ("turns right", &["turns to the right", "makes a right turn"]),
    (
        "walks and turns",
        &["walks and then turns", "walks, then turns"],
    ),
    (
        "runs and turns",
        &["runs and then turns", "runs, then turns"],
    ),
    ("waves goodbye", &["waves bye", "waves farewell"]),
    ("raises", &["lifts", "puts up"]),
    ("left hand", &["left arm"]),
    ("right hand", &["right arm"]),
    ("both hands", &["both arms"]),
    ("the floor", &["the ground"]),
    ("the ground", &["the floor"]),
    ("lies down", &["lays down", "lies down flat"]),
    ("squats down", &["crouches down", "squats"]),
    ("stands back up", &["stands up again", "gets back up"]),
    (
        "sneaks forward quietly",
        &["creeps forward quietly", "sneaks ahead quietly"],
    ),
    ("on hands and knees", &["on all fours"]),
    (
        "throws a basketball",
        &["throws a ball", "tosses a basketball"],
    ),
    ("does a", &["performs a"]),
    ("does cartwheels", &["performs cartwheels"]),
    (
        "walks slowly",
        &["walks at a slow pace", "walks slowly along"],
    ),
    ("walks briskly", &["walks quickly", "walks at a brisk pace"]),
    ("punches", &["throws a punch"]),
    ("kicks forward", &["kicks to the front"]),
    ("gets up from", &["stands up from", "rises from"]),
];

/// Whole predicates said another way (a word like "jumps" alone only as the whole
/// action: "jumps forward" is not "does a jump forward").
const WHOLE: &[(&str, &[&str])] = &[
    ("bows", &["takes a bow", "bows down"]),
    ("jumps", &["jumps up", "does a jump"]),
];

/// Subjects without a style word.
const PLAIN_SUBJECTS: &[&str] = &[
    "a person",
    "someone",
    "a man",
    "a woman",
    "the person",
    "a human",
];

/// The article before `word`.
fn article(word: &str) -> &'static str {
    if word.starts_with(['a', 'e', 'i', 'o', 'u']) {
        "an"
    } else {
        "a"
    }
}

/// `caption` split into its subject's style word (if any) and the predicate after
/// "a [style] person"; None when the caption has another form.
fn split_subject(caption: &str) -> Option<(Option<&'static str>, &str)> {
    let rest = caption
        .strip_prefix("a ")
        .or_else(|| caption.strip_prefix("an "))?;
    if let Some(pred) = rest.strip_prefix("person ") {
        return Some((None, pred));
    }
    let (style, after) = rest.split_once(' ')?;
    let pred = after.strip_prefix("person ")?;
    STYLES
        .iter()
        .find(|(s, _)| *s == style)
        .map(|(s, _)| (Some(*s), pred))
}

/// The action a caption names, without its subject and style ("walks forward").
pub fn action_of(caption: &str) -> &str {
    split_subject(caption).map_or(caption, |(_, pred)| pred)
}

/// Subjects of the same meaning, each with the possessive that fits it.
fn subjects(style: Option<&str>) -> Vec<(String, &'static str)> {
    let possessive = |s: &str| {
        if s.ends_with("man") && !s.ends_with("woman") {
            "his"
        } else if s.ends_with("woman") {
            "her"
        } else {
            "their"
        }
    };
    match style {
        None => PLAIN_SUBJECTS
            .iter()
            .map(|s| (s.to_string(), possessive(s)))
            .collect(),
        Some(style) => {
            let words = STYLES
                .iter()
                .find(|(s, _)| *s == style)
                .map_or(&[][..], |s| s.1);
            words
                .iter()
                .flat_map(|w| {
                    ["person", "man", "woman"]
                        .into_iter()
                        .map(move |noun| (format!("{} {w} {noun}", article(w)), noun))
                })
                .chain(words.iter().map(|w| (format!("the {w} person"), "person")))
                .map(|(s, noun)| {
                    let p = possessive(noun);
                    (s, p)
                })
                .collect()
        }
    }
}

/// `verb` (third person singular) in its -ing form: "walks" → "walking", "runs" →
/// "running", "raises" → "raising", "crouches" → "crouching", "lies" → "lying".
pub fn ing_form(verb: &str) -> Option<String> {
    let irregular = [("lies", "lying"), ("does", "doing"), ("goes", "going")];
    if let Some((_, ing)) = irregular.iter().find(|(v, _)| *v == verb) {
        return Some(ing.to_string());
    }
    let base = if let Some(stem) = verb.strip_suffix("ies") {
        format!("{stem}y")
    } else if ["ches", "shes", "sses", "xes", "zes"]
        .iter()
        .any(|e| verb.ends_with(e))
    {
        verb[..verb.len() - 2].to_string()
    } else {
        verb.strip_suffix('s')?.to_string()
    };
    if base.len() < 2 {
        return None;
    }
    let b: Vec<char> = base.chars().collect();
    let vowel = |c: char| "aeiou".contains(c);
    let n = b.len();
    if b[n - 1] == 'e' && b[n - 2] != 'e' {
        return Some(format!("{}ing", &base[..base.len() - 1]));
    }
    // One short syllable ending consonant-vowel-consonant doubles its last letter.
    let cvc = n >= 3 && !vowel(b[n - 3]) && vowel(b[n - 2]) && !vowel(b[n - 1]);
    let vowels = b.iter().filter(|c| vowel(**c)).count();
    if cvc && vowels == 1 && !"wxy".contains(b[n - 1]) {
        return Some(format!("{base}{}ing", b[n - 1]));
    }
    Some(format!("{base}ing"))
}

/// The predicate in the progressive ("walks and turns left" → "is walking and turning
/// left"): the first word and every verb after "and" or "then".
fn progressive(pred: &str) -> Option<String> {
    let words: Vec<&str> = pred.split(' ').collect();
    let mut out = Vec::with_capacity(words.len() + 1);
    out.push("is".to_string());
    for (i, w) in words.iter().enumerate() {
        let after_joint = i > 0 && matches!(words[i - 1], "and" | "then");
        let verb_like = w.ends_with('s') && !w.ends_with("ss") && w.len() > 2;
        if i == 0 || (after_joint && verb_like) {
            out.push(ing_form(w)?);
        } else {
            out.push(w.to_string());
        }
    }
    Some(out.join(" "))
}

/// Every way of writing `pred` with the phrase substitutions (each position kept or
/// replaced), the original first.
fn predicate_variants(pred: &str) -> Vec<String> {
    let mut variants = vec![pred.to_string()];
    if let Some((_, alternatives)) = WHOLE.iter().find(|(w, _)| *w == pred) {
        variants.extend(alternatives.iter().map(|a| a.to_string()));
    }
    for (phrase, alternatives) in PHRASES {
        let mut more = Vec::new();
        for v in &variants {
            if let Some(at) = find_words(v, phrase) {
                for alt in *alternatives {
                    more.push(format!("{}{alt}{}", &v[..at], &v[at + phrase.len()..]));
                }
            }
        }
        variants.extend(more);
        variants.truncate(64);
    }
    variants
}

/// Byte offset of `phrase` in `text` as whole words.
fn find_words(text: &str, phrase: &str) -> Option<usize> {
    let mut from = 0;
    while let Some(i) = text[from..].find(phrase) {
        let at = from + i;
        let end = at + phrase.len();
        let before_ok = at == 0 || text.as_bytes()[at - 1] == b' ';
        let after_ok = end == text.len() || !text.as_bytes()[end].is_ascii_alphanumeric();
        if before_ok && after_ok {
            return Some(at);
        }
        from = at + 1;
    }
    None
}

/// Rule-made paraphrases of `caption` (not including it), in a fixed order: subjects
/// and styles of the same meaning, same-meaning phrases, "the left hand" as the
/// subject's own, and the progressive ("is walking"). Side, direction and speed words
/// stay.
pub fn paraphrases(caption: &str) -> Vec<String> {
    let caption = caption.trim();
    let (subjects, pred) = match split_subject(caption) {
        Some((style, pred)) => (subjects(style), pred.to_string()),
        None => (Vec::new(), caption.to_string()),
    };
    let mut preds = Vec::new();
    for v in predicate_variants(&pred) {
        if let Some(p) = progressive(&v) {
            preds.push(p);
        }
        preds.push(v);
    }
    let mut out: Vec<String> = Vec::new();
    let mut push = |s: String| {
        if s != caption && !out.contains(&s) {
            out.push(s);
        }
    };
    if subjects.is_empty() {
        preds.into_iter().for_each(&mut push);
        return out;
    }
    for (subject, possessive) in &subjects {
        for p in &preds {
            push(format!("{subject} {p}"));
            if possessive != &"their" || subject.starts_with("someone") {
                let own = p
                    .replace("the left ", &format!("{possessive} left "))
                    .replace("the right ", &format!("{possessive} right "));
                push(format!("{subject} {own}"));
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ing_forms_follow_english_spelling() {
        for (v, ing) in [
            ("walks", "walking"),
            ("runs", "running"),
            ("raises", "raising"),
            ("crouches", "crouching"),
            ("lies", "lying"),
            ("steps", "stepping"),
            ("waves", "waving"),
            ("jumps", "jumping"),
            ("bows", "bowing"),
            ("dashes", "dashing"),
            ("leaps", "leaping"),
            ("carries", "carrying"),
            ("kicks", "kicking"),
        ] {
            assert_eq!(ing_form(v).as_deref(), Some(ing), "{v}");
        }
    }

    #[test]
    fn paraphrases_keep_side_direction_and_speed_words() {
        let side = |s: &str| (s.contains("left"), s.contains("right"), s.contains("both"));
        for caption in [
            "a person raises the left hand",
            "a tired person walks and turns right",
            "a person walks backwards",
            "a energetic person runs forward",
            "a person walks slowly",
            "a person kicks forward with the left leg",
        ] {
            let all = paraphrases(caption);
            assert!(all.len() >= 6, "{caption}: {all:?}");
            for p in &all {
                assert_ne!(p, caption);
                assert_eq!(side(p), side(caption), "{caption} → {p}");
                if caption.contains("backwards") {
                    assert!(p.contains("backward") || p.contains("reverse"), "{p}");
                }
                if caption.contains("runs") {
                    assert!(p.contains("run"), "{p}");
                }
                if caption.contains("slowly") {
                    assert!(p.contains("slow"), "{p}");
                }
            }
        }
    }

    #[test]
    fn subjects_styles_and_progressive() {
        let all = paraphrases("a tired person raises the left hand");
        for expected in [
            "an exhausted man lifts his left hand",
            "a weary woman raises her left arm",
            "the tired person is raising the left hand",
        ] {
            assert!(all.iter().any(|p| p == expected), "{expected}: {all:?}");
        }
        let walk = paraphrases("a person walks and turns left");
        assert!(
            walk.iter()
                .any(|p| p == "someone is walking and turning left"),
            "{walk:?}"
        );
        assert!(
            walk.iter()
                .any(|p| p == "a man walks and then turns to the left"),
            "{walk:?}"
        );
        // An article that fits the style word.
        assert!(
            paraphrases("a energetic person bows")
                .iter()
                .any(|p| p.starts_with("an energetic man"))
        );
        assert_eq!(action_of("a tired person walks forward"), "walks forward");
        assert_eq!(action_of("someone walks"), "someone walks");
    }

    #[test]
    fn whole_words_only() {
        // "bows" inside "elbows" is not a bow.
        let all = paraphrases("a person touches each knee with the opposite elbow");
        assert!(all.iter().all(|p| !p.contains("elbow down")), "{all:?}");
        assert_eq!(find_words("touches elbows", "bows"), None);
        assert_eq!(find_words("a person bows", "bows"), Some(9));
    }
}
