//! ASF/AMC on a small CMU-named skeleton: positions against the ASF forward kinematics
//! written out by hand (`p_child = p_parent + length · R_bone · direction`,
//! `R_bone = R_parent · C · M · C⁻¹`), the `cmu-asf` rig table, and located errors.

use super::*;

/// A CMU-named skeleton in ASF units of 1/0.45 inch (as CMU and HDM05 write them).
pub(crate) const ASF: &str = include_str!("../../../tests/fixtures/rigs/asf/HDM_tt.asf");

/// One AMC frame: standing, root turned and bent, a few joints bent.
pub(crate) fn amc_frame(n: usize, knee: f32) -> String {
    format!(
        "{n}\nroot 1.0 17.0 -2.0 5 30 -10\nlowerback 5 0 0\nupperback 0 5 0\nthorax 0 0 5\n\
lowerneck 0 0 0\nupperneck 0 0 0\nhead 10 0 0\nrclavicle 0 0\nrhumerus 10 20 30\nrradius 40\n\
rwrist 0\nlclavicle 0 0\nlhumerus -10 0 -40\nlradius 30\nlwrist 0\nrfemur -20 0 0\n\
rtibia {knee}\nrfoot 0 0\nrtoes 0\nlfemur 0 0 10\nltibia 5\nlfoot 10 0\nltoes 0\n"
    )
}

pub(crate) fn amc(frames: usize) -> String {
    let mut text = String::from("#!OML:ASF test\n:FULLY-SPECIFIED\n:DEGREES\n");
    for i in 0..frames {
        text.push_str(&amc_frame(i + 1, 20.0 + i as f32));
    }
    text
}

/// Positions of every bone's end by the ASF formula, metres.
fn asf_fk(asf: &Asf, frame: &[Vec<f32>]) -> Vec<Vec3> {
    let unit = asf.metres_per_unit;
    let root = &frame[0];
    let root_pos = Vec3::new(root[0], root[1], root[2]) * unit;
    let root_rot = euler(
        Vec3::new(root[3], root[4], root[5]).map(f32::to_radians),
        "XYZ",
    )
    .unwrap();
    let mut rot = vec![Quat::IDENTITY; asf.bones.len()];
    let mut end = vec![Vec3::ZERO; asf.bones.len()];
    // Bones are listed parents-first in this skeleton's :bonedata? Not necessarily: loop.
    let mut done = vec![false; asf.bones.len()];
    while done.iter().any(|d| !d) {
        for (b, bone) in asf.bones.iter().enumerate() {
            if done[b] || bone.parent.is_some_and(|p| !done[p]) {
                continue;
            }
            let (prot, ppos) = match bone.parent {
                Some(p) => (rot[p], end[p]),
                None => (root_rot, root_pos),
            };
            let mut a = Vec3::ZERO;
            for (k, axis) in bone.dof.iter().enumerate() {
                let v = frame[b + 1][k].to_radians();
                match axis {
                    'x' => a.x = v,
                    'y' => a.y = v,
                    _ => a.z = v,
                }
            }
            let m = euler(a, "XYZ").unwrap();
            rot[b] = prot * bone.axis * m * bone.axis.inverse();
            end[b] = ppos + rot[b] * (bone.direction * bone.length * unit);
            done[b] = true;
        }
    }
    end
}

#[test]
fn positions_match_the_asf_formula() {
    let asf = parse_asf("t.asf", ASF).unwrap();
    assert!((asf.metres_per_unit - 0.0254 / 0.45).abs() < 1e-7);
    let text = amc(3);
    let parsed = parse_amc("t.amc", &text, &asf, 100).unwrap();
    let bvh = asf_amc_to_bvh("t.amc", &asf, &text, 120.0, &BvhImportOptions::default()).unwrap();
    let globals = crate::formats::bvh::fk::global_positions(&bvh);
    let per = bvh.joints.len();
    for (f, frame) in parsed.frames.iter().enumerate() {
        let want = asf_fk(&asf, frame);
        for (b, bone) in asf.bones.iter().enumerate() {
            // A bone's end is its first child's joint, or its End Site.
            let j = bvh
                .joints
                .iter()
                .position(|j| {
                    j.parent.is_some_and(|p| bvh.joints[p].name == bone.name)
                        && (j.end_site || j.offset.length() > 0.0)
                })
                .or_else(|| {
                    bvh.joints
                        .iter()
                        .position(|j| j.parent.is_some_and(|p| bvh.joints[p].name == bone.name))
                })
                .unwrap();
            let got = globals[f * per + j];
            assert!(
                (got - want[b]).length() < 1e-4,
                "frame {f} bone {}: {got} vs {}",
                bone.name,
                want[b]
            );
        }
    }
}

#[test]
fn imports_through_the_cmu_asf_table() {
    let asf = parse_asf("t.asf", ASF).unwrap();
    let text = amc(13);
    let bvh = asf_amc_to_bvh("t.amc", &asf, &text, 120.0, &BvhImportOptions::default()).unwrap();
    let out = import_parsed("t.amc", bvh, &BvhImportOptions::default()).unwrap();
    assert_eq!(out.joint_map.rig, "cmu-asf");
    assert_eq!(out.source_fps, 120.0);
    // 13 frames at 120 fps → 3 frames at 20 fps (0, 6, 12).
    assert_eq!(out.motion.frames.len(), 3);
    assert_eq!(out.unit_scale, 1.0, "{:?}", out.warnings);
    let p = &out.motion.frames[0];
    // Pelvis at 17 units ≈ 0.96 m; the head above it.
    assert!((p[0].y - 17.0 * 0.0254 / 0.45).abs() < 1e-4);
    assert!(p[15].y > p[12].y && p[12].y > p[0].y);
}

fn asf_error(text: &str) -> (Option<usize>, String) {
    let e = parse_asf("t.asf", text).unwrap_err();
    (e.line, e.to_string())
}

fn amc_error(text: &str) -> (Option<usize>, String) {
    let asf = parse_asf("t.asf", ASF).unwrap();
    let e = parse_amc("t.amc", text, &asf, 100).unwrap_err();
    (e.line, e.to_string())
}

#[test]
fn errors_name_file_and_line() {
    let bad = ASF.replacen("length 7.3", "length seven", 1);
    let (line, msg) = asf_error(&bad);
    assert_eq!(line, Some(24), "{msg}");
    assert!(msg.starts_with("t.asf:24: ASF/AMC: `seven`"), "{msg}");
    let (_, msg) = asf_error(&ASF.replace("lfemur ltibia", "lfemur tibia"));
    assert!(msg.contains("unknown bone `tibia`"), "{msg}");
    let (_, msg) = asf_error(&ASF.replacen("dof rx ry rz", "dof tx ry rz", 1));
    assert!(msg.contains("`tx` is not read"), "{msg}");
    let (_, msg) = asf_error(&ASF.replace("    lfoot ltoes\n", ""));
    assert!(msg.contains("`ltoes` is not in :hierarchy"), "{msg}");

    let good = amc(2);
    let (line, msg) = amc_error(&good.replacen("rradius 40", "rradius 40 2", 1));
    assert_eq!(line, Some(14), "{msg}");
    assert!(msg.contains("`rradius` has 2 values, expected 1"), "{msg}");
    let (_, msg) = amc_error(&good.replacen("head 10 0 0", "hed 10 0 0", 1));
    assert!(msg.contains("unknown bone `hed`"), "{msg}");
    let (line, msg) = amc_error(&good.replacen("ltoes 0\n", "", 1));
    assert_eq!(line, Some(4), "{msg}");
    assert!(msg.contains("frame lacks the `ltoes` line"), "{msg}");
    let (_, msg) = amc_error(&good.replacen("rtibia 20", "rtibia NaN", 1));
    assert!(msg.contains("not a finite number"), "{msg}");
    let (_, msg) = amc_error(":FULLY-SPECIFIED\nroot 0 0 0 0 0 0\n");
    assert!(msg.contains("before the first frame number"), "{msg}");
    let (_, msg) = amc_error(":DEGREES\n");
    assert!(msg.contains("no frames"), "{msg}");
}

#[test]
fn fps_from_the_name() {
    assert_eq!(amc_fps(Path::new("HDM_bd_squat1Reps_001_120.amc")), 120.0);
    assert_eq!(amc_fps(Path::new("x/07_01.amc")), 120.0);
    assert_eq!(amc_fps(Path::new("walk_60.amc")), 60.0);
}

#[test]
fn zyx_round_trip() {
    let q = euler(Vec3::new(0.3, -0.7, 1.1), "XYZ").unwrap();
    let [z, y, x] = zyx_degrees(q);
    let back = Quat::from_rotation_z(z.to_radians())
        * Quat::from_rotation_y(y.to_radians())
        * Quat::from_rotation_x(x.to_radians());
    assert!(q.dot(back).abs() > 1.0 - 1e-6);
}
