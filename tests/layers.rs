//! The layers of ARCHITECTURE.md hold: every `crate::` path from one top-level module of
//! the library into another (in `use` lines and inline, tests included) is an edge the
//! page's table allows, and every top-level module has a row. The table is read from the
//! page itself, so the page and this test cannot disagree.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

/// The table between the `layers` markers: module → modules it may use.
fn allowed_edges(page: &str) -> BTreeMap<String, BTreeSet<String>> {
    let start = page
        .find("<!-- layers:start -->")
        .expect("layers:start marker");
    let end = page.find("<!-- layers:end -->").expect("layers:end marker");
    let mut table = BTreeMap::new();
    for line in page[start..end].lines().filter(|l| l.starts_with("| `")) {
        let cells: Vec<&str> = line.split('|').map(str::trim).collect();
        let names = |cell: &str| -> BTreeSet<String> {
            cell.split(',')
                .map(|n| n.trim().trim_matches('`').to_string())
                .filter(|n| !n.is_empty())
                .collect()
        };
        let module = cells[1].trim_matches('`').to_string();
        assert!(
            table.insert(module.clone(), names(cells[2])).is_none(),
            "{module} has two rows"
        );
    }
    table
}

/// The library's top-level modules, from `pub mod` / `mod` lines of `src/lib.rs`.
fn modules() -> BTreeSet<String> {
    let lib = std::fs::read_to_string(root().join("src/lib.rs")).unwrap();
    lib.lines()
        .filter_map(|l| {
            let l = l.trim();
            l.strip_prefix("pub mod ")
                .or_else(|| l.strip_prefix("mod "))
                .map(|r| r.trim_end_matches(';').trim().to_string())
        })
        .collect()
}

/// The first identifier at the start of `s`.
fn ident(s: &str) -> &str {
    let end = s
        .find(|c: char| !(c.is_ascii_alphanumeric() || c == '_'))
        .unwrap_or(s.len());
    &s[..end]
}

/// Top-level modules named by `crate::` paths in `code` (comments removed), including
/// each first segment of a grouped `crate::{a::b, c}`.
fn crate_paths(code: &str) -> BTreeSet<String> {
    let code: String = code
        .lines()
        .map(|l| l.split("//").next().unwrap_or(""))
        .collect::<Vec<_>>()
        .join("\n");
    let mut found = BTreeSet::new();
    for (at, _) in code.match_indices("crate::") {
        let rest = &code[at + "crate::".len()..];
        if let Some(group) = rest.strip_prefix('{') {
            let (mut depth, mut item_start) = (1, true);
            for (i, c) in group.char_indices() {
                match c {
                    '{' => depth += 1,
                    '}' if depth == 1 => break,
                    '}' => depth -= 1,
                    ',' if depth == 1 => item_start = true,
                    c if c.is_whitespace() => {}
                    _ if item_start && depth == 1 => {
                        found.insert(ident(&group[i..]).to_string());
                        item_start = false;
                    }
                    _ => {}
                }
            }
        } else {
            found.insert(ident(rest).to_string());
        }
    }
    found
}

fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        if path.is_dir() {
            rust_files(&path, out);
        } else if path.extension().is_some_and(|e| e == "rs") {
            out.push(path);
        }
    }
}

#[test]
fn every_edge_between_modules_is_one_architecture_md_allows() {
    let page = std::fs::read_to_string(root().join("ARCHITECTURE.md")).unwrap();
    let table = allowed_edges(&page);
    let modules = modules();
    let missing: Vec<_> = modules.iter().filter(|m| !table.contains_key(*m)).collect();
    assert!(
        missing.is_empty(),
        "modules with no row in ARCHITECTURE.md: {missing:?}"
    );
    let stale: Vec<_> = table.keys().filter(|m| !modules.contains(*m)).collect();
    assert!(
        stale.is_empty(),
        "rows for modules that do not exist: {stale:?}"
    );

    let src = root().join("src");
    let mut files = Vec::new();
    rust_files(&src, &mut files);
    let mut bad = Vec::new();
    let mut used: BTreeSet<(String, String)> = BTreeSet::new();
    for file in files {
        let rel = file.strip_prefix(&src).unwrap();
        let top = rel.iter().next().unwrap().to_string_lossy();
        let top = top.trim_end_matches(".rs").to_string();
        if !modules.contains(&top) {
            continue; // lib.rs, main.rs and the CLI may use everything
        }
        let code = std::fs::read_to_string(&file).unwrap();
        for target in crate_paths(&code) {
            if target == top || !modules.contains(&target) {
                continue;
            }
            used.insert((top.clone(), target.clone()));
            if !table[&top].contains(&target) {
                bad.push(format!("{}: {top} -> {target}", rel.display()));
            }
        }
    }
    assert!(
        bad.is_empty(),
        "edges ARCHITECTURE.md does not allow (change the code, or the table on purpose):\n{}",
        bad.join("\n")
    );
    // The table is a map of the code, not a wish list: every allowed edge is used.
    let unused: Vec<String> = table
        .iter()
        .flat_map(|(m, to)| to.iter().map(move |t| (m.clone(), t.clone())))
        .filter(|e| !used.contains(e))
        .map(|(m, t)| format!("{m} -> {t}"))
        .collect();
    assert!(unused.is_empty(), "allowed edges no code uses: {unused:?}");
}

#[test]
fn crate_paths_are_found_in_use_lines_groups_and_inline_paths() {
    let code = "use crate::a::X;\nuse crate::{b::{Y, Z}, c};\nlet v = crate::d::f(); // crate::e\n";
    let found: Vec<String> = crate_paths(code).into_iter().collect();
    assert_eq!(found, ["a", "b", "c", "d"]);
    let page = "<!-- layers:start -->\n| module | may use |\n| --- | --- |\n| `a` | `b`, `c` |\n| `b` | |\n<!-- layers:end -->";
    let table = allowed_edges(page);
    assert_eq!(table["a"].len(), 2);
    assert!(table["b"].is_empty());
}
