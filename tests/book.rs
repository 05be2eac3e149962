//! The book cannot drift: every ```` ```mprog ```` block under `book/src` compiles
//! (`{{#include}}`s resolved), every ```` ```mprog,error CODE ```` block fails with that
//! code, every ```` ```mprog,repl ```` transcript replays through the REPL backend, the
//! generated pages equal what `mprog doc book` writes, and the LLM prompt's examples
//! compile.

use mprog::docgen::book::{pages, read_programs, summary_with_cookbook};
use mprog::docgen::markdown::{CodeBlock, code_blocks};
use mprog::docgen::prompt::{EXAMPLES, system_prompt};
use mprog::lang::{check_source, compile, with_unseen_poses};
use mprog::skeleton::{ALIASES, JOINT_NAMES};
use std::path::{Path, PathBuf};

/// The coverage set built into the binary (the shipped model's), for
/// `mprog::unseen_pose` blocks.
fn coverage() -> &'static mprog::coverage::Coverage {
    static SET: std::sync::OnceLock<mprog::coverage::Coverage> = std::sync::OnceLock::new();
    SET.get_or_init(mprog::coverage::Coverage::builtin)
}

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn book_pages() -> Vec<PathBuf> {
    fn walk(dir: &Path, out: &mut Vec<PathBuf>) {
        for e in std::fs::read_dir(dir).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                walk(&p, out);
            } else if p.extension().is_some_and(|x| x == "md") {
                out.push(p);
            }
        }
    }
    let mut out = Vec::new();
    walk(&root().join("book/src"), &mut out);
    out.sort();
    out
}

/// The block's text with mdBook `{{#include path}}` lines replaced by the file.
fn resolve_includes(text: &str, page: &Path) -> String {
    text.lines()
        .map(|l| {
            match l
                .trim()
                .strip_prefix("{{#include ")
                .and_then(|r| r.strip_suffix("}}"))
            {
                Some(rel) => {
                    let path = page.parent().unwrap().join(rel.trim());
                    std::fs::read_to_string(&path).unwrap_or_else(|e| {
                        panic!("{}: include {}: {e}", page.display(), path.display())
                    })
                }
                None => format!("{l}\n"),
            }
        })
        .collect()
}

fn check_block(page: &Path, b: &CodeBlock) -> Result<(), String> {
    let what = format!(
        "{}:{}",
        page.strip_prefix(root()).unwrap_or(page).display(),
        b.line
    );
    let src = resolve_includes(&b.text, page);
    match b.attrs.first().map(String::as_str) {
        None => compile(&src, &what, &[])
            .map(|_| ())
            .map_err(|d| format!("{what}: block does not compile:\n{}", d.render_plain())),
        // `mprog,error CODE`: the block fails with CODE; `mprog,warning CODE`: it compiles
        // and warns with CODE.
        Some(kind @ ("error" | "warning")) => {
            let code = b
                .attrs
                .get(1)
                .ok_or(format!("{what}: `mprog,{kind}` names no code"))?;
            // As `mprog check` reports it with the shipped model's pose coverage.
            let d = with_unseen_poses(check_source(&src, &what, &[]), &src, &[], coverage());
            if d.has_errors() == (kind == "error") && d.items.iter().any(|i| i.code == code) {
                Ok(())
            } else {
                Err(format!(
                    "{what}: expected {kind} {code}, got:\n{}",
                    d.render_plain()
                ))
            }
        }
        Some("repl") => replay(&what, &src),
        Some(other) => Err(format!("{what}: unknown block attribute `{other}`")),
    }
}

/// A transcript: `mprog> input` lines (continuations start with `  ...> `) and the
/// expected output. A line ending in `…` matches any line starting with the rest; a
/// last line of just `…` matches whatever follows.
fn replay(what: &str, transcript: &str) -> Result<(), String> {
    let mut session = mprog::repl::Session::new(None);
    let mut lines = transcript.lines().peekable();
    while let Some(line) = lines.next() {
        let Some(input) = line.strip_prefix("mprog> ") else {
            return Err(format!("{what}: expected `mprog> `, found {line:?}"));
        };
        let mut input = input.to_string();
        while let Some(more) = lines.peek().and_then(|l| l.strip_prefix("  ...> ")) {
            input.push('\n');
            input.push_str(more);
            lines.next();
        }
        let mut expected = Vec::new();
        while let Some(l) = lines.peek().filter(|l| !l.starts_with("mprog> ")) {
            expected.push(l.to_string());
            lines.next();
        }
        // Tests run in the package root, like a reader of the book in a checkout.
        let got = session.handle(&input).render(false);
        let got: Vec<&str> = got.lines().collect();
        // A last expected line of just `…` matches the rest of the output.
        let open_end = expected.last().is_some_and(|l| l.trim() == "…");
        let fixed = if open_end {
            &expected[..expected.len() - 1]
        } else {
            &expected[..]
        };
        let ok = (got.len() == fixed.len() || (open_end && got.len() >= fixed.len()))
            && got
                .iter()
                .zip(fixed)
                .all(|(g, e)| match e.strip_suffix('…') {
                    Some(prefix) => g.starts_with(prefix),
                    None => g.trim_end() == e.trim_end(),
                });
        if !ok {
            return Err(format!(
                "{what}: `{input}` printed\n{}\nexpected\n{}",
                got.join("\n"),
                expected.join("\n")
            ));
        }
    }
    Ok(())
}

#[test]
fn every_mprog_block_in_the_book_checks() {
    let mut failures = Vec::new();
    let mut count = 0;
    for page in book_pages() {
        let md = std::fs::read_to_string(&page).unwrap();
        for b in code_blocks(&md).into_iter().filter(|b| b.lang == "mprog") {
            count += 1;
            if let Err(e) = check_block(&page, &b) {
                failures.push(e);
            }
        }
    }
    assert!(count >= 60, "only {count} mprog blocks found in book/src");
    assert!(failures.is_empty(), "{}", failures.join("\n\n"));
}

#[test]
fn generated_pages_are_up_to_date() {
    let programs = read_programs(&root().join("programs")).unwrap();
    let src = root().join("book/src");
    let mut stale = Vec::new();
    for (rel, text) in pages(&programs, &src, &mprog::model::weights::shipped_actions()) {
        if std::fs::read_to_string(src.join(&rel)).ok().as_deref() != Some(text.as_str()) {
            stale.push(rel.display().to_string());
        }
    }
    let summary = std::fs::read_to_string(src.join("SUMMARY.md")).unwrap();
    if summary_with_cookbook(&summary, &programs).as_deref() != Some(summary.as_str()) {
        stale.push("SUMMARY.md".into());
    }
    assert!(
        stale.is_empty(),
        "stale book pages (run `cargo run -- doc book`): {stale:?}"
    );
}

#[test]
fn every_summary_link_exists() {
    let src = root().join("book/src");
    let summary = std::fs::read_to_string(src.join("SUMMARY.md")).unwrap();
    for part in summary.split("](").skip(1) {
        let link = part.split(')').next().unwrap();
        assert!(
            src.join(link).exists(),
            "SUMMARY.md links to missing {link}"
        );
    }
}

#[test]
fn prompt_examples_compile_and_cover_the_library() {
    let prompt = system_prompt();
    let blocks: Vec<CodeBlock> = code_blocks(&prompt)
        .into_iter()
        .filter(|b| b.lang == "mprog")
        .collect();
    assert_eq!(
        blocks.len(),
        EXAMPLES.len() + 2,
        "the language sketch, the timeline and the worked examples"
    );
    assert_eq!(EXAMPLES.len(), 7);
    for b in &blocks {
        let diags = check_source(&b.text, "prompt", &[]);
        assert!(
            !diags.has_errors(),
            "prompt block at line {}:\n{}\n{}",
            b.line,
            b.text,
            diags.render_plain()
        );
        assert!(
            diags.items.is_empty(),
            "prompt block at line {} has warnings:\n{}",
            b.line,
            diags.render_plain()
        );
    }
    for name in JOINT_NAMES.iter().chain(ALIASES.iter().map(|(a, _)| a)) {
        assert!(
            prompt.contains(&format!("`{name}`")),
            "prompt lacks joint {name}"
        );
    }
    for d in mprog::lang::stdlib::docs() {
        assert!(
            prompt.contains(&d.signature),
            "prompt lacks {}",
            d.signature
        );
    }
    for b in mprog::lang::check::builtins::BUILTINS {
        assert!(prompt.contains(b.signature), "prompt lacks {}", b.signature);
    }
    // The worked examples are new tasks, not copies of programs/.
    for p in read_programs(&root().join("programs")).unwrap() {
        for (_, ex) in EXAMPLES {
            assert_ne!(p.text.trim(), ex.trim(), "{} is a worked example", p.file);
        }
    }
}

#[test]
fn every_diagnostic_code_is_on_the_diagnostics_page() {
    let page = std::fs::read_to_string(root().join("book/src/reference/diagnostics.md")).unwrap();
    let missing: Vec<&str> = mprog::lang::codes::ALL
        .iter()
        .map(|(code, _)| *code)
        .filter(|code| !page.contains(&format!("`{code}`")))
        .collect();
    assert!(
        missing.is_empty(),
        "codes missing from book/src/reference/diagnostics.md: {missing:?}"
    );
}
