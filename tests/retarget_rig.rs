//! Motions on a user's rig (`--rig`): the HumanML3D golden clip put on
//! `tests/fixtures/rigs/mixamo_tall.bvh` (Mixamo names, 65 joints with fingers, centimetres,
//! T-pose, legs 15 % longer than HumanML3D's) by `mprog convert`, read back with mprog's own
//! BVH reader: the rig's joints and offsets exactly, feet on the floor, the path scaled by
//! leg length, foot skating no worse; the same with `mixamorig:` names, an A-pose, Z up and
//! metres; the skinned `.glb` on the rig; and located errors (golden) for rigs that cannot
//! be mapped, with nothing written.
//!
//! `MPROG_RIG_SOURCE=walk.npy cargo test --test retarget_rig figures -- --ignored --nocapture`
//! prints the figures for another motion (the book's come from a generated walk).

mod common;

use glam::{DQuat, DVec3};
use mprog::formats::bvh::{BvhImportOptions, Units, UpAxis, import_bvh, parse_bvh};
use mprog::formats::character::Character;
use mprog::formats::gltf::read::parse_glb;
use mprog::metrics::per_motion::foot_skating_ratio;
use mprog::motion::Motion;
use std::path::{Path, PathBuf};
use std::process::Command;

fn rig_path() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/rigs/mixamo_tall.bvh")
}

fn rig_text() -> String {
    std::fs::read_to_string(rig_path()).unwrap()
}

fn mprog(args: &[&std::ffi::OsStr]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_mprog"))
        .args(args)
        .output()
        .unwrap()
}

/// `mprog convert input --rig rig [--rig-map map] -o outputs…`; panics with stderr on failure.
fn convert_onto(input: &Path, rig: &Path, map: Option<&Path>, outputs: &[PathBuf]) {
    let mut args: Vec<&std::ffi::OsStr> = vec!["convert".as_ref(), input.as_os_str()];
    args.extend(["--rig".as_ref(), rig.as_os_str()]);
    if let Some(m) = map {
        args.extend(["--rig-map".as_ref(), m.as_os_str()]);
    }
    args.push("-o".as_ref());
    args.extend(outputs.iter().map(|o| o.as_os_str()));
    let out = mprog(&args);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

fn write_npy(path: &Path, m: &Motion) {
    mprog::formats::npy::write_joints_npy(path, std::slice::from_ref(m)).unwrap();
}

/// Hip–knee–ankle length, mean of both legs and all frames.
fn leg(m: &Motion) -> f32 {
    let mut sum = 0.0;
    for p in &m.frames {
        sum += mprog::formats::bvh::units::leg_length(p);
    }
    sum / m.len() as f32
}

/// Median over frames of the lowest foot joint (ankles and toes), metres.
fn median_lowest_foot(m: &Motion) -> f32 {
    let mut lows: Vec<f32> = m
        .frames
        .iter()
        .map(|p| {
            [7, 8, 10, 11]
                .iter()
                .map(|&j| p[j].y)
                .fold(f32::MAX, f32::min)
        })
        .collect();
    lows.sort_by(f32::total_cmp);
    lows[lows.len() / 2]
}

/// Horizontal distance the pelvis travels (sum of its steps), metres.
fn hip_travel(m: &Motion) -> f32 {
    m.frames
        .windows(2)
        .map(|w| {
            let d = w[1][0] - w[0][0];
            (d.x * d.x + d.z * d.z).sqrt()
        })
        .sum()
}

/// The measured figures of `source` on the rig, read back from `out` (a BVH on the rig).
struct Figures {
    scale: f32,
    lowest_source: f32,
    lowest_rig: f32,
    travel_source: f32,
    travel_rig: f32,
    skating_source: f32,
    skating_rig: f32,
    skating_rig_unscaled: f32,
    /// Largest distance of an ankle or toe (scaled back) from the source's, metres.
    feet_gap: f32,
    /// Median of the same.
    feet_gap_median: f32,
    /// One frame step of the skating ratio, 1 / (frames − 1).
    step: f32,
}

fn figures(source: &Motion, out: &Path) -> Figures {
    let back = import_bvh(out, &BvhImportOptions::default()).unwrap();
    assert_eq!(back.unit_scale, 0.01, "read back in centimetres");
    let rig = back.motion;
    assert_eq!(rig.len(), source.len());
    let scale = leg(&rig) / leg(source);
    let unscaled = Motion {
        frames: rig.frames.iter().map(|p| p.map(|v| v / scale)).collect(),
        fps: rig.fps,
    };
    let mut gaps: Vec<f32> = unscaled
        .frames
        .iter()
        .zip(&source.frames)
        .flat_map(|(a, b)| [7, 8, 10, 11].map(|j| a[j].distance(b[j])))
        .collect();
    gaps.sort_by(f32::total_cmp);
    Figures {
        feet_gap: gaps[gaps.len() - 1],
        feet_gap_median: gaps[gaps.len() / 2],
        step: 1.0 / (source.len() - 1) as f32,
        scale,
        lowest_source: median_lowest_foot(source),
        lowest_rig: median_lowest_foot(&rig),
        travel_source: hip_travel(source),
        travel_rig: hip_travel(&rig),
        skating_source: foot_skating_ratio(source),
        skating_rig: foot_skating_ratio(&rig),
        skating_rig_unscaled: foot_skating_ratio(&unscaled),
    }
}

impl Figures {
    fn print(&self, what: &str) {
        println!(
            "{what}: leg ratio {:.3}; median lowest foot {:.3} m (source {:.3} m); hips travel {:.3} m vs source × ratio {:.3} m ({:+.2} %); foot skating {:.3} (source {:.3}; the rig's motion scaled back to the source's size {:.3}); ankles and toes scaled back vs the source's: median {:.4} m, largest {:.4} m",
            self.scale,
            self.lowest_rig,
            self.lowest_source,
            self.travel_rig,
            self.travel_source * self.scale,
            100.0 * (self.travel_rig / (self.travel_source * self.scale) - 1.0),
            self.skating_rig,
            self.skating_source,
            self.skating_rig_unscaled,
            self.feet_gap_median,
            self.feet_gap,
        );
    }

    fn check(&self) {
        assert!(self.lowest_rig.abs() < 0.03, "feet off the floor");
        let travel = self.travel_rig / (self.travel_source * self.scale);
        assert!((travel - 1.0).abs() < 0.05, "hips travel ratio {travel}");
        // The metric on the rig's motion as it is (a taller body: faster feet, but the 5 cm
        // contact height is lower on it) ...
        assert!(
            self.skating_rig <= self.skating_source,
            "skating {} vs {}",
            self.skating_rig,
            self.skating_source
        );
        // ... and scaled back to the source's size, where only toes a few millimetres
        // higher or lower cross its thresholds: within one frame step.
        assert!(
            self.skating_rig_unscaled <= self.skating_source + self.step + 1e-6,
            "scaled-back skating {} vs {}",
            self.skating_rig_unscaled,
            self.skating_source
        );
        assert!(
            self.feet_gap < 0.01,
            "feet {} m from the source's",
            self.feet_gap
        );
    }
}

#[test]
fn a_motion_on_a_tall_mixamo_rig_keeps_the_rig_and_the_feet() {
    let (_, clip) = common::golden();
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("clip.npy");
    write_npy(&input, &clip);
    let out = dir.path().join("on_rig.bvh");
    convert_onto(&input, &rig_path(), None, std::slice::from_ref(&out));

    // Exactly the rig's joints, offsets and channels.
    let rig = parse_bvh("rig", &rig_text(), Default::default()).unwrap();
    let text = std::fs::read_to_string(&out).unwrap();
    let got = parse_bvh("out", &text, Default::default()).unwrap();
    assert_eq!(got.joints.len(), rig.joints.len());
    for (a, b) in got.joints.iter().zip(&rig.joints) {
        assert_eq!(
            (&a.name, a.parent, a.offset, &a.channels, a.end_site),
            (&b.name, b.parent, b.offset, &b.channels, b.end_site)
        );
    }
    assert_eq!(got.frame_count, clip.len());
    assert!((got.frame_time - 0.05).abs() < 1e-6);

    let f = figures(&clip, &out);
    f.print("golden clip 012314 on mixamo_tall.bvh");
    f.check();
    assert!((f.scale - 1.15).abs() < 0.02, "leg ratio {}", f.scale);

    // Joints mprog does not drive keep their rest pose: every finger channel is zero.
    let finger = rig
        .joints
        .iter()
        .position(|j| j.name == "LeftHandIndex2")
        .unwrap();
    let first = got.joints[finger].first_channel;
    for frame in 0..got.frame_count {
        assert_eq!(&got.frame(frame)[first..first + 3], &[0.0, 0.0, 0.0]);
    }
}

/// The 22 joints read back from a BVH on a rig (`up`: its up axis).
fn read_back(path: &Path, up: UpAxis, units: Units) -> Motion {
    let opts = BvhImportOptions {
        up,
        units,
        ..Default::default()
    };
    import_bvh(path, &opts).unwrap().motion
}

fn worst(a: &Motion, b: &Motion) -> f32 {
    a.frames
        .iter()
        .zip(&b.frames)
        .flat_map(|(p, q)| p.iter().zip(q).map(|(x, y)| x.distance(*y)))
        .fold(0.0, f32::max)
}

/// The fixture with each joint's offset changed by `f(name, offset)`.
fn edit_offsets(text: &str, f: impl Fn(&str, DVec3) -> DVec3) -> String {
    let mut name = String::new();
    let mut out = String::new();
    for line in text.lines() {
        let t = line.trim_start();
        if let Some(n) = t.strip_prefix("JOINT ").or_else(|| t.strip_prefix("ROOT ")) {
            name = n.to_string();
        } else if t.starts_with("End Site") {
            name = format!("{name} End Site");
        }
        if let Some(v) = t.strip_prefix("OFFSET ") {
            let v: Vec<f64> = v.split_whitespace().map(|x| x.parse().unwrap()).collect();
            let o = f(&name, DVec3::new(v[0], v[1], v[2]));
            let pad = &line[..line.len() - t.len()];
            out.push_str(&format!("{pad}OFFSET {} {} {}\n", o.x, o.y, o.z));
        } else {
            out.push_str(line);
            out.push('\n');
        }
    }
    out
}

#[test]
fn prefixes_rest_poses_axes_and_units_give_the_same_motion() {
    let (_, clip) = common::golden();
    let clip = Motion {
        frames: clip.frames[..60].to_vec(),
        fps: clip.fps,
    };
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("clip.npy");
    write_npy(&input, &clip);
    let put = |name: &str, text: String| -> PathBuf {
        let rig = dir.path().join(format!("{name}.bvh"));
        std::fs::write(&rig, text).unwrap();
        let out = dir.path().join(format!("{name}_out.bvh"));
        convert_onto(&input, &rig, None, std::slice::from_ref(&out));
        out
    };
    let plain = read_back(&put("plain", rig_text()), UpAxis::Y, Units::Centimetres);

    let prefixed = rig_text()
        .replace("JOINT ", "JOINT mixamorig:")
        .replace("ROOT ", "ROOT mixamorig:");
    let out = put("prefixed", prefixed);
    assert!(
        std::fs::read_to_string(&out)
            .unwrap()
            .contains("JOINT mixamorig:LeftHandThumb1")
    );
    let e = worst(&read_back(&out, UpAxis::Y, Units::Centimetres), &plain);
    assert!(e < 1e-4, "mixamorig: prefix: {e} m");

    // A-pose: both arms 45° down from the shoulder (every offset below the upper arm
    // turned about the body's forward axis).
    let a_pose = edit_offsets(&rig_text(), |name, o| {
        let below_arm = ["ForeArm", "Hand"].iter().any(|p| name.contains(p));
        let turn = match (below_arm, name.starts_with("Left")) {
            (false, _) => return o,
            (true, true) => -std::f64::consts::FRAC_PI_4,
            (true, false) => std::f64::consts::FRAC_PI_4,
        };
        DQuat::from_rotation_z(turn) * o
    });
    let e = worst(
        &read_back(&put("a_pose", a_pose), UpAxis::Y, Units::Centimetres),
        &plain,
    );
    println!("A-pose rig vs T-pose rig: largest joint difference {e:.2e} m");
    assert!(e < 1e-3, "A-pose: {e} m");

    // Z up (Blender's axes), and metres.
    let z_up = edit_offsets(&rig_text(), |_, o| DVec3::new(o.x, -o.z, o.y));
    let e = worst(
        &read_back(&put("z_up", z_up), UpAxis::Z, Units::Centimetres),
        &plain,
    );
    assert!(e < 1e-3, "Z up: {e} m");
    let metres = edit_offsets(&rig_text(), |_, o| o / 100.0);
    let out = put("metres", metres);
    let e = worst(&read_back(&out, UpAxis::Y, Units::Metres), &plain);
    assert!(e < 1e-3, "metres: {e} m");
}

/// A rig of the 22 HumanML3D joints whose rest pose is `pose` (no connectors: the pelvis
/// and spine3 carry three bones each, as in most rigs), metres.
fn rig_of_pose(pose: &mprog::motion::Pose) -> String {
    use mprog::skeleton::{JOINT_NAMES, PARENTS};
    fn joint(out: &mut String, pose: &mprog::motion::Pose, j: usize, depth: usize) {
        let pad = "  ".repeat(depth);
        let o = if j == 0 {
            pose[0]
        } else {
            pose[j] - pose[PARENTS[j]]
        };
        let kind = if j == 0 { "ROOT" } else { "JOINT" };
        let channels = if j == 0 {
            "6 Xposition Yposition Zposition Zrotation Yrotation Xrotation"
        } else {
            "3 Zrotation Yrotation Xrotation"
        };
        out.push_str(&format!(
            "{pad}{kind} {}\n{pad}{{\n{pad}  OFFSET {} {} {}\n{pad}  CHANNELS {channels}\n",
            JOINT_NAMES[j], o.x, o.y, o.z
        ));
        for c in (1..22).filter(|&c| PARENTS[c] == j) {
            joint(out, pose, c, depth + 1);
        }
        out.push_str(&format!("{pad}}}\n"));
    }
    let mut out = String::from("HIERARCHY\n");
    joint(&mut out, pose, 0, 0);
    out.push_str("MOTION\nFrames: 1\nFrame Time: 0.05\n");
    out.push_str(&vec!["0"; 6 + 3 * 21].join(" "));
    out.push('\n');
    out
}

#[test]
fn on_a_rig_of_its_own_shape_the_motion_comes_back() {
    // The golden clip's frame 0 as a rig: the clip's own bone lengths and rest geometry.
    let (_, clip) = common::golden();
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("clip.npy");
    write_npy(&input, &clip);
    let own = dir.path().join("own.bvh");
    std::fs::write(&own, rig_of_pose(&clip.frames[0])).unwrap();
    let back = dir.path().join("back.bvh");
    convert_onto(&input, &own, None, std::slice::from_ref(&back));
    let back = read_back(&back, UpAxis::Y, Units::Metres);
    let mut worst = [0.0f32; 22];
    for (p, q) in back.frames.iter().zip(&clip.frames) {
        for j in 0..22 {
            worst[j] = worst[j].max(p[j].distance(q[j]));
        }
    }
    let all = worst.iter().copied().fold(0.0, f32::max);
    println!("onto a rig of its own shape: largest joint error {all:.4} m, per joint {worst:.3?}");
    assert!(all < 0.03, "{all} m");
    // The ankles and toes are where the clip's are (IK), to the millimetre.
    for j in [7, 8, 10, 11] {
        assert!(worst[j] < 2e-3, "joint {j}: {} m", worst[j]);
    }
    // --bvh-fps resamples before retargeting.
    let at_30 = dir.path().join("back30.bvh");
    let out = mprog(&[
        "convert".as_ref(),
        input.as_os_str(),
        "--rig".as_ref(),
        own.as_os_str(),
        "--bvh-fps".as_ref(),
        "30".as_ref(),
        "-o".as_ref(),
        at_30.as_os_str(),
    ]);
    assert!(out.status.success());
    let text = std::fs::read_to_string(&at_30).unwrap();
    assert!(
        text.contains("Frames: 254\nFrame Time: 0.03333333"),
        "30 fps"
    );
}

#[test]
fn the_glb_on_the_rig_is_the_rigs_skeleton_skinned() {
    let (_, clip) = common::golden();
    let clip = Motion {
        frames: clip.frames[..40].to_vec(),
        fps: clip.fps,
    };
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("clip.npy");
    write_npy(&input, &clip);
    let (bvh, glb) = (dir.path().join("out.bvh"), dir.path().join("out.glb"));
    convert_onto(&input, &rig_path(), None, &[bvh.clone(), glb.clone()]);
    let back = read_back(&bvh, UpAxis::Y, Units::Centimetres);
    let g = parse_glb(&std::fs::read(&glb).unwrap()).unwrap();
    // The rig's 65 joints (End Sites are drawn, not nodes) and the body.
    assert_eq!(g.doc.nodes.len(), 66);
    assert_eq!(g.doc.skins[0].joints.len(), 65);
    let names = [
        (0, "Hips"),
        (4, "LeftLeg"),
        (7, "LeftFoot"),
        (10, "LeftToeBase"),
        (15, "Head"),
        (21, "RightHand"),
    ];
    for f in [0, 25] {
        for (j, name) in names {
            let p = g.node_position(name, f).unwrap();
            let d = p.distance(back.frames[f][j]);
            assert!(d < 1e-3, "{name} frame {f}: {d} m from the BVH's");
        }
    }
    let body = g.doc.nodes.iter().position(|n| n.mesh.is_some()).unwrap();
    let verts = g.skinned_vertices(body, 10).unwrap();
    let lowest = verts.iter().map(|v| v.y).fold(f32::MAX, f32::min);
    assert!(lowest > -0.1, "the body stays above the floor: {lowest}");
}

#[test]
fn a_glb_of_the_22_joints_matches_the_npy_within_a_centimetre() {
    let (_, clip) = common::golden();
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("clip.npy");
    write_npy(&input, &clip);
    let glb = dir.path().join("clip.glb");
    let out = mprog(&[
        "convert".as_ref(),
        input.as_os_str(),
        "-o".as_ref(),
        glb.as_os_str(),
    ]);
    assert!(out.status.success());
    let g = parse_glb(&std::fs::read(&glb).unwrap()).unwrap();
    assert_eq!(g.doc.skins.len(), 1);
    let mut worst = 0.0f32;
    for (f, pose) in clip.frames.iter().enumerate() {
        let world = g.world(f).unwrap();
        for (j, name) in mprog::skeleton::JOINT_NAMES.iter().enumerate() {
            let id = g.doc.nodes.iter().position(|n| n.name == *name).unwrap();
            worst = worst.max(world[id].w_axis.truncate().distance(pose[j]));
        }
    }
    println!("glb joints vs npy: largest difference {worst:.2e} m");
    assert!(worst < 0.01, "{worst} m");
}

/// The figures for the motion in `MPROG_RIG_SOURCE` (an `.npy` of joints).
#[test]
#[ignore = "set MPROG_RIG_SOURCE to a motion's .npy"]
fn figures_of_a_motion() {
    let Ok(source) = std::env::var("MPROG_RIG_SOURCE") else {
        println!("SKIPPED: MPROG_RIG_SOURCE is not set");
        return;
    };
    let loaded = mprog::formats::read_motion(Path::new(&source)).unwrap();
    let mprog::formats::LoadedMotion::Joints { people, .. } = loaded else {
        panic!("{source}: expected joints")
    };
    let motion = people.into_iter().next().unwrap().motion;
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("on_rig.bvh");
    convert_onto(
        Path::new(&source),
        &rig_path(),
        None,
        std::slice::from_ref(&out),
    );
    let f = figures(&motion, &out);
    f.print(&format!("{source} on mixamo_tall.bvh"));
    f.check();
}

/// The error text of a rig given as text (and a mapping file's text).
fn rig_error(name: &str, text: &str, map: Option<&str>) -> String {
    match Character::from_text((name, text), map.map(|m| ("map.toml", m))) {
        Ok(_) => panic!("{name}: the rig was accepted"),
        Err(e) => e.to_string(),
    }
}

/// The fixture with its joint names translated (a rig no name table knows).
fn german() -> String {
    let mut t = rig_text();
    for (en, de) in [
        ("UpLeg", "Oberschenkel"),
        ("ToeBase", "Zehen"),
        ("Toe_End", "Zehenspitze"),
        ("Leg", "Knie"),
        ("Foot", "Fuss"),
    ] {
        t = t.replace(&format!("Left{en}"), &format!("{de}_L"));
        t = t.replace(&format!("Right{en}"), &format!("{de}_R"));
    }
    t
}

#[test]
fn rigs_that_cannot_be_mapped_are_located_errors() {
    insta::assert_snapshot!(
        "unknown_leg_names",
        rig_error("german.bvh", &german(), None)
    );
    let map = "# German leg names\nleft_hip = \"Oberschenkel_L\"\nright_hip = \"Oberschenkel_R\"\nleft_knee = \"Knie_L\"\nright_knee = \"Knie_R\"\nleft_ankle = \"Fuss_L\"\nright_ankle = \"Fuss_R\"\nleft_foot = \"Zehen_L\"\nright_foot = \"Zehen_R\"\n";
    let ch = Character::from_text(("german.bvh", &german()), Some(("map.toml", map))).unwrap();
    assert!(
        ch.summary().contains("and the mapping file"),
        "{}",
        ch.summary()
    );
    // Names that say nothing: the suggestions come from the rig's shape.
    let mut numbered = rig_text();
    let names: Vec<String> = numbered
        .lines()
        .filter_map(|l| {
            let t = l.trim_start();
            t.strip_prefix("JOINT ")
                .or_else(|| t.strip_prefix("ROOT "))
                .map(String::from)
        })
        .collect();
    for (i, n) in names.iter().enumerate() {
        numbered = numbered.replace(&format!(" {n}\n"), &format!(" j{i:02}\n"));
    }
    insta::assert_snapshot!(
        "numbered_joints",
        rig_error("numbered.bvh", &numbered, None)
    );
    insta::assert_snapshot!(
        "map_names_a_missing_joint",
        rig_error("german.bvh", &german(), Some("left_knee = \"Knee_L\"\n"))
    );
    // Arms on the wrong side of the hierarchy for what the mapping file says.
    insta::assert_snapshot!(
        "map_breaks_the_hierarchy",
        rig_error(
            "rig.bvh",
            &rig_text(),
            Some("left_elbow = \"RightForeArm\"\nright_elbow = \"LeftForeArm\"\n")
        )
    );
    // The left forearm with two rotation channels only.
    let text = rig_text();
    let at = text.find("JOINT LeftForeArm").unwrap();
    let channels = "CHANNELS 3 Zrotation Xrotation Yrotation";
    let c = at + text[at..].find(channels).unwrap();
    let two_channels = format!(
        "{}CHANNELS 2 Zrotation Xrotation{}",
        &text[..c],
        &text[c + channels.len()..]
    );
    insta::assert_snapshot!(
        "two_rotation_channels",
        rig_error("rig.bvh", &two_channels, None)
    );
    let fixed = rig_text().replace(
        "CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation",
        "CHANNELS 3 Zrotation Xrotation Yrotation",
    );
    insta::assert_snapshot!("nothing_moves", rig_error("rig.bvh", &fixed, None));
    let upside_down = edit_offsets(&rig_text(), |_, o| -o);
    insta::assert_snapshot!("upside_down", rig_error("rig.bvh", &upside_down, None));
    let flat_knee = edit_offsets(&rig_text(), |name, o| {
        if name == "LeftFoot" { DVec3::ZERO } else { o }
    });
    insta::assert_snapshot!("zero_length_shin", rig_error("rig.bvh", &flat_knee, None));
    insta::assert_snapshot!(
        "syntax",
        rig_error(
            "rig.bvh",
            &rig_text().replacen("OFFSET 0 9.5 0.5", "OFFSET 0 nine 0.5", 1),
            None
        )
    );
}

#[test]
fn a_bad_rig_on_the_command_line_writes_nothing() {
    let (_, clip) = common::golden();
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("clip.npy");
    write_npy(&input, &clip);
    let rig = dir.path().join("german.bvh");
    std::fs::write(&rig, german()).unwrap();
    let (npy, bvh) = (dir.path().join("o.npy"), dir.path().join("o.bvh"));
    let out = mprog(&[
        "convert".as_ref(),
        input.as_os_str(),
        "--rig".as_ref(),
        rig.as_os_str(),
        "-o".as_ref(),
        npy.as_os_str(),
        bvh.as_os_str(),
    ]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success());
    assert!(
        err.contains("german.bvh") && err.contains("left_knee"),
        "{err}"
    );
    assert!(!npy.exists() && !bvh.exists(), "nothing written");
    // A broken glTF rig (its header cut short) is refused, saying so; nothing written.
    let glb = dir.path().join("character.glb");
    std::fs::write(&glb, b"glTF").unwrap();
    let out = mprog(&[
        "convert".as_ref(),
        input.as_os_str(),
        "--rig".as_ref(),
        glb.as_os_str(),
        "-o".as_ref(),
        bvh.as_os_str(),
    ]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("cannot read the .glb rig") && err.contains("byte 4"),
        "{err}"
    );
    assert!(!out.status.success() && !bvh.exists(), "nothing written");
    // --rig needs a .bvh or .glb output, --rig-map needs --rig.
    let out = mprog(&[
        "convert".as_ref(),
        input.as_os_str(),
        "--rig".as_ref(),
        rig_path().as_os_str(),
        "-o".as_ref(),
        npy.as_os_str(),
    ]);
    assert!(String::from_utf8_lossy(&out.stderr).contains("--rig"));
    assert!(!out.status.success() && !npy.exists());
}

/// Blender's own BVH and glTF importers read the outputs on the rig as mprog's reader does,
/// with the feet on the floor:
/// `cargo test --test retarget_rig -- --ignored blender --nocapture`.
#[test]
#[ignore = "needs Blender (apt-get install blender python3-numpy); run by hand"]
fn blender_reads_the_rig_outputs_as_mprog_does() {
    if Command::new("blender").arg("--version").output().is_err() {
        println!("SKIPPED: blender is not installed");
        return;
    }
    let (_, clip) = common::golden();
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("clip.npy");
    write_npy(&input, &clip);
    let (bvh, glb) = (dir.path().join("rig.bvh"), dir.path().join("rig.glb"));
    convert_onto(&input, &rig_path(), None, &[bvh.clone(), glb.clone()]);
    let expected = dir.path().join("expected.npy");
    let out = mprog(&[
        "convert".as_ref(),
        bvh.as_os_str(),
        "-o".as_ref(),
        expected.as_os_str(),
    ]);
    assert!(out.status.success());
    let names = "Hips,LeftUpLeg,RightUpLeg,Spine,LeftLeg,RightLeg,Spine1,LeftFoot,RightFoot,Spine2,LeftToeBase,RightToeBase,Neck,LeftShoulder,RightShoulder,Head,LeftArm,RightArm,LeftForeArm,RightForeArm,LeftHand,RightHand";
    let scripts = concat!(env!("CARGO_MANIFEST_DIR"), "/scripts/");
    for (script, file, extra) in [
        ("blender_check.py", &bvh, vec!["--scale", "0.01"]),
        ("blender_gltf_check.py", &glb, vec![]),
    ] {
        let out = Command::new("blender")
            .args(["-b", "--factory-startup", "--python"])
            .arg(format!("{scripts}{script}"))
            .arg("--")
            .arg(file)
            .arg(&expected)
            .args(["--names", names])
            .args(extra)
            .output()
            .unwrap();
        let stdout = String::from_utf8_lossy(&out.stdout);
        let report: Vec<&str> = stdout
            .lines()
            .filter(|l| l.starts_with("blender_"))
            .collect();
        println!("{}", report.join("\n"));
        assert!(
            out.status.success() && report.iter().any(|l| l.contains(": OK")),
            "{script} failed:\n{stdout}"
        );
        if let Some(line) = report.iter().find(|l| l.contains("feet median lowest")) {
            let lowest: f32 = line.split_whitespace().nth(4).unwrap().parse().unwrap();
            assert!(lowest.abs() < 0.03, "{line}");
        }
    }
}

/// Every BVH the fuzzers and the adversarial tests keep, and each with its text cut short
/// or its numbers mangled, used as a rig: a rig or an error, never a panic; a rig that
/// maps takes a motion and writes both files.
#[test]
fn hostile_rigs_never_panic() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures");
    let mut texts: Vec<(String, String)> = Vec::new();
    for dir in ["fuzz/bvh", "adversarial", "rigs"] {
        for entry in std::fs::read_dir(root.join(dir)).unwrap() {
            let path = entry.unwrap().path();
            if path.extension().is_some_and(|e| e == "bvh")
                && let Ok(text) = std::fs::read_to_string(&path)
            {
                texts.push((path.display().to_string(), text));
            }
        }
    }
    let mut variants = Vec::new();
    for (name, text) in &texts {
        let hierarchy_end = text.find("MOTION").unwrap_or(text.len());
        for cut in [hierarchy_end / 3, hierarchy_end / 2, hierarchy_end * 9 / 10] {
            let cut = (0..=cut).rev().find(|&i| text.is_char_boundary(i)).unwrap();
            variants.push((format!("{name} cut at {cut}"), text[..cut].to_string()));
        }
    }
    // Well-formed rigs made degenerate: every offset zero, huge, tiny, or flattened.
    let text = rig_text();
    variants.push(("zero".into(), edit_offsets(&text, |_, _| DVec3::ZERO)));
    variants.push(("huge".into(), edit_offsets(&text, |_, o| o * 1e30)));
    variants.push(("tiny".into(), edit_offsets(&text, |_, o| o * 1e-30)));
    variants.push((
        "flat".into(),
        edit_offsets(&text, |_, o| DVec3::new(o.x, 0.0, 0.0)),
    ));
    variants.push((
        "line".into(),
        edit_offsets(&text, |_, o| DVec3::new(0.0, o.length(), 0.0)),
    ));
    texts.extend(variants);
    let (_, clip) = common::golden();
    let clip = Motion {
        frames: clip.frames[..5].to_vec(),
        fps: clip.fps,
    };
    let mut mapped = 0;
    for (name, text) in &texts {
        let Ok(rig) = Character::from_text((name, text), None) else {
            continue;
        };
        mapped += 1;
        if let Ok(posed) = rig.retarget(&clip) {
            let bvh = mprog::formats::character::write::bvh_text(&rig, &posed);
            assert!(bvh.starts_with("HIERARCHY"), "{name}");
            mprog::formats::gltf::posed_glb(&[posed]).unwrap();
        }
    }
    println!("{mapped} of {} hostile rigs mapped", texts.len());
    assert!(mapped >= 5, "{mapped} of {} mapped", texts.len());
}
