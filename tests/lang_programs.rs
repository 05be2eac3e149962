//! The program corpus and the library: every `programs/*.mprog` checks without warnings
//! and evaluates to finite errors and gradients; every library file parses cleanly and
//! every documented example compiles; mutated programs never panic the pipeline.

mod lang_common;

use lang_common::*;
use mprog::lang::{check_source, compile, stdlib};
use rand::{Rng, SeedableRng};
use std::path::PathBuf;

fn programs() -> Vec<(String, String)> {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("programs");
    let mut out: Vec<(String, String)> = std::fs::read_dir(dir)
        .unwrap()
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x == "mprog"))
        .map(|p| {
            (
                p.file_name().unwrap().to_string_lossy().to_string(),
                std::fs::read_to_string(&p).unwrap(),
            )
        })
        .collect();
    out.sort();
    out
}

#[test]
fn every_program_checks_and_evaluates() {
    let all = programs();
    assert!(
        all.len() >= 19,
        "expected the PMG, Fig. 1 and InterControl programs"
    );
    for (name, src) in all {
        let prog = match compile(&src, &name, &[]) {
            Ok(p) => p,
            Err(d) => panic!("{name} does not check:\n{}", d.render_plain()),
        };
        assert_eq!(
            prog.warnings().items.len(),
            0,
            "{name}:\n{}",
            prog.warnings().render_plain()
        );
        assert!(!prog.statements().is_empty());
        let m = motion(prog.people().len(), prog.length());
        let (data, shape) = flat(&m);
        let (total, per) = eval(&prog, &data, shape);
        assert!(
            total.is_finite() && per.iter().all(|v| v.is_finite()),
            "{name}: {total} {per:?}"
        );
        let g = grad(&prog, &data, shape);
        assert!(
            g.iter().all(|v| v.is_finite()),
            "{name}: non-finite gradient"
        );
        assert!(
            g.iter().any(|v| *v != 0.0),
            "{name}: zero gradient everywhere"
        );
    }
}

#[test]
fn library_files_parse_cleanly_and_examples_compile() {
    for (file, text) in stdlib::FILES {
        let (_, diags) = mprog::lang::syntax::source_to_ast(text);
        assert!(diags.is_empty(), "{file}: {diags:?}");
    }
    let docs = stdlib::docs();
    assert!(docs.len() >= 25, "library has {} items", docs.len());
    for d in docs {
        let example = d
            .doc
            .lines()
            .find_map(|l| l.strip_prefix("Example: "))
            .unwrap_or_else(|| panic!("{} has no `Example:` line", d.name))
            .trim_matches('`');
        assert!(d.doc.lines().count() >= 2, "{} needs a description", d.name);
        let two = example.contains("a.") || example.contains("(a") || example.contains("a,");
        let header = if two {
            "length 4s\npeople a, b\n"
        } else {
            "length 4s\n"
        };
        let src = format!("{header}{example}\n");
        let diags = check_source(&src, &d.name, &[]);
        assert!(
            !diags.has_errors(),
            "example of {}:\n{}",
            d.name,
            diags.render_plain()
        );
    }
}

#[test]
fn builtin_examples_compile() {
    for b in mprog::lang::check::builtins::BUILTINS {
        let src = format!("length 4s\nalways {{ {} }}\n", b.example);
        let src = if b.example.starts_with("minimize") {
            format!("length 4s\n{}\n", b.example)
        } else {
            src
        };
        let diags = check_source(&src, b.name, &[]);
        assert!(
            !diags.has_errors(),
            "example of {}:\n{}",
            b.name,
            diags.render_plain()
        );
    }
}

fn mutate(src: &str, rng: &mut rand_chacha::ChaCha8Rng) -> String {
    const PIECES: &[&str] = &[
        "(",
        ")",
        "{",
        "}",
        "[",
        "]",
        ",",
        "@",
        ".",
        "..",
        "-",
        "not ",
        "and ",
        "==",
        "<",
        "%",
        "s",
        "m",
        "end",
        "head",
        "a.",
        "for j in joints ",
        "if ",
        "at ",
        "weight ",
        "def f(x) = f(x)\n",
        "\n",
        "1e308",
        "0",
        "/",
        "let x = x\n",
        "people a, b\n",
        "length 0 frames\n",
        "é",
        "\"",
    ];
    let mut s: Vec<char> = src.chars().collect();
    for _ in 0..rng.random_range(1..4) {
        let at = if s.is_empty() {
            0
        } else {
            rng.random_range(0..=s.len())
        };
        match rng.random_range(0..4) {
            0 if at < s.len() => {
                let end = (at + rng.random_range(1..8)).min(s.len());
                s.drain(at..end);
            }
            1 => {
                let piece = PIECES[rng.random_range(0..PIECES.len())];
                s.splice(at..at, piece.chars());
            }
            2 if !s.is_empty() => {
                let from = rng.random_range(0..s.len());
                let end = (from + rng.random_range(1..20)).min(s.len());
                let chunk: Vec<char> = s[from..end].to_vec();
                s.splice(at..at, chunk);
            }
            _ => s.truncate(at),
        }
    }
    s.into_iter().collect()
}

#[test]
fn mutated_programs_never_panic() {
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(7);
    let mut sources: Vec<String> = programs().into_iter().map(|(_, s)| s).collect();
    sources.extend(
        stdlib::FILES
            .iter()
            .map(|(_, t)| format!("length 2s\n{t}\nalways {{ head.y > 1 m }}\n")),
    );
    let mut compiled = 0;
    for round in 0..60 {
        for src in &sources {
            let m = mutate(src, &mut rng);
            let result = std::panic::catch_unwind(|| {
                let ok = compile(&m, "fuzz.mprog", &[]).ok();
                let _ = check_source(&m, "fuzz.mprog", &[("x".into(), 1.0)]).render_plain();
                ok.map(|p| {
                    let frames = p.length().min(40);
                    let mm = motion(p.people().len(), frames);
                    let (data, shape) = flat(&mm);
                    eval(&p, &data, shape).0
                })
            });
            match result {
                Ok(Some(_)) => compiled += 1,
                Ok(None) => {}
                Err(_) => panic!("round {round}: the pipeline panicked on:\n{m}"),
            }
        }
    }
    assert!(
        compiled > 50,
        "mutations should sometimes still compile ({compiled})"
    );
}

#[test]
fn adversarial_inputs_are_diagnosed() {
    let cases = [
        String::new(),
        "# only a comment\n".to_string(),
        format!("length 4s\nalways {{ head.y > {}1 }}\n", "- ".repeat(5000)),
        format!("length 4s\nalways {{ {}head.y > 1 }}\n", "not ".repeat(3000)),
        format!("length 4s\nalways {{ head.y > 1{} }}\n", " + 1".repeat(20000)),
        format!("length 4s\n{}head.y > 1 m{}\n", "always { ".repeat(500), " }".repeat(500)),
        "length 4s\nalways { head.y > 1e400 }\n".to_string(),
        "length 4s\nalways { head.y > 1 m }\n".repeat(3000),
        format!("length 4s\nalways {{ head.y > {} }}\n", "1".repeat(400)),
        "length 4s\ndef f(x) = g(x)\ndef g(x) = h(x)\ndef h(x) = f(x)\nalways { f(head.y) > 1 }\n".to_string(),
        "length 4s\nfor i in joints { for j in joints { for k in joints { always { dist(i, j) > dist(j, k) } } } }\n".to_string(),
        "length 4s\ndef a(x) = x + x\ndef b(x) = a(a(x))\ndef c(x) = b(b(b(x)))\ndef d(x) = c(c(c(x)))\ndef e(x) = d(d(d(x)))\nalways { e(head.y) > 1 }\n".to_string(),
        "length 4s\ndef a(x) = x + x + x + x + x + x + x + x\ndef b(x) = a(a(a(a(x))))\ndef c(x) = b(b(b(b(x))))\nalways { c(head.y) > 1 }\n".to_string(),
        "length 4s\nalways { \u{0}\u{feff}head.y > 1 }\n".to_string(),
    ];
    for src in &cases {
        let result = std::panic::catch_unwind(|| check_source(src, "adversarial.mprog", &[]));
        let diags = result.unwrap_or_else(|_| {
            panic!("panicked on input starting {:?}", &src[..src.len().min(80)])
        });
        assert!(
            diags.has_errors(),
            "expected a diagnostic for input starting {:?}",
            &src[..src.len().min(80)]
        );
    }
}

/// Every program scores a real motion-capture clip (HumanML3D's golden clip 012314, shipped
/// under `tests/fixtures/`, MIT): finite errors, and for people programs the clip is placed
/// for each person 1 m apart along x.
#[test]
fn every_program_scores_a_real_clip() {
    use burn::prelude::*;
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("tests/fixtures/humanml3d/new_joints_012314.npy");
    let clip = match mprog::formats::read_motion(&path).unwrap() {
        mprog::formats::LoadedMotion::Joints { people, .. } => people[0].motion.clone(),
        other => panic!("expected joints, got {other:?}"),
    };
    let dev = Device::flex();
    for (name, src) in programs() {
        let prog = compile(&src, &name, &[]).unwrap();
        let people = prog.people().len().max(1);
        let frames = clip.len();
        let mut data = Vec::with_capacity(people * frames * 66);
        for p in 0..people {
            for pose in &clip.frames {
                for j in pose {
                    data.extend_from_slice(&[j.x + p as f32, j.y, j.z]);
                }
            }
        }
        let joints =
            Tensor::<5>::from_data(TensorData::new(data, [1, people, frames, 22, 3]), &dev);
        let per = prog.try_evaluate(joints).unwrap().per_statement;
        let per = per.into_data().try_into_vec::<f32>().unwrap();
        assert!(per.iter().all(|v| v.is_finite()), "{name}: {per:?}");
    }
}
