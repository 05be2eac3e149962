//! ASF skeleton and AMC motion text → [`Asf`] and [`Amc`].
//!
//! ASF: `:units` (length: 1/length inches per unit, angle deg|rad), `:root` (order, axis,
//! position, orientation), `:bonedata` (`begin … end` blocks: name, direction, length,
//! axis + order, dof), `:hierarchy` (`parent child…` lines). AMC: optional `:`-keywords,
//! then per frame a line with the frame number and one `bone values…` line per bone with
//! degrees of freedom. Every error names the file and line.

use crate::formats::bvh::{BvhError, BvhErrorKind};
use glam::{Quat, Vec3};

/// One ASF bone.
#[derive(Clone, Debug, PartialEq)]
pub struct Bone {
    pub name: String,
    /// Unit direction in the rest pose (world frame).
    pub direction: Vec3,
    /// Length in ASF units.
    pub length: f32,
    /// Rotation of the bone's local frame (ASF `axis`).
    pub axis: Quat,
    /// Degrees of freedom in AMC order: `rx`, `ry`, `rz` (translations are refused).
    pub dof: Vec<char>,
    /// Parent bone index; `None` for bones hanging off the root.
    pub parent: Option<usize>,
    /// Line of the bone's `begin`.
    pub line: usize,
}

/// A parsed ASF skeleton.
#[derive(Clone, Debug, PartialEq)]
pub struct Asf {
    /// Metres per ASF length unit (`0.0254 / length`).
    pub metres_per_unit: f32,
    /// True when angles are in degrees.
    pub degrees: bool,
    /// Root value order in AMC lines, e.g. `[TX, TY, TZ, RX, RY, RZ]` as `tx`… .
    pub root_order: Vec<String>,
    /// Root rotation axis order, e.g. `XYZ`.
    pub root_axis: String,
    /// Root rest position (ASF units).
    pub root_position: Vec3,
    /// Bones in file order; parents are resolved from `:hierarchy`.
    pub bones: Vec<Bone>,
}

/// Frames of an AMC file: per frame, root values then each bone's values (ASF order).
#[derive(Clone, Debug, PartialEq)]
pub struct Amc {
    /// `[frame][0]` = root values (6), `[frame][1 + b]` = values of bone `b`.
    pub frames: Vec<Vec<Vec<f32>>>,
    /// Line of each frame's number, for errors.
    pub lines: Vec<usize>,
}

fn err(origin: &str, line: usize, what: impl Into<String>) -> BvhError {
    BvhError::at(origin, line, BvhErrorKind::Asf(what.into()))
}

fn number(origin: &str, line: usize, word: &str) -> Result<f32, BvhError> {
    match word.parse::<f32>() {
        Ok(v) if v.is_finite() => Ok(v),
        _ => Err(err(
            origin,
            line,
            format!("`{word}` is not a finite number"),
        )),
    }
}

fn vec3(origin: &str, line: usize, words: &[&str]) -> Result<Vec3, BvhError> {
    if words.len() < 3 {
        return Err(err(origin, line, "expected three numbers"));
    }
    Ok(Vec3::new(
        number(origin, line, words[0])?,
        number(origin, line, words[1])?,
        number(origin, line, words[2])?,
    ))
}

/// Rotation of Euler angles (radians) applied in `order` (`XYZ`: X first, then Y, then Z,
/// about fixed axes), the ASF/AMC convention: `R = R_Z · R_Y · R_X`.
pub fn euler(angles: Vec3, order: &str) -> Option<Quat> {
    let mut q = Quat::IDENTITY;
    for axis in order.chars() {
        let r = match axis.to_ascii_uppercase() {
            'X' => Quat::from_rotation_x(angles.x),
            'Y' => Quat::from_rotation_y(angles.y),
            'Z' => Quat::from_rotation_z(angles.z),
            _ => return None,
        };
        q = r * q;
    }
    (order.len() == 3).then_some(q)
}

/// Parses ASF text.
pub fn parse_asf(origin: &str, text: &str) -> Result<Asf, BvhError> {
    let mut asf = Asf {
        metres_per_unit: 0.0254,
        degrees: true,
        root_order: vec![],
        root_axis: "XYZ".into(),
        root_position: Vec3::ZERO,
        bones: vec![],
    };
    let mut section = String::new();
    let mut bone: Option<(Bone, [f32; 3], String)> = None;
    let mut hierarchy: Vec<(usize, Vec<String>)> = vec![];
    for (i, raw) in text.lines().enumerate() {
        let line = i + 1;
        let words: Vec<&str> = raw.split_whitespace().collect();
        let Some(&first) = words.first() else {
            continue;
        };
        if first.starts_with('#') {
            continue;
        }
        if let Some(name) = first.strip_prefix(':') {
            if bone.is_some() {
                return Err(err(origin, line, "bone block not closed with `end`"));
            }
            section = name.to_ascii_lowercase();
            continue;
        }
        let rest = &words[1..];
        match section.as_str() {
            "units" => match first {
                "length" => {
                    let l = number(origin, line, rest.first().copied().unwrap_or(""))?;
                    if l <= 0.0 {
                        return Err(err(origin, line, "`length` must be positive"));
                    }
                    asf.metres_per_unit = 0.0254 / l;
                }
                "angle" => asf.degrees = !rest.first().is_some_and(|a| a.starts_with("rad")),
                _ => {}
            },
            "root" => match first {
                "order" => asf.root_order = rest.iter().map(|w| w.to_ascii_lowercase()).collect(),
                "axis" => asf.root_axis = rest.first().unwrap_or(&"").to_string(),
                "position" => asf.root_position = vec3(origin, line, rest)?,
                _ => {}
            },
            "bonedata" => bone_line(origin, line, first, rest, &mut bone, &mut asf)?,
            "hierarchy" if first != "begin" && first != "end" => {
                hierarchy.push((line, words.iter().map(|w| w.to_string()).collect()));
            }
            _ => {}
        }
    }
    if asf.bones.is_empty() {
        return Err(err(
            origin,
            text.lines().count().max(1),
            "no :bonedata bones",
        ));
    }
    let expected = ["tx", "ty", "tz", "rx", "ry", "rz"];
    let listed = |e: &&str| asf.root_order.iter().any(|o| o.as_str() == *e);
    if asf.root_order.len() != 6 || !expected.iter().all(listed) {
        return Err(err(origin, 1, "`:root order` must list TX TY TZ RX RY RZ"));
    }
    link(origin, &mut asf, &hierarchy)?;
    Ok(asf)
}

/// One line inside `:bonedata`.
fn bone_line(
    origin: &str,
    line: usize,
    first: &str,
    rest: &[&str],
    bone: &mut Option<(Bone, [f32; 3], String)>,
    asf: &mut Asf,
) -> Result<(), BvhError> {
    if first == "begin" {
        *bone = Some((
            Bone {
                name: String::new(),
                direction: Vec3::Y,
                length: 0.0,
                axis: Quat::IDENTITY,
                dof: vec![],
                parent: None,
                line,
            },
            [0.0; 3],
            "XYZ".into(),
        ));
        return Ok(());
    }
    let Some((b, axis, order)) = bone.as_mut() else {
        return Err(err(
            origin,
            line,
            format!("`{first}` outside a bone's begin … end"),
        ));
    };
    match first {
        "name" => b.name = rest.first().unwrap_or(&"").to_string(),
        "direction" => b.direction = vec3(origin, line, rest)?.normalize_or_zero(),
        "length" => b.length = number(origin, line, rest.first().copied().unwrap_or(""))?,
        "axis" => {
            let v = vec3(origin, line, rest)?;
            *axis = [v.x, v.y, v.z];
            *order = rest.get(3).unwrap_or(&"XYZ").to_string();
        }
        "dof" => {
            for d in rest {
                match d.to_ascii_lowercase().as_str() {
                    "rx" => b.dof.push('x'),
                    "ry" => b.dof.push('y'),
                    "rz" => b.dof.push('z'),
                    other => {
                        return Err(err(
                            origin,
                            line,
                            format!("degree of freedom `{other}` is not read (only rx, ry, rz)"),
                        ));
                    }
                }
            }
        }
        "end" => {
            let (mut b, axis, order) = bone.take().expect("checked above");
            if b.name.is_empty() {
                return Err(err(origin, b.line, "bone without a name"));
            }
            let to_rad = |a: f32| if asf.degrees { a.to_radians() } else { a };
            b.axis = euler(Vec3::from(axis.map(to_rad)), &order)
                .ok_or_else(|| err(origin, b.line, format!("axis order `{order}`")))?;
            asf.bones.push(b);
        }
        _ => {}
    }
    Ok(())
}

/// Resolves `:hierarchy` lines into parents; every bone must be reached from the root.
fn link(origin: &str, asf: &mut Asf, hierarchy: &[(usize, Vec<String>)]) -> Result<(), BvhError> {
    let names: Vec<String> = asf.bones.iter().map(|b| b.name.clone()).collect();
    let index = |name: &str| names.iter().position(|n| n == name);
    let mut reached = vec![false; asf.bones.len()];
    for (line, words) in hierarchy {
        let parent = match words[0].as_str() {
            "root" => None,
            name => Some(index(name).ok_or_else(|| {
                err(
                    origin,
                    *line,
                    format!("unknown bone `{name}` in :hierarchy"),
                )
            })?),
        };
        if let Some(p) = parent
            && !reached[p]
        {
            return Err(err(
                origin,
                *line,
                format!("`{}` is listed before its own parent", words[0]),
            ));
        }
        for child in &words[1..] {
            let c = index(child).ok_or_else(|| {
                err(
                    origin,
                    *line,
                    format!("unknown bone `{child}` in :hierarchy"),
                )
            })?;
            if reached[c] {
                return Err(err(
                    origin,
                    *line,
                    format!("bone `{child}` has two parents"),
                ));
            }
            reached[c] = true;
            asf.bones[c].parent = parent;
        }
    }
    if let Some(b) = asf.bones.iter().zip(&reached).find(|(_, r)| !**r) {
        return Err(err(
            origin,
            b.0.line,
            format!("bone `{}` is not in :hierarchy", b.0.name),
        ));
    }
    Ok(())
}

/// Parses AMC text against its skeleton.
pub fn parse_amc(origin: &str, text: &str, asf: &Asf, max_frames: usize) -> Result<Amc, BvhError> {
    let mut amc = Amc {
        frames: vec![],
        lines: vec![],
    };
    let width = |name: &str| -> Option<(usize, usize)> {
        if name == "root" {
            return Some((0, 6));
        }
        let b = asf.bones.iter().position(|b| b.name == name)?;
        Some((b + 1, asf.bones[b].dof.len()))
    };
    let mut current: Option<Vec<Option<Vec<f32>>>> = None;
    let finish = |frame: Option<Vec<Option<Vec<f32>>>>, amc: &mut Amc| -> Result<(), BvhError> {
        let Some(frame) = frame else { return Ok(()) };
        let line = *amc.lines.last().expect("frame has a line");
        let mut values = Vec::with_capacity(frame.len());
        for (slot, v) in frame.into_iter().enumerate() {
            match v {
                Some(v) => values.push(v),
                None if slot > 0 && asf.bones[slot - 1].dof.is_empty() => values.push(vec![]),
                None => {
                    let name = if slot == 0 {
                        "root"
                    } else {
                        &asf.bones[slot - 1].name
                    };
                    return Err(err(origin, line, format!("frame lacks the `{name}` line")));
                }
            }
        }
        amc.frames.push(values);
        Ok(())
    };
    for (i, raw) in text.lines().enumerate() {
        let line = i + 1;
        let words: Vec<&str> = raw.split_whitespace().collect();
        let Some(&first) = words.first() else {
            continue;
        };
        if first.starts_with('#') || first.starts_with(':') {
            continue;
        }
        if words.len() == 1 && first.bytes().all(|b| b.is_ascii_digit()) {
            finish(current.take(), &mut amc)?;
            if amc.frames.len() >= max_frames {
                return Err(err(origin, line, format!("more than {max_frames} frames")));
            }
            amc.lines.push(line);
            current = Some(vec![None; asf.bones.len() + 1]);
            continue;
        }
        let Some(frame) = current.as_mut() else {
            return Err(err(
                origin,
                line,
                format!("`{first}` before the first frame number"),
            ));
        };
        let (slot, count) =
            width(first).ok_or_else(|| err(origin, line, format!("unknown bone `{first}`")))?;
        if words.len() - 1 != count {
            return Err(err(
                origin,
                line,
                format!("`{first}` has {} values, expected {count}", words.len() - 1),
            ));
        }
        if frame[slot].is_some() {
            return Err(err(
                origin,
                line,
                format!("second `{first}` line in one frame"),
            ));
        }
        let values = words[1..]
            .iter()
            .map(|w| number(origin, line, w))
            .collect::<Result<Vec<_>, _>>()?;
        frame[slot] = Some(values);
    }
    finish(current.take(), &mut amc)?;
    if amc.frames.is_empty() {
        return Err(err(origin, text.lines().count().max(1), "no frames"));
    }
    Ok(amc)
}
