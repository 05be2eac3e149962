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

#[test]
fn keyframe_pose_warns_only_for_end_postures() {
    let codes = |src: &str| -> Vec<&'static str> {
        let d = check_source(src, "x.mprog", &[]);
        assert!(!d.has_errors(), "{}", d.render_plain());
        let mut v: Vec<&str> = d
            .items
            .iter()
            .map(|i| i.code)
            .filter(|c| *c == "mprog::keyframe_pose")
            .collect();
        v.dedup();
        v
    };
    // Contacts, ground positions, facing, relative heights, the feet, a single hand,
    // keyframes inside the motion, and end states held over a window: no warning.
    let quiet = "length 4s\n\
        at end {\n\
            dist(r_hand, [-0.3, 1.1, 0.4]) < 5 cm\n\
            groundDist(pelvis, [0, 0, 1]) < 10 cm\n\
            dot(facing(), [0, 0, -1]) > 0.9\n\
            r_hand.y > head.y\n\
            footHeight(me) < 5 cm\n\
        }\n\
        at mid { pelvis.y < 60 cm }\n\
        during end - 0.5s..end + 1 { pelvis.y < 60 cm }\n";
    assert!(codes(quiet).is_empty());
    // The pelvis's height, or two hands' heights, on the last frame: a posture.
    assert_eq!(
        codes("length 4s\nat end { pelvis.y < 60 cm }\n"),
        ["mprog::keyframe_pose"]
    );
    assert_eq!(
        codes("length 4s\nat end { l_hand.y > 1.8 m\n r_hand.y > 1.8 m }\n"),
        ["mprog::keyframe_pose"]
    );
}
