//! The REPL backend without a terminal: a `Session` is fed inputs and its replies are
//! checked against numbers computed by hand on a synthetic motion, and against
//! `lang::check_source` for diagnostics.

mod common;

use burn::tensor::{Device, Tensor, TensorData};
use glam::Vec3;
use mprog::lang::{check_source, compile};
use mprog::motion::Motion;
use mprog::repl::Session;
use mprog::skeleton::{NUM_JOINTS, rest_pose};

const F: usize = 40;

/// The rest pose walking forward 0.05 m per frame; the head rises 1 cm per frame.
fn walk() -> Motion {
    let rest = rest_pose();
    Motion::new(
        (0..F)
            .map(|t| {
                std::array::from_fn(|j| {
                    let mut p = rest[j] + Vec3::new(0.0, 0.0, 0.05 * t as f32);
                    if j == 15 {
                        p.y += 0.01 * t as f32;
                    }
                    p
                })
            })
            .collect(),
    )
}

fn session() -> Session {
    let mut s = Session::new(None);
    s.set_motion(vec![walk()], "walk");
    s
}

fn say(s: &mut Session, input: &str) -> String {
    let r = s.handle(input);
    assert!(!r.is_error(), "{input}:\n{}", r.render(false));
    r.render(false)
}

fn fails(s: &mut Session, input: &str) -> String {
    let r = s.handle(input);
    assert!(r.is_error(), "{input} should fail:\n{}", r.render(false));
    r.render(false)
}

#[test]
fn statements_accumulate_and_clear() {
    let mut s = session();
    say(&mut s, "length 2s");
    say(&mut s, "param bar = 1.5 m");
    let added = say(&mut s, "head.y > bar");
    assert!(added.contains("line 3: head.y > bar"), "{added}");
    let shown = say(&mut s, ":show");
    assert!(
        shown.contains("  1 │ length 2s") && shown.contains("  3 │ head.y > bar"),
        "{shown}"
    );
    say(&mut s, "always {\n  pelvis.z < 10 m\n}");
    assert_eq!(s.program().unwrap().statements().len(), 2);
    say(&mut s, ":clear");
    assert_eq!(s.source(), "");
    assert!(say(&mut s, ":show").contains("empty"));
}

#[test]
fn drop_deletes_lines_unless_the_rest_no_longer_checks() {
    let mut s = session();
    say(&mut s, "length 2s");
    say(&mut s, "param bar = 1.5 m");
    say(&mut s, "head.y > bar");
    say(&mut s, "always {\n  pelvis.z < 10 m\n}");
    // Line 2 declares what line 3 uses: dropping it alone leaves an unknown name.
    let refused = fails(&mut s, ":drop 2");
    assert!(
        refused.contains("not dropped") && refused.contains("bar"),
        "{refused}"
    );
    assert_eq!(s.program().unwrap().statements().len(), 2);
    // A block's closing brace alone is refused; its body, then the whole block, go.
    fails(&mut s, ":drop 6");
    assert!(say(&mut s, ":drop 5").contains("pelvis.z < 10 m"));
    say(&mut s, ":drop 4-5");
    say(&mut s, ":drop 2-3");
    assert_eq!(s.source(), "length 2s\n");
    assert!(fails(&mut s, ":drop 7").contains("1 line(s)"));
}

#[test]
fn wrong_code_is_rejected_with_the_checkers_diagnostics() {
    let mut s = session();
    say(&mut s, "length 2s");
    let out = fails(&mut s, "r_hnad.y > 1");
    let expected = check_source("length 2s\nr_hnad.y > 1\n", "<repl>", &[]).render_plain();
    assert_eq!(out.trim_end(), expected.trim_end());
    assert!(out.contains("did you mean `r_hand`?"));
    assert_eq!(s.source(), "length 2s\n", "rejected code is not kept");
}

#[test]
fn eval_of_a_scalar_summarises_frames() {
    let mut s = session();
    let rest = rest_pose();
    let out = say(&mut s, ":eval head.y");
    let lo = rest[15].y;
    let hi = rest[15].y + 0.01 * (F - 1) as f32;
    let mean = (lo + hi) / 2.0;
    let want = format!("min {:.3}  mean {:.3}  max {:.3}", lo, mean, hi);
    assert!(out.contains(&want), "{out}\nwant {want}");
    assert!(
        out.contains('▁') && out.contains('█') && out.contains("frames 0–39"),
        "{out}"
    );
}

#[test]
fn eval_of_a_vector_shows_components() {
    let mut s = session();
    let out = say(&mut s, ":eval pelvis - pelvis@start");
    assert!(out.contains("x  min 0  mean 0  max 0"), "{out}");
    assert!(out.contains("z  min 0  mean 0.9750  max 1.950"), "{out}");
}

#[test]
fn eval_of_a_statement_shows_its_error() {
    let mut s = session();
    // pelvis.z = 0.05 t: the error of `pelvis.z > 1 m` is max(1 − 0.05 t, 0).
    let out = say(&mut s, ":eval pelvis.z > 1 m");
    let want: f32 = (0..F)
        .map(|t| (1.0 - 0.05 * t as f32).max(0.0))
        .sum::<f32>()
        / F as f32;
    assert!(
        out.contains(&format!("error {want:.4} m")),
        "{out}\nwant {want}"
    );
    assert!(out.contains("zero at 20"), "{out}");
    let end = say(&mut s, ":eval at end { pelvis.z > 3 m }");
    assert!(end.contains("frame 39: 1.050"), "{end}");
    let during = say(&mut s, ":eval during 10..20 { pelvis.z > 1 m }");
    assert!(
        during.contains("frames 10–19") && !during.contains('·'),
        "{during}"
    );
}

#[test]
fn eval_explains_bad_input() {
    let mut s = session();
    let out = fails(&mut s, ":eval head.w");
    assert!(
        out.contains("mprog::unknown_component") && !out.contains("not_a_constraint"),
        "{out}"
    );
    let none = fails(&mut s, ":eval let q = 3");
    assert!(none.contains("nothing to evaluate"), "{none}");
    let mut empty = Session::new(None);
    assert!(fails(&mut empty, ":eval head.y").contains("no current motion"));
}

#[test]
fn grad_ranks_the_joints_the_statement_moves() {
    let mut s = session();
    let out = say(&mut s, ":grad l_hand.y > 3 m");
    let first = out.lines().nth(1).unwrap_or("");
    assert!(first.trim_start().starts_with("left_wrist"), "{out}");
    assert_eq!(out.lines().count(), 2, "only the left wrist moves:\n{out}");
    let satisfied = say(&mut s, ":grad l_hand.y < 3 m");
    assert!(satisfied.contains("gradient is zero"), "{satisfied}");
    let two = say(&mut s, ":grad dist(l_hand, r_hand) < 10 cm");
    assert!(
        two.contains("left_wrist") && two.contains("right_wrist"),
        "{two}"
    );
    assert!(fails(&mut s, ":grad l_hand").contains("vector"));
}

#[test]
fn score_matches_program_evaluation() {
    let mut s = session();
    let src = "length 2s\nhead.y > 1.8 m\nat end { pelvis.z > 3 m }\nfor f in [l_foot, r_foot] { f.y < 1 cm }\n";
    for line in src.lines() {
        say(&mut s, line);
    }
    let out = say(&mut s, ":score");
    let prog = compile(src, "x", &[]).unwrap();
    let m = walk();
    let x = Tensor::<5>::from_data(
        TensorData::new(m.to_flat(), [1, 1, F, NUM_JOINTS, 3]),
        &Device::flex(),
    );
    let total = prog
        .evaluate(x)
        .total
        .into_data()
        .try_into_vec::<f32>()
        .unwrap()[0];
    let want = format!("total {} on walk", mprog::repl::summary::num(total));
    assert!(out.contains(&want), "{out}\nwant {want}");
    assert_eq!(out.lines().count(), 4, "{out}");
}

#[test]
fn per_frame_errors_average_to_the_statement_errors() {
    let src = "length 2s\nhead.y > 1.8 m\nif pelvis.z > 1 m { head.y > 1.9 m }\nduring 5..15 weight 2 { for f in [l_foot, r_foot] { f.y > 0.2 m } }\nat end { pelvis.z > 3 m }\n";
    let prog = compile(src, "x", &[]).unwrap();
    let m = walk();
    let x = Tensor::<5>::from_data(
        TensorData::new(m.to_flat(), [1, 1, F, NUM_JOINTS, 3]),
        &Device::flex(),
    );
    let per = prog
        .evaluate(x.clone())
        .per_statement
        .into_data()
        .try_into_vec::<f32>()
        .unwrap();
    let frames = prog.evaluate_frames(x).unwrap();
    assert_eq!(frames.len(), per.len());
    for (i, fe) in frames.iter().enumerate() {
        let vals: Vec<f32> = fe.errors[0]
            .iter()
            .zip(&fe.applies[0])
            .filter(|(_, a)| **a)
            .map(|(v, _)| *v)
            .collect();
        let mean = vals.iter().sum::<f32>() / vals.len().max(1) as f32;
        assert!(
            (mean - per[i]).abs() < 1e-4,
            "statement {i}: per-frame mean {mean} vs {}",
            per[i]
        );
    }
    assert_eq!(frames[2].frames, (5..15).collect::<Vec<_>>());
    assert_eq!(
        frames[1].applies[0].iter().filter(|a| **a).count(),
        19,
        "pelvis.z > 1 from frame 21"
    );
}

#[test]
fn files_commands_and_errors() {
    let dir = tempfile::tempdir().unwrap();
    let mut s = Session::new(Some(dir.path().join("no-model")));
    assert!(fails(&mut s, ":motion /no/such/walk.bvh").contains("walk.bvh"));
    let gen_err = fails(&mut s, ":gen \"a person walks\" 2");
    assert!(
        gen_err.contains("cannot load the model bundle") && gen_err.contains("--model"),
        "{gen_err}"
    );
    let good = dir.path().join("good.mprog");
    std::fs::write(&good, "length 2s\nhead.y > 1 m\n").unwrap();
    let bad = dir.path().join("bad.mprog");
    std::fs::write(&bad, "length 2s\nhead.q > 1 m\n").unwrap();
    say(&mut s, &format!(":load {}", good.display()));
    let out = fails(&mut s, &format!(":load {}", bad.display()));
    assert!(
        out.contains("unknown_component") && out.contains("not loaded"),
        "{out}"
    );
    assert_eq!(s.source(), "length 2s\nhead.y > 1 m\n");
    let npy = dir.path().join("walk.npy");
    mprog::formats::write_motion(&npy, &[walk()], &mprog::formats::Meta::new()).unwrap();
    assert!(say(&mut s, &format!(":motion {}", npy.display())).contains("40 frames"));
    let png = dir.path().join("walk.png");
    say(&mut s, &format!(":render {}", png.display()));
    assert!(std::fs::metadata(&png).unwrap().len() > 1000);
    assert!(fails(&mut s, ":render out.txt").contains("out.txt"));
}

#[test]
fn people_must_match_the_motion() {
    let mut s = session();
    say(&mut s, "people a \"a person\", b \"another\"");
    let out = fails(&mut s, ":eval a.head.y");
    assert!(
        out.contains("2 person(s)") && out.contains("has 1"),
        "{out}"
    );
}

#[test]
fn commands_report_usage() {
    let mut s = session();
    assert!(fails(&mut s, ":nope").contains(":help"));
    assert!(say(&mut s, ":help").contains(":grad STATEMENT"));
    assert!(say(&mut s, ":help eval").contains(":eval EXPR"));
    // The solvers and their knobs come from the registry.
    let run = say(&mut s, ":help run");
    assert!(
        run.contains("lbfgs:") && run.contains("paper=0") && run.contains("k_late=200"),
        "{run}"
    );
    assert!(s.handle(":quit").quit);
}

#[test]
fn run_solves_the_session_program_with_the_shipped_model() {
    let mut s = Session::new(Some(mprog::model::weights::default_model_dir()));
    say(&mut s, "prompt \"a person walks forward\"");
    say(&mut s, "length 1s");
    say(&mut s, "at end { pelvis.z > 1 m }");
    // A short chain keeps the test quick; guide with 10 steps still moves the pelvis.
    let out = say(&mut s, ":run guide 3 steps=10 k_late=20 late_steps=2");
    assert!(out.contains("guide in") && out.contains("line 3"), "{out}");
    let score = say(&mut s, ":eval pelvis.z");
    assert!(score.contains("max"), "{score}");
    assert!(fails(&mut s, ":run warp").contains("unknown solver"));
    assert!(fails(&mut s, ":run latent 1 k_late=3").contains("ddim_steps"));
    let mut empty = Session::new(None);
    assert!(fails(&mut empty, ":run").contains("length"));
}

#[test]
fn view_writes_the_page_with_the_programs_timeline_and_geometry() {
    let dir = tempfile::tempdir().unwrap();
    let page = dir.path().join("walk.html");
    let mut s = session();
    say(&mut s, "length 2s");
    say(&mut s, "distToPlane(r_hand, [0, 0, 2], [0, 0, 1]) < 5 cm");
    let reply = say(&mut s, &format!(":view {}", page.display()));
    assert!(reply.contains("wrote"), "{reply}");
    let html = std::fs::read_to_string(&page).unwrap();
    assert!(
        html.contains("\"statement_errors\""),
        "no timeline in the page"
    );
    assert!(html.contains("\"vertical_plane\""), "the wall is not drawn");
    assert!(
        html.contains("distToPlane(r_hand"),
        "the statement's label is on the page"
    );
    fails(&mut s, ":view");
}

#[test]
fn save_writes_the_program_and_the_motion_with_its_scores() {
    let dir = tempfile::tempdir().unwrap();
    let mut s = session();
    say(&mut s, "length 2s");
    say(&mut s, "head.y > 1.5 m");
    let prog = dir.path().join("typed.mprog");
    say(&mut s, &format!(":save {}", prog.display()));
    let text = std::fs::read_to_string(&prog).unwrap();
    assert_eq!(text, "length 2s\nhead.y > 1.5 m\n");
    // The saved program checks as a file, exactly as typed.
    compile(&text, "typed.mprog", &[]).unwrap();

    let json = dir.path().join("walk.json");
    say(&mut s, &format!(":w {}", json.display()));
    let doc: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    assert_eq!(doc["people"][0]["frames"].as_array().unwrap().len(), F);
    assert_eq!(doc["meta"]["origin"], "walk");
    assert!(
        doc["meta"]["statement_errors"].is_array(),
        "{}",
        doc["meta"]
    );
    let npy = dir.path().join("walk.npy");
    say(&mut s, &format!(":save {}", npy.display()));
    assert!(dir.path().join("walk.meta.json").exists());

    // Every output kind of the table, pictures included.
    let gif = dir.path().join("x.gif");
    assert!(say(&mut s, &format!(":save {}", gif.display())).contains("wrote"));
    assert!(std::fs::metadata(&gif).unwrap().len() > 1000);
    let txt = fails(
        &mut s,
        &format!(":save {}", dir.path().join("x.txt").display()),
    );
    assert!(txt.contains(".bvh") && txt.contains(".mprog"), "{txt}");
    assert!(fails(&mut Session::new(None), ":save p.mprog").contains("empty"));
}

/// A take longer than the model makes (12 s) is edited in windows, as `mprog run` does.
#[test]
fn run_edits_a_long_take_in_windows() {
    let dir = tempfile::tempdir().unwrap();
    let take = dir.path().join("long.json");
    let long = common::synthetic_walk(241);
    mprog::formats::write_motion(
        &take,
        std::slice::from_ref(&long),
        &mprog::formats::Meta::new(),
    )
    .unwrap();
    let mut s = Session::new(Some(mprog::model::weights::default_model_dir()));
    say(&mut s, "prompt \"a person walks forward\"");
    say(&mut s, "length 12s");
    say(&mut s, "at end { head.y > 1 m }");
    say(&mut s, &format!(":motion {}", take.display()));
    let out = say(
        &mut s,
        ":run guide 2 steps=10 k_late=20 late_steps=2 strength=0.5",
    );
    assert!(
        out.contains("at strength 0.5") && out.contains("240 frames"),
        "{out}"
    );
}

#[test]
fn run_edits_the_take_loaded_with_motion() {
    let dir = tempfile::tempdir().unwrap();
    let take = dir.path().join("take.json");
    mprog::formats::write_motion(&take, &[walk()], &mprog::formats::Meta::new()).unwrap();
    let mut s = Session::new(Some(mprog::model::weights::default_model_dir()));
    say(&mut s, "prompt \"a person walks forward\"");
    say(&mut s, "length 2s");
    say(&mut s, "head.y > 1 m");
    assert!(fails(&mut s, ":run plain strength=0").contains(":motion"));
    let loaded = say(&mut s, &format!(":motion {}", take.display()));
    assert!(loaded.contains("edits this take"), "{loaded}");
    // Strength 0 returns the take, retargeted: 40 frames give 39, where the take stood.
    let out = say(&mut s, ":run plain strength=0");
    assert!(
        out.contains("editing") && out.contains("39 frames"),
        "{out}"
    );
    let want = mprog::solve::Take::encode(&[walk()])
        .unwrap()
        .motions()
        .unwrap();
    let got = &s.motion().unwrap().people[0];
    for (a, b) in got.frames.iter().zip(&want[0].frames) {
        assert!(a.iter().zip(b).all(|(p, q)| (*p - *q).length() < 1e-4));
    }
    assert!(fails(&mut s, ":run plain strength=1.5").contains("outside 0…1"));
    assert!(fails(&mut s, ":run ik strength=0.5").contains("cannot edit a take"));
    // A short edited chain runs, and `:gen` would end the editing.
    let out = say(
        &mut s,
        ":run guide 2 steps=10 k_late=20 late_steps=2 strength=0.5",
    );
    assert!(out.contains("at strength 0.5"), "{out}");
    // The saved edit names the take, its hash and the strength.
    let saved = dir.path().join("edited.json");
    say(&mut s, &format!(":save {}", saved.display()));
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&saved).unwrap()).unwrap();
    let meta = &json["meta"];
    let hash = mprog::fsutil::sha256_hex(&take).unwrap();
    assert_eq!(meta["take"], take.display().to_string(), "{meta}");
    assert_eq!(meta["take_sha256"], hash, "{meta}");
    assert_eq!(meta["strength"], 0.5, "{meta}");
    assert_eq!(meta["keep_path"], true, "{meta}");
}

#[test]
fn rig_puts_saved_motions_on_a_users_character() {
    let dir = tempfile::tempdir().unwrap();
    let rig = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/tests/fixtures/rigs/mixamo_tall.bvh"
    );
    let mut s = session();
    assert!(say(&mut s, ":rig").contains("no rig"));
    assert!(say(&mut s, &format!(":rig {rig}")).contains("65 joints"));
    assert!(say(&mut s, ":rig").contains("mixamo_tall.bvh"));
    let bvh = dir.path().join("on_rig.bvh");
    say(&mut s, &format!(":save {}", bvh.display()));
    let text = std::fs::read_to_string(&bvh).unwrap();
    assert!(text.contains("JOINT LeftHandIndex1"), "the rig's joints");
    say(&mut s, ":rig -");
    say(&mut s, &format!(":save {}", bvh.display()));
    assert!(
        std::fs::read_to_string(&bvh)
            .unwrap()
            .contains("JOINT left_wrist")
    );
    let bad = fails(&mut s, ":rig nowhere.bvh");
    assert!(bad.contains("nowhere.bvh"), "{bad}");
    // A rig whose leg names no table knows, with its mapping file; a skinned .glb.
    let german = std::fs::read_to_string(rig)
        .unwrap()
        .replace("LeftUpLeg", "Oberschenkel_L")
        .replace("RightUpLeg", "Oberschenkel_R");
    let (de, map) = (dir.path().join("de rig.bvh"), dir.path().join("map.toml"));
    std::fs::write(&de, german).unwrap();
    std::fs::write(
        &map,
        "left_hip = \"Oberschenkel_L\"\nright_hip = \"Oberschenkel_R\"\n",
    )
    .unwrap();
    let bad = fails(&mut s, &format!(":rig \"{}\"", de.display()));
    assert!(bad.contains("left_hip"), "{bad}");
    let ok = say(
        &mut s,
        &format!(":rig \"{}\" {}", de.display(), map.display()),
    );
    assert!(ok.contains("and the mapping file"), "{ok}");
    let glb = rig.replace(".bvh", ".glb");
    assert!(say(&mut s, &format!(":rig {glb}")).contains(".glb outputs are this file"));
    let out = dir.path().join("on_rig.glb");
    say(&mut s, &format!(":save {}", out.display()));
    let bytes = std::fs::read(&out).unwrap();
    let names: Vec<String> = mprog::formats::gltf::read::node_positions_at(&bytes, 0)
        .unwrap()
        .into_iter()
        .map(|(n, _)| n)
        .collect();
    assert!(
        names.iter().any(|n| n == "Body"),
        "the user's mesh node is kept"
    );
    assert!(fails(&mut s, ":rig a.bvh b.toml c").contains("optionally its mapping file"));
}
