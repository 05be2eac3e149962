//! Diagnostic goldens: every `tests/diagnostics/*.mprog` is a wrong program whose first
//! line names the codes it must produce (`# expect: mprog::unknown_joint, …`); the full
//! plain-text report and the JSON form are pinned as insta snapshots.

use mprog::lang::check_source;

#[test]
fn wrong_programs_report_expected_diagnostics() {
    insta::glob!("diagnostics/*.mprog", |path| {
        let src = std::fs::read_to_string(path).unwrap();
        let name = path.file_name().unwrap().to_string_lossy().to_string();
        let expected: Vec<&str> = src
            .lines()
            .next()
            .and_then(|l| l.strip_prefix("# expect:"))
            .expect("first line is `# expect: codes`")
            .split(',')
            .map(str::trim)
            .collect();
        let diags = check_source(&src, &name, &[]);
        for code in &expected {
            assert!(
                diags.items.iter().any(|d| d.code == *code),
                "{name}: expected {code}, got:\n{}",
                diags.render_plain()
            );
        }
        for d in &diags.items {
            assert!(d.help.is_some(), "{name}: {} has no hint", d.code);
        }
        insta::assert_snapshot!(diags.render_plain());
    });
}

#[test]
fn json_form_has_positions_and_hints() {
    let src = "length 4s\nalways { r_hnad.y > 1 m }\n";
    let diags = check_source(src, "x.mprog", &[]);
    let json = serde_json::to_value(diags.to_json()).unwrap();
    insta::assert_snapshot!(serde_json::to_string_pretty(&json).unwrap());
}

#[test]
fn overrides_are_checked() {
    let src = "length 4s\nparam diameter = 40 cm\nalways { dist(l_hand, r_hand) == diameter }\n";
    let ok = mprog::lang::compile(src, "x.mprog", &[("diameter".into(), 50.0)]).unwrap();
    assert!(
        (ok.params()[0].value[0] - 0.5).abs() < 1e-12,
        "override is in the default's unit"
    );
    let bad = check_source(src, "x.mprog", &[("diamter".into(), 0.5)]);
    assert!(bad.items.iter().any(|d| d.code == "mprog::unknown_param"
        && d.help.as_deref() == Some("did you mean `diameter`?")));
}
