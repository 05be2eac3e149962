//! Every parse error names its line: hierarchy, motion section, truncation, binary input.

use super::super::*;
use super::{chain, parse};

/// Parses `text` and returns the error's line and kind.
fn error_of(text: &str) -> (Option<usize>, BvhErrorKind) {
    let e = parse(text).unwrap_err();
    assert!(e.to_string().starts_with("t.bvh:"), "{e}");
    (e.line, e.kind)
}

#[test]
fn errors_name_the_line() {
    let good = chain("3 Zrotation Xrotation Yrotation", "0 0 0 0 0 0 0 0 0");
    let lines: Vec<&str> = good.lines().collect();
    let edit = |line: usize, new: &str| -> String {
        let mut l = lines.clone();
        l[line - 1] = new;
        l.join("\n")
    };
    use BvhErrorKind as K;
    // Missing CHANNELS line (line 9) on joint Mid (line 6).
    let (line, kind) = error_of(&edit(9, ""));
    assert_eq!((line, kind), (Some(6), K::MissingChannels("Mid".into())));
    // Fewer channel names than declared.
    let (line, kind) = error_of(&edit(9, "CHANNELS 3 Zrotation Xrotation"));
    assert_eq!(
        (line, kind),
        (
            Some(9),
            K::ChannelCount {
                declared: 3,
                found: 2
            }
        )
    );
    assert_eq!(
        error_of(&edit(9, "CHANNELS 2 Zrotation Wrotation")),
        (Some(9), K::UnknownChannel("Wrotation".into()))
    );
    assert_eq!(
        error_of(&edit(8, "OFFSET 0 ten 0")),
        (Some(8), K::BadNumber("ten".into()))
    );
    assert_eq!(
        error_of(&edit(8, "OFFSET 0 nan 0")),
        (Some(8), K::NonFinite("nan".into()))
    );
    assert_eq!(
        error_of(&edit(8, "")),
        (Some(6), K::MissingOffset("Mid".into()))
    );
    assert_eq!(
        error_of(&edit(10, "Bone Site")),
        (Some(10), K::UnknownKeyword("Bone".into()))
    );
    assert_eq!(
        error_of(&edit(1, "HIERARCHIE")),
        (Some(1), K::MissingHierarchy("HIERARCHIE".into()))
    );
    // Motion section.
    let (line, kind) = error_of(&edit(19, "0 0 0 0 0 0 0 0"));
    assert_eq!(
        (line, kind),
        (
            Some(19),
            K::ValueCount {
                found: 8,
                expected: 9
            }
        )
    );
    assert_eq!(
        error_of(&edit(19, "0 0 0 0 0 0 0 NaN 0")),
        (Some(19), K::NonFinite("NaN".into()))
    );
    assert_eq!(
        error_of(&edit(19, "0 0 0 0 0 0 0 inf 0")),
        (Some(19), K::NonFinite("inf".into()))
    );
    assert_eq!(error_of(&edit(17, "Frames: 0")), (Some(17), K::ZeroFrames));
    assert_eq!(
        error_of(&edit(17, "Frames: two")),
        (Some(17), K::BadFrameCount("two".into()))
    );
    assert_eq!(
        error_of(&edit(17, "Frame: 1")),
        (Some(17), K::MissingHeader("Frames"))
    );
    assert_eq!(
        error_of(&edit(18, "Frame Time: 0")),
        (Some(18), K::BadFrameTime("0".into()))
    );
    assert_eq!(
        error_of(&edit(17, "Frames: 3")),
        (
            Some(19),
            K::MissingFrames {
                found: 1,
                declared: 3
            }
        )
    );
    let extra = format!("{good}0 0 0 0 0 0 0 0 0\n");
    assert_eq!(error_of(&extra), (Some(20), K::ExtraFrames { declared: 1 }));
    let (line, kind) = error_of(&edit(17, "Frames: 100000000"));
    assert_eq!(line, Some(17));
    assert!(
        matches!(
            kind,
            K::TooBig {
                count: 900_000_000,
                ..
            }
        ),
        "{kind:?}"
    );
}

#[test]
fn truncated_files_are_errors() {
    let good = chain("3 Zrotation Xrotation Yrotation", "0 0 0 0 0 0 0 0 0");
    let lines: Vec<&str> = good.lines().collect();
    // Cut inside the hierarchy: after Mid's CHANNELS line (line 9).
    let (line, kind) = error_of(&lines[..9].join("\n"));
    assert_eq!(
        (line, kind),
        (Some(9), BvhErrorKind::UnclosedJoint("Mid".into()))
    );
    // Cut after the hierarchy.
    assert_eq!(
        error_of(&lines[..15].join("\n")),
        (Some(15), BvhErrorKind::MissingMotion)
    );
    // Cut inside the MOTION header.
    assert_eq!(
        error_of(&lines[..16].join("\n")),
        (Some(16), BvhErrorKind::MissingHeader("Frames"))
    );
    assert_eq!(
        error_of(&lines[..17].join("\n")),
        (Some(17), BvhErrorKind::MissingHeader("Frame Time"))
    );
    assert_eq!(
        error_of(""),
        (
            Some(1),
            BvhErrorKind::MissingHierarchy("end of file".into())
        )
    );
}

#[test]
fn binary_input_is_refused_through_the_entry_point() {
    let mut bytes = chain("1 Xrotation", "0 0 0 0 0 0 0").into_bytes();
    bytes.extend_from_slice(&[0, 159, 146, 150]);
    let e = import_bvh_bytes("b.bvh", &bytes, &BvhImportOptions::default()).unwrap_err();
    assert_eq!((e.line, e.kind), (Some(20), BvhErrorKind::Binary));
}
