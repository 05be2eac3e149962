use super::*;
use crate::metrics::actions::{MEASURES, track};
use crate::motion::{Motion, Pose};
use crate::skeleton::rest_pose;
use glam::{Quat, Vec3};
use std::path::Path;

const PELVIS: usize = 0;
const L_KNEE: usize = 4;
const R_KNEE: usize = 5;
const L_ANKLE: usize = 7;
const NECK: usize = 12;
const HEAD: usize = 15;
const R_SHOULDER: usize = 17;
const L_ELBOW: usize = 18;
const R_ELBOW: usize = 19;
const L_WRIST: usize = 20;
const R_WRIST: usize = 21;

fn value(name: &str, m: &Motion) -> f32 {
    (measure(name).expect("a measure").value)(&track(m))
}

/// The rest pose turned by `yaw` (radians, + = left) about the pelvis and moved by `at`.
fn pose(yaw: f32, at: Vec3) -> Pose {
    let rest = rest_pose();
    let q = Quat::from_rotation_y(yaw);
    rest.map(|p| q * (p - rest[PELVIS]) + rest[PELVIS] + at)
}

/// `frames` poses facing `yaw`, the pelvis moving by `step` each frame.
fn moving(frames: usize, yaw: f32, step: Vec3) -> Motion {
    Motion::new((0..frames).map(|f| pose(yaw, step * f as f32)).collect())
}

fn still(frames: usize) -> Vec<Pose> {
    (0..frames).map(|_| pose(0.0, Vec3::ZERO)).collect()
}

#[test]
fn travel_is_read_along_the_body_first_facing() {
    // 40 frames (2 s), 2 m along +Z, facing +Z: forward.
    let m = moving(41, 0.0, Vec3::new(0.0, 0.0, 0.05));
    assert!((value("forward", &m) - 2.0).abs() < 1e-4);
    assert!(value("left", &m).abs() < 1e-4);
    assert!((value("forward_speed", &m) - 2.0 / (41.0 / 20.0)).abs() < 1e-4);
    // Facing +X (turned 90° left): its left is −Z, so moving along −Z is to the left and
    // moving along −X is backwards.
    let yaw = std::f32::consts::FRAC_PI_2;
    let m = moving(41, yaw, Vec3::new(0.0, 0.0, -0.05));
    assert!(
        (value("left", &m) - 2.0).abs() < 1e-4,
        "{}",
        value("left", &m)
    );
    assert!(value("forward", &m).abs() < 1e-4);
    let m = moving(41, yaw, Vec3::new(-0.05, 0.0, 0.0));
    assert!((value("forward", &m) + 2.0).abs() < 1e-4);
    assert!((value("left_speed", &m)).abs() < 1e-4);
    // A body walking to its right: negative left.
    let m = moving(41, 0.0, Vec3::new(-0.05, 0.0, 0.0));
    assert!((value("left", &m) + 2.0).abs() < 1e-4);
    assert!((value("speed", &m) - 2.0 / (41.0 / 20.0)).abs() < 1e-3);
}

#[test]
fn hands_sides_and_heights() {
    let mut frames = still(20);
    // The left hand goes 0.2 m over the head in frame 5; the right only to the shoulder.
    frames[5][L_WRIST].y = frames[5][HEAD].y + 0.2;
    frames[8][R_WRIST].y = frames[8][R_SHOULDER].y + 0.01;
    let m = Motion::new(frames);
    assert!((value("left_wrist_over_head", &m) - 0.2).abs() < 1e-5);
    assert!(value("right_wrist_over_head", &m) < 0.0);
    assert!((value("wrist_over_head", &m) - 0.2).abs() < 1e-5);
    assert!(value("both_wrists_over_head", &m) < 0.0);
    assert!(value("right_minus_left_wrist", &m) < -0.1);
    assert!((value("right_wrist_over_shoulder", &m) - 0.01).abs() < 1e-5);
    assert!(value("both_wrists_over_shoulder", &m) < 0.0);
    // Both over the head in one frame.
    let mut frames = still(10);
    frames[3][L_WRIST].y = frames[3][HEAD].y + 0.1;
    frames[3][R_WRIST].y = frames[3][HEAD].y + 0.3;
    let m = Motion::new(frames);
    assert!((value("both_wrists_over_head", &m) - 0.1).abs() < 1e-5);
    // Both over the head, but never at once.
    let mut frames = still(10);
    frames[3][L_WRIST].y = frames[3][HEAD].y + 0.1;
    frames[6][R_WRIST].y = frames[6][HEAD].y + 0.1;
    assert!(value("both_wrists_over_head", &Motion::new(frames)) < 0.0);
    // Putting something down with the right hand: the right wrist goes lowest.
    let mut frames = still(10);
    frames[4][R_WRIST].y = 0.1;
    let m = Motion::new(frames);
    assert!(value("right_minus_left_wrist_low", &m) < -0.3);
    assert!(value("right_wrist_min", &m) < 0.15);
}

#[test]
fn a_wave_is_a_raised_hand_moving_side_to_side() {
    let swing = |raised: bool, amplitude: f32| {
        let frames: Vec<Pose> = still(60)
            .into_iter()
            .enumerate()
            .map(|(f, mut p)| {
                let lift = if raised { 0.3 } else { -0.3 };
                p[R_WRIST].y = p[R_SHOULDER].y + lift;
                // Three cycles along the body's left (+X), 20 frames each.
                p[R_WRIST].x =
                    p[R_SHOULDER].x + amplitude * (f as f32 * std::f32::consts::TAU / 20.0).sin();
                p
            })
            .collect();
        Motion::new(frames)
    };
    let m = swing(true, 0.1);
    assert!(
        value("right_wave_swings", &m) >= 4.0,
        "{}",
        value("right_wave_swings", &m)
    );
    assert_eq!(value("left_wave_swings", &m), 0.0);
    assert_eq!(value("wave_swings", &m), value("right_wave_swings", &m));
    assert_eq!(value("both_wave_swings", &m), 0.0);
    // The same movement below the shoulder, or a 2 cm tremble, is no wave.
    assert_eq!(value("right_wave_swings", &swing(false, 0.1)), 0.0);
    assert_eq!(value("right_wave_swings", &swing(true, 0.01)), 0.0);
}

#[test]
fn feet_floor_and_body_heights() {
    // Standing, then the whole body 0.2 m up for three frames: a jump.
    let frames: Vec<Pose> = (0..20)
        .map(|f| {
            let up = if (8..11).contains(&f) { 0.2 } else { 0.0 };
            pose(0.0, Vec3::new(0.0, up, 0.0))
        })
        .collect();
    let m = Motion::new(frames);
    assert!((value("both_feet_up", &m) - 0.2).abs() < 1e-5);
    // A left kick: the left ankle 0.6 m up and 0.4 m in front of the pelvis.
    let mut frames = still(20);
    let pelvis = frames[10][PELVIS];
    frames[10][L_ANKLE] = Vec3::new(frames[10][L_ANKLE].x, 0.0, pelvis.z + 0.4);
    let floor = frames[0][L_ANKLE].y;
    frames[10][L_ANKLE].y = floor + 0.6;
    let m = Motion::new(frames);
    assert!((value("left_ankle_max", &m) - 0.6).abs() < 1e-5);
    assert!(value("right_minus_left_ankle", &m) < -0.5);
    assert!((value("left_ankle_ahead", &m) - 0.4).abs() < 1e-5);
    assert!(value("right_ankle_ahead", &m).abs() < 0.05);
    // Squat and stand: the pelvis drops 0.4 m in the middle and comes back.
    let frames: Vec<Pose> = (0..20)
        .map(|f| {
            let mut p = pose(0.0, Vec3::ZERO);
            if f == 10 {
                for j in [
                    PELVIS, 3, 6, 9, NECK, HEAD, 13, 14, 16, 17, 18, 19, 20, 21, 1, 2,
                ] {
                    p[j].y -= 0.4;
                }
            }
            p
        })
        .collect();
    let m = Motion::new(frames);
    assert!((value("pelvis_drop", &m) - 0.4).abs() < 1e-5);
    assert!(value("pelvis_end_minus_start", &m).abs() < 1e-5);
    assert!(value("pelvis_min", &m) < value("pelvis_start", &m) - 0.39);
    // Lying down at the end: the last pose flat at floor height.
    let mut frames = still(10);
    let floor = frames[0][L_ANKLE].y;
    for p in &mut frames[9] {
        p.y = floor + 0.1;
    }
    let m = Motion::new(frames);
    assert!((value("pelvis_end", &m) - 0.1).abs() < 1e-5);
    assert!((value("head_end", &m) - 0.1).abs() < 1e-5);
    assert!(value("head_median", &m) > 1.0);
}

#[test]
fn upside_down_lean_reach_and_elbows() {
    // A cartwheel's middle: the pose flipped about the pelvis's height.
    let mut frames = still(10);
    let py = frames[5][PELVIS].y;
    for p in &mut frames[5] {
        p.y = 2.0 * py - p.y;
    }
    let m = Motion::new(frames);
    assert!(value("head_below_pelvis", &m) > 0.3);
    assert!(value("head_below_pelvis", &Motion::new(still(10))) < 0.0);
    // A bow: the neck 45° forward of the pelvis.
    let mut frames = still(10);
    let trunk = frames[4][NECK] - frames[4][PELVIS];
    let len = trunk.length();
    let s = std::f32::consts::FRAC_1_SQRT_2;
    frames[4][NECK] = frames[4][PELVIS] + Vec3::new(0.0, len * s, len * s);
    let m = Motion::new(frames);
    assert!(
        (value("torso_lean", &m) - 45.0).abs() < 0.5,
        "{}",
        value("torso_lean", &m)
    );
    // The same lean backwards is no bow.
    let mut frames = still(10);
    for p in &mut frames {
        p[NECK] = p[PELVIS] + Vec3::new(0.0, len * s, -len * s);
    }
    assert!(value("torso_lean", &Motion::new(frames)) < -40.0);
    // A punch: the right wrist 0.5 m in front of its shoulder, fast.
    let mut frames = still(10);
    frames[5][R_WRIST] = frames[5][R_SHOULDER] + Vec3::new(0.0, 0.0, 0.5);
    let m = Motion::new(frames);
    assert!((value("punch_reach", &m) - 0.5).abs() < 1e-5);
    assert!(value("wrist_speed", &m) > 3.0);
    assert_eq!(value("wrist_speed", &Motion::new(still(10))), 0.0);
    // Each elbow to the opposite knee, at different moments.
    let mut frames = still(10);
    frames[2][L_ELBOW] = frames[2][R_KNEE];
    frames[7][R_ELBOW] = frames[7][L_KNEE] + Vec3::new(0.05, 0.0, 0.0);
    let m = Motion::new(frames.clone());
    assert!((value("elbow_to_opposite_knee", &m) - 0.05).abs() < 1e-5);
    // Only one side: the other pair stays apart.
    frames[7][R_ELBOW] = frames[0][R_ELBOW];
    assert!(value("elbow_to_opposite_knee", &Motion::new(frames)) > 0.3);
}

#[test]
fn an_empty_motion_passes_no_judge() {
    let m = Motion::new(Vec::new());
    let t = track(&m);
    for spec in MEASURES {
        let v = (spec.value)(&t);
        let judge = Judge {
            measure: spec,
            min: Some(-1e9),
            max: Some(1e9),
            word: None,
        };
        // Empty motions give NaN (or a count of 0 / ±inf for a few), never a pass by accident
        // of a huge bound only when the value is NaN.
        if v.is_nan() {
            assert!(!judge.holds(v), "{}", spec.name);
        }
    }
}

#[test]
fn judges_hold_within_their_bounds_and_words_are_counted_apart() {
    let speed = measure("speed").unwrap();
    let turn = measure("turn").unwrap();
    let between = Judge {
        measure: speed,
        min: Some(0.15),
        max: Some(1.0),
        word: None,
    };
    assert!(between.holds(0.15) && between.holds(1.0) && between.holds(0.5));
    assert!(!between.holds(1.01) && !between.holds(0.1) && !between.holds(f32::NAN));
    assert_eq!(between.describe(), "0.15 ≤ speed ≤ 1");
    let side = Judge {
        measure: turn,
        min: Some(0.0),
        max: None,
        word: Some(Word::Side),
    };
    assert_eq!(side.describe(), "side: turn ≥ 0");
    let entry = Entry {
        caption: "a person walks and turns left".into(),
        wordings: vec!["someone turns left while walking".into()],
        pace: None,
        judges: vec![
            Judge {
                measure: turn,
                min: Some(45.0),
                max: None,
                word: None,
            },
            side,
        ],
    };
    assert!(entry.passes(&[60.0, 60.0]));
    assert!(!entry.passes(&[30.0, 30.0]));
    assert_eq!(entry.words_right(&[30.0, 30.0]), Some(true));
    assert_eq!(entry.words_right(&[-30.0, -30.0]), Some(false));
    let plain = Entry {
        judges: vec![entry.judges[0]],
        ..entry.clone()
    };
    assert_eq!(plain.words_right(&[60.0]), None);
}

#[test]
fn reversals_need_the_hysteresis() {
    let count = |v: &[f32]| crate::metrics::actions::count_reversals(v.iter().copied(), 0.05);
    assert_eq!(count(&[0.0, 0.1, 0.0, 0.1, 0.0]), 3);
    assert_eq!(count(&[0.0, 0.02, 0.0, 0.02, 0.0]), 0);
    assert_eq!(count(&[0.0, 0.1, 0.2, 0.3]), 0);
    assert_eq!(count(&[]), 0);
    assert_eq!(count(&[0.0, -0.06, 0.0]), 1);
}

// ---------------------------------------------------------------- the set file

const GOOD: &str = r#"
[[entry]]
caption = "a person runs forward"
wordings = ["someone runs ahead", "a man is running forwards"]
pace = "fast"
judges = [
  { measure = "speed", min = 2.2, word = "speed" },
  { measure = "forward", min = 0.0, word = "direction" },
]

[[entry]]
caption = "a person jumps"
wordings = ["someone jumps up"]
judges = [{ measure = "both_feet_up", min = 0.1 }]
"#;

fn parse(text: &str) -> Result<ParaphraseSet, SetError> {
    parse_set(text, Path::new("bench/test.toml"))
}

fn error(text: &str) -> String {
    parse(text).expect_err("a bad set").to_string()
}

#[test]
fn a_good_set_parses() {
    let set = parse(GOOD).unwrap();
    assert_eq!(set.entries.len(), 2);
    let run = &set.entries[0];
    assert_eq!(run.caption, "a person runs forward");
    assert_eq!(run.wordings.len(), 2);
    assert_eq!(run.pace, Some(Pace::Fast));
    assert_eq!(run.judges[0].measure.name, "speed");
    assert_eq!(run.judges[0].min, Some(2.2));
    assert_eq!(run.judges[1].word, Some(Word::Direction));
    assert_eq!(set.entries[1].pace, None);
}

#[test]
fn bad_sets_name_the_file_and_the_entry() {
    // Not TOML at all: the parser's line.
    let e = error("[[entry]]\ncaption = \"a person jumps\nwordings = []\n");
    assert!(e.starts_with("bench/test.toml: not valid TOML"), "{e}");
    assert!(e.contains("line 2"), "{e}");
    // An unknown measure: the entry by number, caption and line, and the known names.
    let e = error(&GOOD.replace("both_feet_up", "flying_height"));
    assert!(
        e.starts_with("bench/test.toml: entry 2 (\"a person jumps\", line 12): judge 1: unknown measure `flying_height`"),
        "{e}"
    );
    assert!(
        e.contains("both_feet_up") && e.contains("forward_speed"),
        "{e}"
    );
    // Wrong types and misspelt keys come from serde, with the entry named.
    let e = error(&GOOD.replace(
        "wordings = [\"someone jumps up\"]",
        "wordings = \"someone jumps up\"",
    ));
    assert!(e.contains("entry 2 (\"a person jumps\""), "{e}");
    assert!(e.contains("invalid type"), "{e}");
    let e = error(&GOOD.replace("pace = \"fast\"", "pace = \"quick\""));
    assert!(e.contains("entry 1 (\"a person runs forward\""), "{e}");
    assert!(e.contains("quick"), "{e}");
    let e = error(&GOOD.replace("wordings = [\"someone jumps up\"]", "wording = [\"x\"]"));
    assert!(
        e.contains("entry 2") && e.contains("unknown field `wording`"),
        "{e}"
    );
    // Bounds.
    let e = error(&GOOD.replace("min = 0.1 }", "min = 0.3, max = 0.1 }"));
    assert!(
        e.contains("entry 2") && e.contains("min 0.3 is above max 0.1"),
        "{e}"
    );
    let e = error(&GOOD.replace("min = 0.1 }", "word = \"side\" }"));
    assert!(e.contains("give `min`, `max` or both"), "{e}");
    let e = error(&GOOD.replace(
        "judges = [{ measure = \"both_feet_up\", min = 0.1 }]",
        "judges = []",
    ));
    assert!(e.contains("entry 2") && e.contains("no judges"), "{e}");
    // Wordings.
    let e = error(&GOOD.replace("[\"someone jumps up\"]", "[]"));
    assert!(e.contains("entry 2") && e.contains("no wordings"), "{e}");
    let e = error(&GOOD.replace("[\"someone jumps up\"]", "[\"A person jumps\"]"));
    assert!(e.contains("the caption itself"), "{e}");
    let e = error(&GOOD.replace("[\"someone jumps up\"]", "[\"x\", \"x\"]"));
    assert!(e.contains("wording 2 (\"x\") is given twice"), "{e}");
    // No caption: the entry by number alone.
    let e = error("[[entry]]\nwordings = [\"x\"]\njudges = [{ measure = \"speed\", min = 1.0 }]\n");
    assert!(
        e.starts_with("bench/test.toml: entry 1: missing field `caption`"),
        "{e}"
    );
    // The file's shape.
    let e = error(&GOOD.replace(
        "caption = \"a person jumps\"",
        "caption = \"a person runs forward\"",
    ));
    assert!(e.contains("entry 2") && e.contains("earlier entry"), "{e}");
    assert!(error("").contains("no [[entry]] tables"));
    assert!(error("title = \"x\"\n").contains("unknown key `title`"));
    assert!(error("entry = 3\n").contains("written [[entry]]"));
    // A missing file.
    let e = read_set(Path::new("/nonexistent/set.toml"))
        .unwrap_err()
        .to_string();
    assert!(e.contains("/nonexistent/set.toml"), "{e}");
}

/// The shipped set: at least 32 training captions of the shipped model with 3–4 wordings
/// each, no wording a training caption, and no wording naming the other side.
#[test]
fn the_shipped_set_is_well_formed() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let set = read_set(&root.join(DEFAULT_SET)).unwrap();
    assert!(set.entries.len() >= 32, "{}", set.entries.len());
    let actions: Vec<serde_json::Value> = serde_json::from_str(
        &std::fs::read_to_string(root.join("models/default/actions.json")).unwrap(),
    )
    .unwrap();
    let captions: Vec<&str> = actions
        .iter()
        .filter_map(|a| a["caption"].as_str())
        .collect();
    let lengths: serde_json::Map<String, serde_json::Value> = serde_json::from_str(
        &std::fs::read_to_string(root.join("models/default/lengths.json")).unwrap(),
    )
    .unwrap();
    let words = |s: &str| -> Vec<String> {
        s.split(|c: char| !c.is_alphanumeric())
            .map(str::to_lowercase)
            .collect()
    };
    let names_side = |s: &str, side: &str| {
        words(s).iter().any(|w| {
            w.starts_with(side)
                || (side == "left" && w == "counterclockwise")
                || (side == "right" && w == "clockwise")
        })
    };
    for e in &set.entries {
        assert!(captions.contains(&e.caption.as_str()), "{}", e.caption);
        assert!((3..=4).contains(&e.wordings.len()), "{}", e.caption);
        for w in &e.wordings {
            assert!(
                !lengths.keys().any(|c| c.eq_ignore_ascii_case(w)),
                "\"{w}\" is a training caption"
            );
            for (side, other) in [("left", "right"), ("right", "left")] {
                if names_side(&e.caption, side) {
                    assert!(names_side(w, side), "\"{w}\" drops \"{side}\"");
                    assert!(!names_side(w, other), "\"{w}\" names \"{other}\"");
                }
            }
            if e.caption.contains("backward") {
                assert!(
                    w.contains("backward") || w.contains("reverse"),
                    "\"{w}\" drops backwards"
                );
            }
        }
    }
}

// ---------------------------------------------------------------- totals and tables

fn sample(values: &[f32], speed: f32) -> Sample {
    Sample {
        values: values.to_vec(),
        speed,
    }
}

fn prompt(text: &str, exact: bool, differs: bool, samples: Vec<Vec<Sample>>) -> PromptRun {
    PromptRun {
        text: text.into(),
        exact,
        frames: 60,
        nearest: None,
        snapped: None,
        differs,
        training_caption: false,
        samples,
    }
}

/// A run of two entries (fast runs, slow walks), two seeds, both conditionings.
fn fake_run() -> BenchRun {
    let set = parse(
        r#"
[[entry]]
caption = "a person runs forward"
wordings = ["someone runs ahead"]
pace = "fast"
judges = [{ measure = "speed", min = 2.2, word = "speed" }]

[[entry]]
caption = "a person walks slowly"
wordings = ["someone strolls"]
pace = "slow"
judges = [{ measure = "speed", min = 0.15 }, { measure = "speed", max = 1.0, word = "speed" }]
"#,
    )
    .unwrap();
    let runs = &set.entries[0];
    let walks = &set.entries[1];
    BenchRun {
        settings: BenchSettings {
            seeds: vec![1, 2],
            steps: 50,
            guidance: 2.5,
            conditioning: vec![Conditioning::Nearest, Conditioning::Literal],
            max_wordings: None,
            caption_length: false,
        },
        entries: vec![
            EntryRun {
                entry: runs.clone(),
                prompts: vec![
                    prompt(
                        "a person runs forward",
                        true,
                        false,
                        vec![
                            vec![sample(&[2.5], 2.5), sample(&[2.6], 2.6)],
                            vec![sample(&[2.5], 2.5), sample(&[2.6], 2.6)],
                        ],
                    ),
                    prompt(
                        "someone runs ahead",
                        false,
                        true,
                        vec![
                            vec![sample(&[2.4], 2.4), sample(&[1.5], 1.5)],
                            vec![sample(&[0.8], 0.8), sample(&[0.9], 0.9)],
                        ],
                    ),
                ],
            },
            EntryRun {
                entry: walks.clone(),
                prompts: vec![
                    prompt(
                        "a person walks slowly",
                        true,
                        false,
                        vec![
                            vec![sample(&[0.7, 0.7], 0.7), sample(&[0.8, 0.8], 0.8)],
                            vec![sample(&[0.7, 0.7], 0.7), sample(&[0.8, 0.8], 0.8)],
                        ],
                    ),
                    prompt(
                        "someone strolls",
                        false,
                        false,
                        vec![
                            vec![sample(&[1.2, 1.2], 1.2), sample(&[0.6, 0.6], 0.6)],
                            vec![sample(&[1.2, 1.2], 1.2), sample(&[0.6, 0.6], 0.6)],
                        ],
                    ),
                ],
            },
        ],
    }
}

#[test]
fn totals_count_exact_and_paraphrase_success_words_and_pace() {
    let run = fake_run();
    let near = summary(&run, 0);
    assert_eq!(
        near.exact,
        Tally {
            passed: 4,
            total: 4
        }
    );
    // Runs ahead: 2.4 ✓, 1.5 ✗; strolls: 1.2 ✗, 0.6 ✓.
    assert_eq!(
        near.paraphrase,
        Tally {
            passed: 2,
            total: 4
        }
    );
    assert_eq!(near.ratio(), Some(0.5));
    assert_eq!(
        near.words_paraphrase,
        Tally {
            passed: 2,
            total: 4
        }
    );
    // Exact: fast 2.5, 2.6 against slow 0.7, 0.8: all four pairs.
    assert_eq!(
        near.pace_exact,
        Tally {
            passed: 4,
            total: 4
        }
    );
    // Wordings: fast 2.4, 1.5 against slow 1.2, 0.6: all four pairs faster.
    assert_eq!(
        near.pace_paraphrase,
        Tally {
            passed: 4,
            total: 4
        }
    );
    assert_eq!(near.slowest_fast.as_ref().unwrap().2, 2);
    let lit = summary(&run, 1);
    assert_eq!(lit.exact, near.exact);
    assert_eq!(
        lit.paraphrase,
        Tally {
            passed: 1,
            total: 4
        }
    );
    // Fast 0.8 and 0.9 against slow 1.2 and 0.6: two of four pairs.
    assert_eq!(
        lit.pace_paraphrase,
        Tally {
            passed: 2,
            total: 4
        }
    );
    assert_eq!(Tally::default().to_string(), "–");
    assert_eq!(near.paraphrase.to_string(), "2/4 (50 %)");
}

#[test]
fn tables_show_totals_captions_and_every_sample() {
    let md = tables(&fake_run());
    for needle in [
        "### Totals",
        "| nearest captions (`gen`'s default) | 4/4 (100 %) | 2/4 (50 %) | 50 % |",
        "| literal (`--literal-prompt`) | 4/4 (100 %) | 1/4 (25 %) | 25 % |",
        "### Per caption",
        "| a person runs forward (fast) | speed: speed ≥ 2.2 | 2/2 | 1/2 | 0/2 |",
        "| a person walks slowly (slow) | speed ≥ 0.15; speed: speed ≤ 1 | 2/2 | 1/2 | 1/2 |",
        "### Per prompt",
        "| **a person runs forward** (caption) |",
        "✗ **1.50**",
        "✓ 0.60 · 0.60",
        "slowest fast wording \"someone runs ahead\" (seed 2) 1.50 m/s",
    ] {
        assert!(md.contains(needle), "{needle} missing:\n{md}");
    }
    // The stroll reads the same under both conditionings: its literal cells say so.
    let stroll = md
        .lines()
        .find(|l| l.starts_with("| someone strolls |"))
        .unwrap();
    assert!(stroll.ends_with("| = | = |"), "{stroll}");
    assert!(md.contains("words right in every case"));
}

#[test]
fn every_measure_is_listed_once() {
    let table = measures_table();
    for m in MEASURES {
        assert_eq!(
            MEASURES.iter().filter(|o| o.name == m.name).count(),
            1,
            "{}",
            m.name
        );
        assert!(table.contains(&format!("| `{}` |", m.name)));
    }
}
