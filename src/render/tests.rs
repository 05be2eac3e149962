//! End-to-end render tests: synthetic walks rendered to GIF and PNG in a temp dir, the files
//! decoded again (signatures, sizes, GIF frame count and timing, pixels changing between
//! frames), picture orientation checked on pixels, and bad input rejected without leaving a
//! file behind.

use super::camera::Rect;
use super::draw::render_rgb;
use super::scene::Scene;
use super::style::{OVERLAY, person_colors};
use super::test_motion::{test_walk, walk};
use super::test_util::{decode_gif, decode_png, dir_entries, mean, pixels_of};
use super::views::{TopMarks, draw_side, draw_top, side_view, top_view};
use super::*;
use crate::motion::Motion;
use crate::skeleton::rest_pose;
use glam::Vec3;
use std::path::Path;

#[test]
fn gif_round_trip_has_every_frame_real_time_and_motion() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("walk.gif");
    let opts = RenderOptions {
        frame_step: 2,
        ..RenderOptions::titled("a person walks forward")
    };
    render_gif(&[test_walk()], &opts, &path).unwrap();
    let bytes = std::fs::read(&path).unwrap();
    assert_eq!(&bytes[..6], b"GIF89a");
    let g = decode_gif(&path);
    assert_eq!((g.w, g.h), (640, 320));
    // 40 frames at step 2 → 20 GIF frames of 0.1 s: 2 s in total.
    assert_eq!(g.frames.len(), 20);
    assert!(g.delays.iter().all(|&d| d == 10), "{:?}", g.delays);
    let changed = |a: &[u8], b: &[u8]| {
        a.chunks_exact(3)
            .zip(b.chunks_exact(3))
            .filter(|(p, q)| p != q)
            .count()
    };
    for k in 1..g.frames.len() {
        assert!(
            changed(&g.frames[k - 1], &g.frames[k]) > 50,
            "frame {k} did not change"
        );
    }
    // The figure moves rightwards in the side view (left 60 % of the picture).
    let side_x = |rgb: &[u8]| {
        let px: Vec<_> = pixels_of(rgb, g.w, person_colors(0).right)
            .into_iter()
            .filter(|p| p.0 < 384)
            .collect();
        mean(&px).0
    };
    assert!(side_x(&g.frames[19]) > side_x(&g.frames[0]) + 40.0);
    assert_eq!(dir_entries(dir.path()), 1, "no temp files left behind");
}

#[test]
fn strip_png_shows_both_sides_people_and_overlays() {
    let dir = tempfile::tempdir().unwrap();
    let a = test_walk();
    let b = walk(30, 0.8, Vec3::new(1.5, 0.0, 2.5), Vec3::NEG_Z);
    let mut opts = RenderOptions::titled("two people pass each other");
    let plain = dir.path().join("plain.png");
    render_strip_png(&[a.clone(), b.clone()], &opts, &plain).unwrap();
    opts.overlays = vec![
        Overlay::Point {
            at: Vec3::new(0.0, 1.0, 2.0),
            label: Some("target".into()),
        },
        Overlay::VerticalPlane {
            point: Vec3::new(0.0, 0.0, 3.0),
            normal: Vec3::Z,
        },
        Overlay::Box {
            min: Vec3::new(-0.5, 0.0, 0.5),
            max: Vec3::new(0.5, 0.5, 1.0),
        },
    ];
    let with = dir.path().join("overlays.png");
    render_strip_png(&[a, b], &opts, &with).unwrap();
    assert_eq!(&std::fs::read(&with).unwrap()[..8], b"\x89PNG\r\n\x1a\n");
    let (w, h, rgb) = decode_png(&plain);
    assert_eq!(w, 1280);
    assert!(h > 200 && h < 3000, "height {h}");
    for person in 0..2 {
        let c = person_colors(person);
        assert!(
            pixels_of(&rgb, w, c.left).len() > 100,
            "person {person} left side missing"
        );
        assert!(
            pixels_of(&rgb, w, c.right).len() > 100,
            "person {person} right side missing"
        );
    }
    assert!(pixels_of(&rgb, w, OVERLAY).is_empty());
    let (w2, _, rgb2) = decode_png(&with);
    assert!(pixels_of(&rgb2, w2, OVERLAY).len() > 500);
}

/// Renders one view of `people` at `frame` into a 400×300 picture.
fn view_pixels(people: &[Motion], top: bool, frame: usize) -> Vec<u8> {
    let opts = RenderOptions::default();
    let scene = Scene::new(people, &opts).unwrap();
    let rect = Rect {
        x: 0.0,
        y: 0.0,
        w: 400.0,
        h: 300.0,
    };
    render_rgb(400, 300, |area| {
        if top {
            draw_top(
                area,
                &scene,
                &top_view(&scene, rect),
                TopMarks::Current(frame),
                11.0,
            )
        } else {
            draw_side(area, &scene, &side_view(&scene, rect), frame, 11.0)
        }
    })
    .unwrap()
}

#[test]
fn views_are_upright_and_not_mirrored() {
    let still = Motion::new(vec![rest_pose(); 3]);
    let c = person_colors(0);
    // Side view: the head (spine colour, topmost) is above the legs.
    let side = view_pixels(std::slice::from_ref(&still), false, 0);
    let centre = pixels_of(&side, 400, c.centre);
    let legs: Vec<_> = pixels_of(&side, 400, c.right)
        .into_iter()
        .chain(pixels_of(&side, 400, c.left))
        .collect();
    let head_top = centre.iter().map(|p| p.1).min().unwrap();
    let lowest_limb = legs.iter().map(|p| p.1).max().unwrap();
    assert!(
        head_top + 100 < lowest_limb,
        "figure is not upright: head {head_top}, feet {lowest_limb}"
    );
    // Top view of someone facing +Z (screen right): their left (+X) is up on screen.
    let top = view_pixels(&[still], true, 0);
    let (left, right) = (
        mean(&pixels_of(&top, 400, c.left)),
        mean(&pixels_of(&top, 400, c.right)),
    );
    assert!(
        left.1 + 5.0 < right.1,
        "left side {left:?} must be above right side {right:?}"
    );
}

#[test]
fn render_to_path_dispatches_on_extension() {
    let dir = tempfile::tempdir().unwrap();
    let m = [Motion::new(vec![rest_pose(); 4])];
    let opts = RenderOptions {
        frame_step: 1,
        ..RenderOptions::default()
    };
    render_to_path(&m, &opts, &dir.path().join("a.GIF")).unwrap();
    render_to_path(&m, &opts, &dir.path().join("sub/a.png")).unwrap();
    assert_eq!(
        &std::fs::read(dir.path().join("a.GIF")).unwrap()[..6],
        b"GIF89a"
    );
    assert_eq!(
        &std::fs::read(dir.path().join("sub/a.png")).unwrap()[..4],
        b"\x89PNG"
    );
    let bad = dir.path().join("a.jpg");
    assert!(matches!(
        render_to_path(&m, &opts, &bad),
        Err(RenderError::UnknownFormat(_))
    ));
    assert!(!bad.exists());
}

#[test]
fn bad_motions_are_errors_and_write_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let gif = dir.path().join("x.gif");
    let png = dir.path().join("x.png");
    let opts = RenderOptions::default();
    let mut nan = test_walk();
    nan.frames[7][3].y = f32::NAN;
    let mut slow = test_walk();
    slow.fps = 10.0;
    type Expect = fn(&RenderError) -> bool;
    let cases: Vec<(Vec<Motion>, Expect)> = vec![
        (vec![], |e| matches!(e, RenderError::NoPeople)),
        (vec![Motion::new(vec![])], |e| {
            matches!(e, RenderError::EmptyMotion { person: 0 })
        }),
        (vec![test_walk(), nan], |e| {
            matches!(
                e,
                RenderError::NonFinite {
                    person: 1,
                    frame: 7,
                    joint: 3
                }
            )
        }),
        (vec![test_walk(), slow], |e| {
            matches!(e, RenderError::FpsMismatch { person: 1, .. })
        }),
    ];
    for (people, expected) in cases {
        for path in [&gif, &png] {
            let err = render_to_path(&people, &opts, path).unwrap_err();
            assert!(expected(&err), "unexpected error {err}");
        }
    }
    let walk = [test_walk()];
    let bad_opts = [
        RenderOptions {
            frame_step: 0,
            ..RenderOptions::default()
        },
        RenderOptions {
            frame_range: Some(10..100),
            ..RenderOptions::default()
        },
        RenderOptions {
            size: (10, 10),
            ..RenderOptions::default()
        },
        RenderOptions {
            strip_frames: StripFrames::Indices(vec![3, 40]),
            ..RenderOptions::default()
        },
        RenderOptions {
            camera_yaw_deg: Some(f32::NAN),
            ..RenderOptions::default()
        },
        RenderOptions {
            overlays: vec![Overlay::VerticalPlane {
                point: Vec3::ZERO,
                normal: Vec3::Y,
            }],
            ..RenderOptions::default()
        },
        RenderOptions {
            overlays: vec![Overlay::Point {
                at: Vec3::splat(f32::INFINITY),
                label: None,
            }],
            ..RenderOptions::default()
        },
    ];
    for (i, o) in bad_opts.iter().enumerate() {
        let path = if i == 3 { &png } else { &gif };
        assert!(
            render_to_path(&walk, o, path).is_err(),
            "options {i} should be rejected"
        );
    }
    assert_eq!(dir_entries(dir.path()), 0, "an error left a file behind");
}

/// Writes demo renders for looking at by eye (`cargo test --lib render::tests::demo --
/// --ignored`): into `$MPROG_RENDER_DEMO` or `/tmp/mprog-render-demo`, GIF frames also as PNG.
#[test]
#[ignore = "writes pictures for manual inspection"]
fn demo_renders_for_inspection() {
    let dir =
        std::env::var("MPROG_RENDER_DEMO").unwrap_or_else(|_| "/tmp/mprog-render-demo".into());
    let dir = Path::new(&dir);
    let long_walk = walk(200, 1.2, Vec3::ZERO, Vec3::Z);
    let rest = Motion::new(vec![rest_pose(); 20]);
    let diagonal = walk(60, 1.0, Vec3::new(0.5, 0.0, 0.0), Vec3::new(1.0, 0.0, 0.6));
    let other = walk(60, 0.9, Vec3::new(2.0, 0.0, 3.0), Vec3::NEG_Z);
    let mut opts = RenderOptions::titled("a person walks forward for ten seconds");
    render_to_path(
        std::slice::from_ref(&long_walk),
        &opts,
        &dir.join("walk.gif"),
    )
    .unwrap();
    render_to_path(&[long_walk], &opts, &dir.join("walk.png")).unwrap();
    opts.title = "rest pose".into();
    render_to_path(std::slice::from_ref(&rest), &opts, &dir.join("rest.gif")).unwrap();
    render_to_path(&[rest], &opts, &dir.join("rest.png")).unwrap();
    opts.title = "two people, a wall, a target and a box".into();
    opts.overlays = vec![
        Overlay::Point {
            at: Vec3::new(1.0, 1.2, 2.0),
            label: Some("target".into()),
        },
        Overlay::VerticalPlane {
            point: Vec3::new(0.0, 0.0, 4.2),
            normal: Vec3::new(0.2, 0.0, 1.0),
        },
        Overlay::Box {
            min: Vec3::new(-0.8, 0.0, 1.0),
            max: Vec3::new(-0.2, 0.6, 1.6),
        },
        Overlay::HorizontalPlane { height: 1.9 },
        Overlay::Segment {
            from: Vec3::new(0.5, 0.0, 0.0),
            to: Vec3::new(0.5, 1.0, 0.0),
        },
    ];
    let pair = [diagonal, other];
    render_to_path(&pair, &opts, &dir.join("pair.gif")).unwrap();
    render_to_path(&pair, &opts, &dir.join("pair.png")).unwrap();
    for name in ["walk", "rest", "pair"] {
        let g = decode_gif(&dir.join(format!("{name}.gif")));
        for k in [0, g.frames.len() / 2, g.frames.len() - 1] {
            let png = super::encode::encode_png(&g.frames[k], g.w as u32, g.h as u32).unwrap();
            crate::fsutil::write_bytes_atomic(&dir.join(format!("{name}-gif-{k}.png")), &png)
                .unwrap();
        }
    }
    let loss = Series {
        name: "train".into(),
        points: (1..500)
            .map(|i| (i as f32, 3.0 / (i as f32).sqrt() + 0.01))
            .collect(),
    };
    let val = Series {
        name: "val".into(),
        points: (1..25)
            .map(|i| ((i * 20) as f32, 3.2 / ((i * 20) as f32).sqrt() + 0.02))
            .collect(),
    };
    plot_lines(
        &dir.join("loss-log.png"),
        "training loss",
        "step",
        "loss",
        &[loss.clone(), val.clone()],
        &PlotOptions {
            log_y: true,
            ..PlotOptions::default()
        },
    )
    .unwrap();
    plot_lines(
        &dir.join("loss-lin.png"),
        "training loss",
        "step",
        "loss",
        &[loss, val],
        &PlotOptions::default(),
    )
    .unwrap();
}

/// A 12 s walk with three prompts; the middle one (1 s) holds none of 4 evenly spaced
/// frames.
fn timeline_walk() -> (Motion, Vec<Vec<TimelineSpan>>) {
    let span = |from, to, prompt: &str| TimelineSpan {
        from,
        to,
        prompt: prompt.into(),
    };
    (
        walk(240, 1.0, Vec3::ZERO, Vec3::Z),
        vec![vec![
            span(0, 100, "a person walks forward"),
            span(100, 120, "a person waves"),
            span(110, 240, "a person sits down"),
        ]],
    )
}

#[test]
fn strip_with_a_timeline_names_each_cells_prompt_and_covers_every_span() {
    use super::style::fade;
    use super::timeline::SPAN_COLORS;
    let dir = tempfile::tempdir().unwrap();
    let (m, timeline) = timeline_walk();
    let plain = RenderOptions {
        strip_frames: StripFrames::Count(4),
        ..RenderOptions::titled("three prompts")
    };
    let with = RenderOptions {
        timeline: timeline.clone(),
        ..plain.clone()
    };
    let (a, b) = (
        dir.path().join("plain.png"),
        dir.path().join("timeline.png"),
    );
    render_strip_png(std::slice::from_ref(&m), &plain, &a).unwrap();
    render_strip_png(std::slice::from_ref(&m), &with, &b).unwrap();
    let (_, h0, _) = decode_png(&a);
    let (w, h1, rgb) = decode_png(&b);
    // A second caption line per cell and the bar make the picture taller.
    assert!(h1 > h0 + 20, "{h0} -> {h1}");
    // Every span is in the bar, in its own colour, on one row of pixels' height.
    for (k, c) in SPAN_COLORS.iter().take(3).enumerate() {
        let px = pixels_of(&rgb, w, fade(*c, 0.72));
        assert!(px.len() > 30, "span {k}: {} pixels", px.len());
        let ys = px.iter().map(|p| p.1);
        assert!(
            ys.clone().max().unwrap() - ys.min().unwrap() < 30,
            "span {k}"
        );
    }
    assert!(pixels_of(&decode_png(&a).2, w, fade(SPAN_COLORS[0], 0.72)).is_empty());
    // The strip's frames moved so that the 1 s wave has a cell; an explicit list stays.
    let scene = Scene::new(std::slice::from_ref(&m), &with).unwrap();
    let tl = super::timeline::Timeline::new(&with, scene.len)
        .unwrap()
        .unwrap();
    let spans: Vec<_> = tl.spans().collect();
    let even = super::frames::strip_frames(240, &with).unwrap();
    assert!(!even.iter().any(|f| (100..120).contains(f)), "{even:?}");
    let moved = super::timeline::cover_spans(even, &spans, &(0..240));
    assert!(moved.iter().any(|f| (100..120).contains(f)), "{moved:?}");
    assert_eq!(tl.caption(moved[1]), "\"a person waves\"");
    // One prompt only: no bar, the same picture as without a timeline.
    let one = RenderOptions {
        timeline: vec![vec![TimelineSpan {
            from: 0,
            to: 240,
            prompt: "a person walks forward".into(),
        }]],
        ..plain.clone()
    };
    assert_eq!(
        strip_bytes(std::slice::from_ref(&m), &one).unwrap(),
        std::fs::read(&a).unwrap()
    );
    // A span past the clip is refused.
    let bad = RenderOptions {
        timeline: vec![vec![
            TimelineSpan {
                from: 0,
                to: 300,
                prompt: "a".into(),
            },
            TimelineSpan {
                from: 250,
                to: 300,
                prompt: "b".into(),
            },
        ]],
        ..plain
    };
    assert!(matches!(
        strip_bytes(&[m], &bad),
        Err(RenderError::BadOption(_))
    ));
}

#[test]
fn gif_with_a_timeline_marks_the_active_prompt_on_its_bar() {
    use super::style::fade;
    use super::timeline::SPAN_COLORS;
    let dir = tempfile::tempdir().unwrap();
    let (m, timeline) = timeline_walk();
    let path = dir.path().join("t.gif");
    let opts = RenderOptions {
        frame_step: 10,
        timeline,
        ..RenderOptions::titled("three prompts")
    };
    render_gif(&[m], &opts, &path).unwrap();
    let g = decode_gif(&path);
    assert_eq!((g.w, g.h, g.frames.len()), (640, 320, 24));
    // Frame 50 (GIF frame 5): the walk's span is drawn active, the sit's not; at frame
    // 200 (GIF frame 20) the other way round. The bar is the bottom of the picture.
    let active = |rgb: &[u8], k: usize| {
        pixels_of(rgb, g.w, fade(SPAN_COLORS[k], 0.35))
            .iter()
            .filter(|p| p.1 > 280)
            .count()
    };
    assert!(active(&g.frames[5], 0) > 100 && active(&g.frames[5], 2) == 0);
    assert!(active(&g.frames[20], 2) > 100 && active(&g.frames[20], 0) == 0);
}
