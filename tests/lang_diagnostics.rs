//! Diagnostic goldens: every `tests/diagnostics/*.mprog` is a wrong program whose first
//! line names the codes it must produce (`# expect: mprog::unknown_joint, …`); the full
//! plain-text report and the JSON form are pinned as insta snapshots. The reports are what
//! `mprog check` prints with the shipped model's pose coverage (`mprog::unseen_pose`;
//! the prompt warnings need the sentence model and are left out).

use mprog::coverage::Coverage;
use mprog::lang::{Diagnostics, check_source, with_unseen_poses};
use std::sync::OnceLock;

/// The coverage set built into the binary (the shipped bundle's).
fn coverage() -> &'static Coverage {
    static SET: OnceLock<Coverage> = OnceLock::new();
    SET.get_or_init(Coverage::builtin)
}

/// What `mprog check` reports for `src` (without the prompt warnings).
fn check(src: &str, name: &str, overrides: &[(String, f64)]) -> Diagnostics {
    with_unseen_poses(
        check_source(src, name, overrides),
        src,
        overrides,
        coverage(),
    )
}

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
        let diags = check(&src, &name, &[]);
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
fn poses_the_training_data_has_are_not_flagged() {
    // The example, the pelvis under 0.2 m with the head above 0.65 m, is in the
    // data (sitting up on the way down to lie on the floor), as are a squat and lying down.
    for body in [
        "during end - 0.5s..end + 1 { pelvis.y < 20 cm\n head.y > 65 cm }",
        "during 2s..3s { pelvis.y < 50 cm\n head.y > 90 cm }",
        "during end - 1s..end + 1 { pelvis.y < 25 cm\n head.y < 30 cm }",
    ] {
        let src = format!("length 6s\n{body}\n");
        let d = check(&src, "x.mprog", &[]);
        assert!(
            !d.items.iter().any(|i| i.code == "mprog::unseen_pose"),
            "{body}:\n{}",
            d.render_plain()
        );
    }
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
