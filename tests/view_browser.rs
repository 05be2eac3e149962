//! The viewer page in a real browser (ignored: needs Chromium, `apt-get install chromium`):
//! headless Chromium screenshots the page at `#frame=0` and `#frame=40`, and the pictures
//! must show the scene (floor, the blue and red figures, the magenta overlay), differ
//! between the two frames, and draw the error chart.
//! `cargo test --test view_browser -- --ignored --nocapture`

mod common;

use common::synthetic_walk;
use glam::Vec3;
use mprog::formats::Meta;
use mprog::motion::Motion;
use serde_json::json;
use std::path::Path;
use std::process::Command;

const WIDTH: u32 = 1200;
const HEIGHT: u32 = 800;

fn chromium() -> Option<&'static str> {
    ["chromium", "chromium-browser", "google-chrome"]
        .into_iter()
        .find(|name| {
            Command::new(name)
                .arg("--version")
                .output()
                .is_ok_and(|o| o.status.success())
        })
}

/// Screenshots `page#hash` into `png`; returns the RGB pixels.
fn screenshot(browser: &str, page: &Path, hash: &str, png: &Path) -> Vec<u8> {
    let profile = tempfile::tempdir().unwrap();
    let status = Command::new(browser)
        .args([
            "--headless",
            "--no-sandbox",
            "--disable-gpu",
            "--disable-quic",
            "--no-first-run",
            "--disable-background-networking",
            "--disable-component-update",
            "--disable-sync",
            "--hide-scrollbars",
        ])
        .arg(format!("--user-data-dir={}", profile.path().display()))
        .arg(format!("--screenshot={}", png.display()))
        .arg(format!("--window-size={WIDTH},{HEIGHT}"))
        .arg(format!("file://{}{hash}", page.display()))
        .output()
        .expect("chromium runs");
    assert!(
        png.exists(),
        "no screenshot: {}",
        String::from_utf8_lossy(&status.stderr)
    );
    let decoder = png::Decoder::new(std::io::BufReader::new(std::fs::File::open(png).unwrap()));
    let mut reader = decoder.read_info().unwrap();
    let mut buf = vec![0; reader.output_buffer_size()];
    let info = reader.next_frame(&mut buf).unwrap();
    assert_eq!((info.width, info.height), (WIDTH, HEIGHT));
    buf.truncate(info.buffer_size());
    let channels = match info.color_type {
        png::ColorType::Rgb => 3,
        png::ColorType::Rgba => 4,
        other => panic!("unexpected screenshot colour type {other:?}"),
    };
    buf.chunks_exact(channels)
        .flat_map(|p| [p[0], p[1], p[2]])
        .collect()
}

/// Pixels within `tol` (per channel) of `rgb`, in rows `rows`.
fn count_near(px: &[u8], rgb: [u8; 3], tol: i32, rows: std::ops::Range<u32>) -> usize {
    px.chunks_exact(3)
        .enumerate()
        .filter(|(i, _)| rows.contains(&(*i as u32 / WIDTH)))
        .filter(|(_, p)| (0..3).all(|k| (p[k] as i32 - rgb[k] as i32).abs() <= tol))
        .count()
}

#[test]
#[ignore = "needs Chromium (apt-get install chromium); run by hand"]
fn chromium_draws_the_scene_and_follows_the_frame_hash() {
    let Some(browser) = chromium() else {
        println!("SKIPPED: no chromium / chromium-browser / google-chrome on PATH");
        return;
    };
    let walker = synthetic_walk(80);
    let mut partner = walker.clone();
    for pose in &mut partner.frames {
        for p in pose.iter_mut() {
            *p += Vec3::new(1.5, 0.0, 0.5);
        }
    }
    let people: Vec<Motion> = vec![walker, partner];
    let values: Vec<f64> = (0..80).map(|f| (f as f64 / 10.0).sin().abs()).collect();
    let meta: Meta = json!({
        "overlays": [{"kind": "box", "min": [-1.0, 0.0, 1.0], "max": [-0.5, 1.0, 1.5]},
                     {"kind": "point", "at": [0.5, 1.2, 2.0], "label": "target"}],
        "contacts": [{"a": {"person": 0, "joint": "right_wrist"},
                      "b": {"person": 1, "joint": "left_wrist"}, "frames": [30, 50]}],
        "statement_errors": [{"label": "line 1: reach", "line": 1, "unit": "m",
                              "tolerance": 0.2, "values": values}]
    })
    .as_object()
    .unwrap()
    .clone();
    let dir = tempfile::tempdir().unwrap();
    let page = dir.path().join("view.html");
    mprog::view::write_html(&people, &meta, "browser test", &page).unwrap();

    let keep = std::env::var_os("MPROG_KEEP_SCREENSHOTS").map(std::path::PathBuf::from);
    let out = keep.clone().unwrap_or_else(|| dir.path().to_path_buf());
    std::fs::create_dir_all(&out).unwrap();
    let first = screenshot(browser, &page, "#frame=0", &out.join("view_frame0.png"));
    let later = screenshot(browser, &page, "#frame=40", &out.join("view_frame40.png"));
    if let Some(k) = keep {
        println!("screenshots in {}", k.display());
    }

    for (name, px) in [("frame 0", &first), ("frame 40", &later)] {
        // Not blank: many colours, and the canvas area (rows 70–520, below the legend's
        // colour swatches) holds the floor, person 1's dark blue, person 2's dark red and
        // the magenta overlays.
        let mut colours: Vec<[u8; 3]> = px.chunks_exact(3).map(|p| [p[0], p[1], p[2]]).collect();
        colours.sort_unstable();
        colours.dedup();
        assert!(
            colours.len() > 200,
            "{name}: only {} colours",
            colours.len()
        );
        let canvas = 70..520;
        let floor = count_near(px, [242, 242, 238], 3, canvas.clone());
        let blue = count_near(px, [0x14, 0x46, 0xaa], 40, canvas.clone());
        let red = count_near(px, [0xaa, 0x1e, 0x1e], 40, canvas.clone());
        let magenta = count_near(px, [0xd2, 0x00, 0x96], 40, canvas.clone());
        println!(
            "{name}: {} colours, floor {floor}, blue {blue}, red {red}, magenta {magenta} px",
            colours.len()
        );
        assert!(floor > 20_000, "{name}: floor not drawn ({floor} px)");
        assert!(blue > 150, "{name}: person 1 not drawn ({blue} px)");
        assert!(red > 150, "{name}: person 2 not drawn ({red} px)");
        assert!(magenta > 150, "{name}: overlays not drawn ({magenta} px)");
        // The chart under the canvas draws its curve in #2d6ed2 and a red cursor.
        let curve = count_near(px, [0x2d, 0x6e, 0xd2], 40, 560..HEIGHT);
        assert!(
            curve > 100,
            "{name}: error chart curve missing ({curve} px)"
        );
    }
    // The figures moved: the canvas differs between frame 0 and frame 40.
    let changed = first
        .chunks_exact(3)
        .zip(later.chunks_exact(3))
        .skip((70 * WIDTH) as usize)
        .take((450 * WIDTH) as usize)
        .filter(|(a, b)| a != b)
        .count();
    println!("{changed} canvas pixels differ between frame 0 and frame 40");
    assert!(
        changed > 500,
        "frame hash ignored? only {changed} pixels differ"
    );
    // At frame 40 the contact is active: its orange line is drawn; at frame 0 it is not.
    let orange_0 = count_near(&first, [0xff, 0x82, 0x00], 40, 70..520);
    let orange_40 = count_near(&later, [0xff, 0x82, 0x00], 40, 70..520);
    println!("contact orange: frame 0 {orange_0} px, frame 40 {orange_40} px");
    assert!(orange_40 > orange_0 + 20, "active contact not highlighted");
}
