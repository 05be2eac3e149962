//! Captions of CMU trials from CMU's own descriptions (`cmu_trial_index.csv`: subject,
//! trial, description, …), e.g. `playground - climb, sit, dangle legs, descend`.
//!
//! A description is an optional context (`playground`, `basketball`, `dance`, `soccer`)
//! and a list of actions in the order they happen. The trials are not cropped (CMU gives
//! no action times), so a caption names every action, in order: "a person climbs, sits
//! down, dangles the legs and then climbs down on a playground". Never the first verb
//! alone. Action words go through [`ACTIONS`]; an action it lacks is conjugated as an
//! English verb phrase (`walk backward` → "walks backward").

use std::collections::HashMap;
use std::path::Path;

/// Descriptions keyed by (subject, trial).
pub type TrialIndex = HashMap<(u32, u32), String>;

/// Reads `cmu_trial_index.csv` (header row, quoted fields with commas).
pub fn read_trial_index(path: &Path) -> Result<TrialIndex, String> {
    let text = std::fs::read_to_string(path).map_err(|e| format!("{}: {e}", path.display()))?;
    let mut index = TrialIndex::new();
    for line in text.lines().skip(1) {
        let fields = csv_fields(line);
        let (Some(s), Some(t), Some(d)) = (fields.first(), fields.get(1), fields.get(2)) else {
            continue;
        };
        if let (Ok(s), Ok(t)) = (s.trim().parse(), t.trim().parse()) {
            index.insert((s, t), d.trim().to_string());
        }
    }
    Ok(index)
}

/// Splits one CSV line; `"…"` fields may hold commas and `""` quotes.
fn csv_fields(line: &str) -> Vec<String> {
    let mut fields = vec![String::new()];
    let mut quoted = false;
    let mut chars = line.chars().peekable();
    while let Some(c) = chars.next() {
        match c {
            '"' if quoted && chars.peek() == Some(&'"') => {
                chars.next();
                fields.last_mut().expect("one field").push('"');
            }
            '"' => quoted = !quoted,
            ',' if !quoted => fields.push(String::new()),
            c => fields.last_mut().expect("one field").push(c),
        }
    }
    fields
}

/// (subject, trial) of a CMU file stem `01_01` (cgspeed) or `02_01`.
pub fn cmu_trial(stem: &str) -> Option<(u32, u32)> {
    let (s, t) = stem.split_once('_')?;
    let digits = |x: &str| !x.is_empty() && x.len() <= 3 && x.bytes().all(|b| b.is_ascii_digit());
    (digits(s) && digits(t)).then(|| Some((s.parse().ok()?, t.parse().ok()?)))?
}

/// Action phrases of CMU's descriptions, third person. Checked whole first, so that
/// sequences written without commas (`run jump stop run`) read as sequences.
const ACTIONS: &[(&str, &str)] = &[
    ("walk", "walks forward"),
    ("slow walk", "walks slowly"),
    ("brisk walk", "walks briskly"),
    ("walk/stride", "walks with long strides"),
    ("slow walk/stride", "walks slowly with long strides"),
    ("exaggerated stride", "takes exaggerated strides"),
    ("walk on uneven terrain", "walks over uneven ground"),
    ("run", "runs forward"),
    ("run/jog", "jogs forward"),
    ("jog", "jogs forward"),
    ("jump", "jumps"),
    ("jumps", "jumps"),
    ("forward jump", "jumps forward"),
    ("forward jumps", "jumps forward several times"),
    ("jump up and down", "jumps up and down in place"),
    ("hop on one foot", "hops on one foot"),
    ("balance", "keeps balance"),
    ("turn around", "turns around"),
    ("punch/strike", "punches and strikes"),
    ("bend over", "bends over"),
    ("scoop up", "scoops something up from the floor"),
    ("rise", "stands back up"),
    ("lift arm", "lifts an arm"),
    ("swordplay", "fights with a sword"),
    ("wash self", "washes themselves"),
    ("climb", "climbs"),
    ("hang", "hangs from a bar"),
    ("swing", "swings"),
    ("go under", "ducks under a bar"),
    ("sit", "sits down"),
    ("dangle legs", "dangles the legs"),
    ("dangle", "dangles from a bar"),
    ("descend", "climbs down"),
    ("jump down", "jumps down"),
    ("rock back", "rocks back"),
    ("lower self to ground", "lowers themselves to the ground"),
    (
        "hold self up with arms straight",
        "holds themselves up with straight arms",
    ),
    ("drop", "drops to the ground"),
    ("lean back", "leans back"),
    ("lean over", "leans over"),
    ("pull up", "does a pull-up"),
    ("legs push off against", "pushes off with the legs"),
    ("walk forward", "walks forward"),
    ("backward", "walks backward"),
    ("sideways", "walks sideways"),
    ("kick ball", "kicks a ball"),
    ("walk to run", "walks and then starts running"),
    ("run to quick stop", "runs and stops quickly"),
    ("run right", "runs to the right"),
    ("run left", "runs to the left"),
    ("run turn left", "runs and turns left"),
    ("run turn right", "runs and turns right"),
    ("run stop run", "runs, stops and runs again"),
    ("run jump stop run", "runs, jumps, stops and runs again"),
    (
        "run dive over roll run",
        "runs, dives over an obstacle, rolls and runs on",
    ),
    ("run jump over", "runs and jumps over an obstacle"),
    ("run duck underneath", "runs and ducks under an obstacle"),
    ("get up from ground", "gets up from the ground"),
    ("get up face down", "gets up from lying face down"),
    ("get up laying on side", "gets up from lying on the side"),
    ("sudden stop", "stops suddenly"),
    ("veer left", "veers left"),
    ("veer right", "veers right"),
    ("90-degree left turn", "turns 90 degrees to the left"),
    ("90-degree right turn", "turns 90 degrees to the right"),
    ("grip bar", "grips a bar"),
    ("swing body", "swings the body"),
    ("leap", "leaps"),
    ("cartwheel", "does a cartwheel"),
    ("cartwheels", "does cartwheels"),
    ("stretch", "stretches"),
    ("jump twist", "jumps and twists in the air"),
    ("hand stand kicks", "kicks from a handstand"),
    ("kick flip", "does a flip kick"),
    ("kick flip stumble", "does a flip kick and stumbles"),
    (
        "helicopter",
        "spins the legs around in a breakdance helicopter",
    ),
    ("jump and spin kick", "jumps and does a spin kick"),
    (
        "crouch and flip backward on hands",
        "crouches and flips backward on the hands",
    ),
    ("stretch and cartwheel", "stretches and does a cartwheel"),
    ("jump kick", "does a jump kick"),
    ("fall on face", "falls forward onto the face"),
    ("bannana peel slip", "slips and falls"),
    ("banana peel slip", "slips and falls"),
    ("jump up to grab", "jumps up to grab something"),
    ("reach for", "reaches for something"),
    ("tiptoe", "stands on tiptoe"),
    ("navigate", "walks around"),
];

/// Context prefixes: how the whole sentence changes.
fn with_context(context: &str, actions: &str) -> String {
    match context {
        "playground" => format!("{actions} on a playground"),
        "basketball" => format!("{actions} with a basketball"),
        "soccer" => format!("{actions} with a soccer ball"),
        "" => actions.to_string(),
        other => format!("{actions} ({other})"),
    }
}

/// Ballet terms of CMU's dance trials, as plain movements.
fn dance_moves(actions: &[String]) -> Vec<&'static str> {
    let mut moves = Vec::new();
    for a in actions {
        let m = if a.contains("pirouette") {
            "spins on one foot"
        } else if a.contains("cartwheel") {
            "does a cartwheel"
        } else if a.contains("jete") {
            "leaps"
        } else if a.contains("arabesque") || a.contains("raised leg") || a.contains("rond") {
            "raises a leg high"
        } else if a.contains("bending back") {
            "bends backwards"
        } else if a.contains("turn") {
            "turns"
        } else if a.contains("arms") {
            "moves the arms gracefully"
        } else {
            continue;
        };
        if !moves.contains(&m) {
            moves.push(m);
        }
    }
    moves
}

/// `JumpTwist` → `jump twist`, lowercased, spaces collapsed.
fn normalise(text: &str) -> String {
    let mut out = String::new();
    let mut prev_lower = false;
    for c in text.chars() {
        if c.is_uppercase() && prev_lower {
            out.push(' ');
        }
        prev_lower = c.is_lowercase();
        out.extend(c.to_lowercase());
    }
    out.split_whitespace().collect::<Vec<_>>().join(" ")
}

/// Third person of an action CMU's table lacks: the first word is taken as the verb.
fn conjugate(action: &str) -> String {
    let (verb, rest) = action.split_once(' ').unwrap_or((action, ""));
    let verb = if verb.ends_with('s') || verb.ends_with("sh") || verb.ends_with("ch") {
        format!("{verb}es")
    } else if verb.ends_with('y') && !verb.ends_with("ay") && !verb.ends_with("ey") {
        format!("{}ies", &verb[..verb.len() - 1])
    } else {
        format!("{verb}s")
    };
    if rest.is_empty() {
        verb
    } else {
        format!("{verb} {rest}")
    }
}

fn phrase(action: &str) -> String {
    ACTIONS
        .iter()
        .find(|(k, _)| *k == action)
        .map(|(_, v)| v.to_string())
        .unwrap_or_else(|| conjugate(action))
}

/// "a, b and then c".
fn in_order(phrases: &[String]) -> String {
    match phrases {
        [] => String::new(),
        [one] => one.clone(),
        [rest @ .., last] => format!("{} and then {last}", rest.join(", ")),
    }
}

/// Sentences for a CMU trial description; empty when it names no action.
pub fn cmu_captions(description: &str) -> Vec<String> {
    let text = normalise(description);
    let (context, body) = match text.split_once(" - ") {
        Some((c, b)) => (c.trim(), b.trim()),
        None => ("", text.as_str()),
    };
    let actions: Vec<String> = body
        .split(',')
        .map(|a| a.trim().to_string())
        .filter(|a| !a.is_empty())
        .collect();
    if actions.is_empty() {
        return Vec::new();
    }
    let sentence = if context == "dance" {
        let moves = dance_moves(&actions);
        if moves.is_empty() {
            "dances ballet".to_string()
        } else {
            let moves: Vec<String> = moves.iter().map(|m| m.to_string()).collect();
            format!(
                "dances ballet: {}",
                in_order(&moves).replace(" and then ", " and ")
            )
        }
    } else if context == "basketball" {
        let what = body.replace("dribble", "").replace("  ", " ");
        let what = what.trim().trim_matches(',').trim();
        if body.contains("shoot") {
            "dribbles a basketball and shoots".to_string()
        } else if what.is_empty() {
            "dribbles a basketball".to_string()
        } else {
            format!("dribbles a basketball, moving {what}")
        }
    } else {
        let phrases: Vec<String> = actions.iter().map(|a| phrase(a)).collect();
        with_context(context, &in_order(&phrases))
    };
    ["a person", "someone", "a man"]
        .iter()
        .map(|s| format!("{s} {sentence}"))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_action_in_order() {
        let c = cmu_captions("playground - climb, sit, dangle legs, descend");
        assert_eq!(
            c[0],
            "a person climbs, sits down, dangles the legs and then climbs down on a playground"
        );
        assert_eq!(cmu_captions("walk")[0], "a person walks forward");
        assert_eq!(
            cmu_captions("Run Jump Stop Run")[0],
            "a person runs, jumps, stops and runs again"
        );
        assert_eq!(
            cmu_captions("bend over, scoop up, rise, lift arm")[0],
            "a person bends over, scoops something up from the floor, stands back up and then lifts an arm"
        );
        assert_eq!(
            cmu_captions("JumpTwist")[0],
            "a person jumps and twists in the air"
        );
        assert!(cmu_captions("dance - small jetes, pirouette")[0].contains("leaps"));
        assert!(cmu_captions("").is_empty());
    }

    #[test]
    fn unknown_actions_are_conjugated() {
        assert_eq!(cmu_captions("push cart")[0], "a person pushes cart");
        assert_eq!(cmu_captions("carry box")[0], "a person carries box");
    }

    #[test]
    fn trial_numbers_and_csv() {
        assert_eq!(cmu_trial("01_01"), Some((1, 1)));
        assert_eq!(cmu_trial("127_38"), Some((127, 38)));
        assert_eq!(cmu_trial("HDM_bd"), None);
        assert_eq!(cmu_trial("dataset-1_walk_normal_001"), None);
        assert_eq!(
            csv_fields(r#"1,2,"climb, sit ""up""",120"#),
            vec!["1", "2", "climb, sit \"up\"", "120"]
        );
    }
}
