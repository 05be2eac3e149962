//! Viewer page tests: the embedded data block is valid JSON that decodes back to the motion
//! (within 0.5 mm), the page references nothing on the network, its size stays small,
//! untrusted strings cannot break out of the page, and `meta` extras are checked.

use super::*;
use crate::render::Overlay;
use crate::render::test_motion::walk;
use glam::Vec3;
use serde_json::{Value, json};

const OPEN: &str = r#"<script type="application/json" id="mprog-data">"#;

fn two_walkers(frames: usize) -> Vec<Motion> {
    vec![
        walk(frames, 1.2, Vec3::ZERO, Vec3::Z),
        walk(frames, 1.0, Vec3::new(1.5, 0.0, 4.0), -Vec3::Z),
    ]
}

/// The data block of a page, parsed.
fn data_of(html: &str) -> Value {
    let start = html.find(OPEN).expect("data block") + OPEN.len();
    let end = start + html[start..].find("</script>").expect("end of data block");
    serde_json::from_str(&html[start..end]).expect("data block is valid JSON")
}

fn meta(v: Value) -> Meta {
    v.as_object().expect("object").clone()
}

#[test]
fn data_block_decodes_back_to_the_motion() {
    let people = two_walkers(50);
    let html = html_string(&people, &Meta::new(), "two walkers").unwrap();
    let d = data_of(&html);
    assert_eq!(d["format"], "mprog-view");
    assert_eq!(d["frames"], 50);
    assert_eq!(d["fps"], 20.0);
    assert_eq!(d["title"], "two walkers");
    assert_eq!(d["joint_names"][21], "right_wrist");
    let got = d["people"].as_array().unwrap();
    assert_eq!(got.len(), 2);
    for (p, m) in got.iter().zip(&people) {
        let mm: Vec<i64> = p["mm"]
            .as_array()
            .unwrap()
            .iter()
            .map(|v| v.as_i64().unwrap())
            .collect();
        assert_eq!(mm.len(), m.len() * 66);
        let mut acc = [0i64; 66];
        for (f, pose) in m.frames.iter().enumerate() {
            for k in 0..66 {
                acc[k] += mm[f * 66 + k];
                let want = pose[k / 3].to_array()[k % 3];
                let err = (acc[k] as f32 / 1000.0 - want).abs();
                assert!(
                    err <= 0.0005 + 1e-5,
                    "frame {f} coordinate {k}: off by {err}"
                );
            }
        }
    }
}

#[test]
fn page_is_self_contained() {
    let html = html_string(&two_walkers(30), &Meta::new(), "walk").unwrap();
    for needle in [
        "http://", "https://", "<link", " src=", "@import", "url(", "//cdn",
    ] {
        assert!(!html.contains(needle), "page contains {needle:?}");
    }
    assert!(html.starts_with("<!DOCTYPE html>"));
    assert!(html.contains("<canvas id=\"view\""));
    assert!(html.contains("<title>walk</title>"));
    // Exactly two scripts: the data block and the inline viewer.
    assert_eq!(html.matches("<script").count(), 2);
}

#[test]
fn size_grows_by_a_few_bytes_per_coordinate() {
    let short = html_string(&[walk(200, 1.2, Vec3::ZERO, Vec3::Z)], &Meta::new(), "w").unwrap();
    let long = html_string(&[walk(400, 1.2, Vec3::ZERO, Vec3::Z)], &Meta::new(), "w").unwrap();
    // The viewer itself is a few tens of kB.
    let fixed = short.len() - data_of(&short).to_string().len();
    assert!(fixed < 40_000, "page without data is {fixed} bytes");
    // 200 more frames × 66 coordinates: deltas of a walk take about 2–3 bytes each.
    let per_coordinate = (long.len() - short.len()) as f64 / (200.0 * 66.0);
    assert!(
        per_coordinate < 3.5,
        "{per_coordinate:.2} bytes per coordinate"
    );
    assert!(
        short.len() < 90_000,
        "10 s walk page is {} bytes",
        short.len()
    );
}

#[test]
fn hostile_title_and_labels_stay_text() {
    let title = "</script><script>alert(1)</script> & <b>";
    let m = meta(json!({"overlays": [
        {"kind": "point", "at": [0, 1, 2], "label": "</script><!--"}
    ]}));
    let html = html_string(&two_walkers(5), &m, title).unwrap();
    assert_eq!(
        html.matches("</script>").count(),
        2,
        "only the page's own script ends"
    );
    assert!(html.contains(
        "<title>&lt;/script&gt;&lt;script&gt;alert(1)&lt;/script&gt; &amp; &lt;b&gt;</title>"
    ));
    let d = data_of(&html);
    assert_eq!(d["title"], title);
    assert_eq!(d["overlays"][0]["label"], "</script><!--");
}

#[test]
fn extras_are_embedded_with_joint_indices() {
    let frames = 20;
    let values: Vec<Value> = (0..frames)
        .map(|f| {
            if f < 3 {
                Value::Null
            } else {
                json!(0.1 / f as f64)
            }
        })
        .collect();
    let m = meta(json!({
        "seed": 7,
        "overlays": [
            {"kind": "point", "at": [0, 1, 3], "label": "target"},
            {"kind": "segment", "from": [0, 0, 0], "to": [1, 0, 2]},
            {"kind": "vertical_plane", "point": [0, 0, 4], "normal": [0, 0, 1]},
            {"kind": "horizontal_plane", "height": 1.9},
            {"kind": "box", "min": [1, 0, 1], "max": [1.5, 0.5, 1.5]}
        ],
        "contacts": [
            {"label": "handshake", "a": {"person": 0, "joint": "right_wrist"},
             "b": {"person": 1, "joint": "r_hand"}, "frames": [5, 9]},
            {"a": {"person": 1, "joint": 15}, "b": {"person": 0, "joint": "head"}}
        ],
        "statement_errors": [
            {"label": "line 3: reach", "line": 3, "unit": "m", "tolerance": 0.02, "values": values}
        ]
    }));
    let d = data_of(&html_string(&two_walkers(frames), &m, "x").unwrap());
    assert_eq!(d["overlays"].as_array().unwrap().len(), 5);
    assert_eq!(d["overlays"][2]["kind"], "vertical_plane");
    assert_eq!(d["contacts"][0]["a"], json!([0, 21]));
    assert_eq!(d["contacts"][0]["b"], json!([1, 21]));
    assert_eq!(d["contacts"][0]["frames"], json!([5, 9]));
    assert_eq!(d["contacts"][1]["frames"], json!([0, frames - 1]));
    assert_eq!(d["contacts"][1]["label"], Value::Null);
    let s = &d["statement_errors"][0];
    assert_eq!(s["unit"], "m");
    assert_eq!(s["line"], 3);
    assert_eq!(s["values"][0], Value::Null);
    assert_eq!(s["values"][3], json!(0.03333));
    assert_eq!(s["values"].as_array().unwrap().len(), frames);
}

#[test]
fn overlays_round_trip_through_meta() {
    let overlays = vec![
        Overlay::Point {
            at: Vec3::new(0.0, 1.0, 3.0),
            label: Some("t".into()),
        },
        Overlay::Point {
            at: Vec3::ONE,
            label: None,
        },
        Overlay::Segment {
            from: Vec3::ZERO,
            to: Vec3::X,
        },
        Overlay::VerticalPlane {
            point: Vec3::Z,
            normal: Vec3::new(0.0, 0.0, -1.0),
        },
        Overlay::HorizontalPlane { height: 0.25 },
        Overlay::Box {
            min: Vec3::ZERO,
            max: Vec3::splat(0.5),
        },
    ];
    let mut m = Meta::new();
    m.insert("overlays".into(), overlays_to_meta(&overlays));
    assert_eq!(overlays_from_meta(&m).unwrap(), overlays);

    let contacts = vec![Contact {
        label: Some("hold".into()),
        a: JointOf {
            person: 0,
            joint: 20,
        },
        b: JointOf {
            person: 1,
            joint: 21,
        },
        frames: (2, 4),
    }];
    let errors = vec![StatementError {
        label: "line 1".into(),
        line: Some(1),
        unit: "m".into(),
        tolerance: None,
        values: vec![None, Some(0.5), Some(0.25), None, Some(0.0)],
    }];
    m.insert("contacts".into(), contacts_to_meta(&contacts));
    m.insert("statement_errors".into(), statement_errors_to_meta(&errors));
    let extras = extras_from_meta(&m, 2, 5).unwrap();
    assert_eq!(extras.contacts, contacts);
    assert_eq!(extras.statement_errors, errors);
}

#[test]
fn malformed_extras_name_the_entry() {
    let cases = [
        (
            json!({"overlays": {"kind": "point"}}),
            "meta.overlays: expected a list",
        ),
        (
            json!({"overlays": [{"kind": "point", "at": [0, 1, 2]}, {"kind": "sphere"}]}),
            "meta.overlays[1]: unknown variant `sphere`",
        ),
        (
            json!({"overlays": [{"kind": "point", "at": [0, 1, 2], "colour": "red"}]}),
            "meta.overlays[0]: unknown field `colour`",
        ),
        (
            json!({"overlays": [{"kind": "vertical_plane", "point": [0, 0, 0], "normal": [0, 1, 0]}]}),
            "horizontal",
        ),
        (
            json!({"overlays": [{"kind": "box", "min": [1, 0, 0], "max": [0, 1, 1]}]}),
            "is above `max`",
        ),
        (
            json!({"contacts": [{"a": {"person": 0, "joint": "left_wrist"}, "b": {"person": 2, "joint": "head"}}]}),
            "meta.contacts[0]: `b.person` is 2, but there are 2 people",
        ),
        (
            json!({"contacts": [{"a": {"person": 0, "joint": "elbow"}, "b": {"person": 1, "joint": "head"}}]}),
            "`a.joint` \"elbow\" is not a joint name",
        ),
        (
            json!({"contacts": [{"a": {"person": 0, "joint": 22}, "b": {"person": 1, "joint": 0}}]}),
            "`a.joint` 22 is out of range",
        ),
        (
            json!({"contacts": [{"a": {"person": 0, "joint": 0}, "b": {"person": 1, "joint": 0}, "frames": [5, 10]}]}),
            "past the last frame 9",
        ),
        (
            json!({"contacts": [{"a": {"person": 0, "joint": 0}, "b": {"person": 1, "joint": 0}, "frames": [5, 2]}]}),
            "ends before it starts",
        ),
        (
            json!({"statement_errors": [{"label": "x", "values": [1, 2]}]}),
            "meta.statement_errors[0]: `values` has 2 entries, but the motion has 10 frames",
        ),
        (
            json!({"statement_errors": [{"values": [0,0,0,0,0,0,0,0,0,0]}]}),
            "missing field `label`",
        ),
        (
            json!({"timeline": [[{"from": 4, "to": 4, "prompt": "x"}]]}),
            "meta.timeline[0]: span 4..4 is empty",
        ),
        (
            json!({"timeline": [[{"from": 0, "to": 5, "prompt": "x"}, {"from": 10, "to": 12, "prompt": "y"}]]}),
            "meta.timeline[0]: span 10..12 starts past the motion's 10 frames",
        ),
        (
            json!({"timeline": [[], [], []]}),
            "meta.timeline: 3 timelines for 2 people",
        ),
        (
            json!({"timeline": [{"from": 0, "to": 5, "prompt": "x"}]}),
            "meta.timeline[0]: invalid type",
        ),
    ];
    for (m, want) in cases {
        let err = html_string(&two_walkers(10), &meta(m.clone()), "x").unwrap_err();
        assert!(matches!(err, ViewError::BadMeta { .. }), "{m}: {err}");
        assert!(
            err.to_string().contains(want),
            "{m}: got {err}, want {want:?}"
        );
    }
}

#[test]
fn bad_motions_are_errors_and_write_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("v.html");
    let good = walk(5, 1.0, Vec3::ZERO, Vec3::Z);
    let mut nan = good.clone();
    nan.frames[3][7].y = f32::NAN;
    let mut slow = good.clone();
    slow.fps = 30.0;
    let cases: Vec<(Vec<Motion>, &str)> = vec![
        (vec![], "no people"),
        (
            vec![good.clone(), Motion::new(vec![])],
            "person 2 has no frames",
        ),
        (vec![nan], "non-finite positions at frame 3"),
        (vec![good.clone(), slow], "person 2 is at 30 fps"),
    ];
    for (people, want) in cases {
        let err = write_html(&people, &Meta::new(), "x", &path).unwrap_err();
        assert!(err.to_string().contains(want), "got {err}, want {want:?}");
        assert!(!path.exists());
    }
    write_html(std::slice::from_ref(&good), &Meta::new(), "ok", &path).unwrap();
    let written = std::fs::read_to_string(&path).unwrap();
    assert_eq!(written, html_string(&[good], &Meta::new(), "ok").unwrap());
}

#[test]
fn people_of_different_lengths_share_the_longest_timeline() {
    let people = vec![
        walk(30, 1.0, Vec3::ZERO, Vec3::Z),
        walk(12, 1.0, Vec3::X, Vec3::Z),
    ];
    let m = meta(json!({"statement_errors": [{"label": "x", "values": vec![0.0; 30]}]}));
    let d = data_of(&html_string(&people, &m, "x").unwrap());
    assert_eq!(d["frames"], 30);
    assert_eq!(d["people"][1]["frames"], 12);
}

#[test]
fn the_timeline_is_embedded_with_its_bar_and_prompt_line() {
    let people = two_walkers(60);
    let m = meta(json!({"timeline": [
        [{"from": 0, "to": 30, "prompt": "a person walks forward"},
         {"from": 25, "to": 80, "prompt": "a person sits down"}],
        []
    ]}));
    let html = html_string(&people, &m, "timeline").unwrap();
    let d = data_of(&html);
    // Cut to the motion's 60 frames; the second person has none.
    assert_eq!(
        d["timeline"],
        json!([[{"from": 0, "to": 30, "prompt": "a person walks forward"},
                {"from": 25, "to": 60, "prompt": "a person sits down"}], []])
    );
    assert!(html.contains(r#"<div id="timeline"></div>"#));
    assert!(html.contains(r#"<span id="prompt""#));
    // Read back as the pictures read it; without one it is empty.
    let lines = timeline_from_meta(&m, 2, 60).unwrap();
    assert_eq!(lines[0][1].to, 60);
    assert_eq!(timeline_to_meta(&lines), d["timeline"]);
    assert_eq!(
        data_of(&html_string(&people, &Meta::new(), "x").unwrap())["timeline"],
        json!([])
    );
}
