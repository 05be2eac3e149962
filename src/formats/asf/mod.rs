//! ASF/AMC import: the CMU and HDM05 databases' own format, read into the BVH pipeline.
//!
//! In: an `.asf` skeleton and an `.amc` motion. Out: a [`BvhImport`] (22 joints, metres,
//! 20 fps), made by turning the pair into a [`Bvh`] in memory, one joint per ASF bone
//! placed where the bone starts (as the cgspeed and HDM05 BVH conversions do), and
//! handing it to [`import_parsed`]: the `cmu-asf` rig table, scale from the leg,
//! resampling. Local rotations are the ASF's `C · M · C⁻¹` (`C` the bone's `axis`, `M` the
//! AMC angles, X then Y then Z about fixed axes), written as Z-Y-X channels.
//!
//! AMC files carry no frame rate: it is read from a `_<fps>` stem suffix (HDM05:
//! `HDM_bd_squat1Reps_001_120.amc`), else CMU's 120.

mod parse;

pub use parse::{Amc, Asf, Bone, euler, parse_amc, parse_asf};

use crate::formats::bvh::parse::{Axis, BvhJoint, Channel};
use crate::formats::bvh::{
    Bvh, BvhError, BvhErrorKind, BvhImport, BvhImportOptions, import_parsed, text,
};
use glam::{EulerRot, Quat, Vec3};
use std::path::{Path, PathBuf};

/// Frame rate of CMU's AMC files when the name gives none.
pub const DEFAULT_AMC_FPS: f32 = 120.0;

/// Biggest ASF or AMC file read (an hour of 120 fps AMC is about 150 MB).
const MAX_BYTES: u64 = 256 << 20;

fn read(path: &Path) -> Result<String, BvhError> {
    let origin = path.display().to_string();
    let io = |e: std::io::Error| BvhError::whole(&origin, BvhErrorKind::Io(e.to_string()));
    let size = std::fs::metadata(path).map_err(io)?.len();
    if size > MAX_BYTES {
        return Err(BvhError::whole(
            &origin,
            BvhErrorKind::FileTooLarge {
                size,
                limit: MAX_BYTES,
            },
        ));
    }
    let bytes = std::fs::read(path).map_err(io)?;
    // ASF files from VICON are Latin-1 at worst in comments: keep what is ASCII.
    let text = match text::decode(&origin, &bytes) {
        Ok(t) => t.to_string(),
        Err(e) if e.kind == BvhErrorKind::NotUtf8 => bytes.iter().map(|&b| b as char).collect(),
        Err(e) => return Err(e),
    };
    Ok(text)
}

/// The `.asf` of an `.amc`: the only `.asf` in its folder, else `<subject>.asf` from the
/// stem's first `_`-field (`07_01.amc` → `07.asf`), else `HDM_<actor>.asf`, looked for in
/// the folder and in an `_asf` folder beside it or one level up.
pub fn find_asf(amc: &Path) -> Option<PathBuf> {
    let dir = amc.parent()?;
    let stem = amc.file_stem()?.to_string_lossy().to_string();
    let fields: Vec<&str> = stem.split('_').collect();
    let mut names = vec![format!("{}.asf", fields[0])];
    if fields.len() > 1 {
        names.push(format!("{}_{}.asf", fields[0], fields[1]));
    }
    let mut dirs = vec![dir.to_path_buf(), dir.join("_asf")];
    dirs.extend(dir.parent().map(|p| p.join("_asf")));
    for d in &dirs {
        for n in &names {
            let p = d.join(n);
            if p.is_file() {
                return Some(p);
            }
        }
    }
    let mut asfs: Vec<PathBuf> = std::fs::read_dir(dir)
        .ok()?
        .flatten()
        .map(|e| e.path())
        .filter(|p| p.extension().is_some_and(|x| x.eq_ignore_ascii_case("asf")))
        .collect();
    (asfs.len() == 1).then(|| asfs.remove(0))
}

/// Frame rate from a `_<fps>` stem suffix, else [`DEFAULT_AMC_FPS`].
pub fn amc_fps(amc: &Path) -> f32 {
    amc.file_stem()
        .and_then(|s| s.to_string_lossy().rsplit('_').next().map(str::to_string))
        .and_then(|f| f.parse::<u32>().ok())
        .filter(|f| (24..=480).contains(f))
        .map_or(DEFAULT_AMC_FPS, |f| f as f32)
}

/// Imports an `.amc` with the `.asf` that [`find_asf`] finds.
pub fn import_amc_beside_asf(amc: &Path, opts: &BvhImportOptions) -> Result<BvhImport, BvhError> {
    let asf = find_asf(amc).ok_or_else(|| {
        BvhError::whole(
            &amc.display().to_string(),
            BvhErrorKind::Asf(
                "no .asf skeleton found beside it (same folder, `_asf/`, or <subject>.asf)".into(),
            ),
        )
    })?;
    import_asf_amc(&asf, amc, opts)
}

/// Imports an `.asf` + `.amc` pair.
pub fn import_asf_amc(
    asf: &Path,
    amc: &Path,
    opts: &BvhImportOptions,
) -> Result<BvhImport, BvhError> {
    let asf_text = read(asf)?;
    let amc_text = read(amc)?;
    let skeleton = parse_asf(&asf.display().to_string(), &asf_text)?;
    let origin = amc.display().to_string();
    let bvh = asf_amc_to_bvh(&origin, &skeleton, &amc_text, amc_fps(amc), opts)?;
    import_parsed(&origin, bvh, opts)
}

/// ASF skeleton + AMC text → the equivalent [`Bvh`] (metres per ASF units, Z-Y-X channels).
pub fn asf_amc_to_bvh(
    origin: &str,
    asf: &Asf,
    amc_text: &str,
    fps: f32,
    opts: &BvhImportOptions,
) -> Result<Bvh, BvhError> {
    let channels_per_frame = 6 + 3 * asf.bones.len();
    let max_frames = (opts.limits.max_values / channels_per_frame as u64).max(1) as usize;
    let amc = parse_amc(origin, amc_text, asf, max_frames)?;
    let unit = asf.metres_per_unit;
    let rotations = || {
        vec![
            Channel::Rotation(Axis::Z),
            Channel::Rotation(Axis::Y),
            Channel::Rotation(Axis::X),
        ]
    };
    let mut joints = vec![BvhJoint {
        name: "root".into(),
        parent: None,
        offset: asf.root_position * unit,
        channels: [
            Channel::Position(Axis::X),
            Channel::Position(Axis::Y),
            Channel::Position(Axis::Z),
        ]
        .into_iter()
        .chain(rotations())
        .collect(),
        first_channel: 0,
        end_site: false,
        line: 1,
    }];
    // Bones in an order where parents come first (BVH needs it), joint index per bone.
    let mut order: Vec<usize> = vec![];
    let mut joint_of = vec![usize::MAX; asf.bones.len()];
    let mut pending: Vec<Option<usize>> = vec![None];
    while let Some(parent) = pending.pop() {
        for (b, bone) in asf.bones.iter().enumerate().rev() {
            if bone.parent == parent {
                order.push(b);
                pending.push(Some(b));
            }
        }
    }
    for &b in &order {
        let bone = &asf.bones[b];
        let (parent_joint, offset) = match bone.parent {
            None => (0, Vec3::ZERO),
            Some(p) => {
                let pb = &asf.bones[p];
                (joint_of[p], pb.direction * pb.length * unit)
            }
        };
        joint_of[b] = joints.len();
        joints.push(BvhJoint {
            name: bone.name.clone(),
            parent: Some(parent_joint),
            offset,
            channels: rotations(),
            first_channel: 6 + 3 * (joints.len() - 1),
            end_site: false,
            line: bone.line,
        });
    }
    for (b, bone) in asf.bones.iter().enumerate() {
        if !asf.bones.iter().any(|c| c.parent == Some(b)) {
            joints.push(BvhJoint {
                name: format!("{} End", bone.name),
                parent: Some(joint_of[b]),
                offset: bone.direction * bone.length * unit,
                channels: vec![],
                first_channel: 6 + 3 * asf.bones.len(),
                end_site: true,
                line: bone.line,
            });
        }
    }
    let angle = |a: f32| if asf.degrees { a.to_radians() } else { a };
    let mut values = Vec::with_capacity(amc.frames.len() * channels_per_frame);
    for frame in &amc.frames {
        let root = &frame[0];
        let get = |name: &str| {
            asf.root_order
                .iter()
                .position(|o| o == name)
                .map_or(0.0, |i| root[i])
        };
        values.extend([get("tx") * unit, get("ty") * unit, get("tz") * unit]);
        let r = euler(
            Vec3::new(angle(get("rx")), angle(get("ry")), angle(get("rz"))),
            &asf.root_axis,
        )
        .unwrap_or(Quat::IDENTITY);
        values.extend(zyx_degrees(r));
        for &b in &order {
            let bone = &asf.bones[b];
            let mut a = Vec3::ZERO;
            for (k, axis) in bone.dof.iter().enumerate() {
                let v = angle(frame[b + 1][k]);
                match axis {
                    'x' => a.x = v,
                    'y' => a.y = v,
                    _ => a.z = v,
                }
            }
            let m = euler(a, "XYZ").expect("fixed order");
            values.extend(zyx_degrees(bone.axis * m * bone.axis.inverse()));
        }
    }
    Ok(Bvh {
        joints,
        channel_count: channels_per_frame,
        frame_time: 1.0 / fps,
        frame_count: amc.frames.len(),
        values,
    })
}

/// `[z, y, x]` degrees with `q = Rz · Ry · Rx` (the order of Z-Y-X BVH channels).
fn zyx_degrees(q: Quat) -> [f32; 3] {
    let (z, y, x) = q.to_euler(EulerRot::ZYX);
    [z.to_degrees(), y.to_degrees(), x.to_degrees()]
}

#[cfg(test)]
mod tests;
