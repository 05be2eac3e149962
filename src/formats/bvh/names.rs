//! Joint-name normalisation for matching rigs by name.
//!
//! In: a source joint name such as `mixamorig:LeftUpLeg`, `Bip01 L Thigh`, `UpperLeg_L`,
//! `thigh.R`, `l_knee`, `m_avg_L_Hip`, `lShldr`. Out: [`NameParts`]: the body side (if
//! any) and the body-part word, lowercased with separators and trailing digits removed
//! (`upleg`, `thigh`, `upperleg`, `knee`, `hip`, `shldr`).

/// Body side named by a joint.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Side {
    Left,
    Right,
}

/// A joint name split into side and body part.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct NameParts {
    pub side: Option<Side>,
    pub part: String,
}

/// Prefixes of exporters that carry no meaning (checked after lowercasing).
const NOISE_PREFIXES: &[&str] = &[
    "m_avg_", "f_avg_", "bip001", "bip01", "joint_", "jnt_", "def-", "def_",
];

/// Splits a joint name into side and body part.
pub fn split_name(raw: &str) -> NameParts {
    // Namespaces (`mixamorig:`, `Character1:`) carry no body part.
    let name = raw.rsplit(':').next().unwrap_or(raw).trim();
    // `lShldr`, `RHand`: a lone side letter glued to a capitalised word.
    let glued_side = glued_side_letter(name);
    let mut lower = name.to_ascii_lowercase();
    for prefix in NOISE_PREFIXES {
        if let Some(rest) = lower.strip_prefix(prefix) {
            lower = rest.to_string();
        }
    }
    if let Some(prefix) = lower.strip_prefix("mixamorig") {
        lower = prefix.to_string();
    }
    let mut words: Vec<&str> = lower
        .split(|c: char| c == '_' || c == '.' || c == '-' || c.is_whitespace())
        .filter(|w| !w.is_empty())
        .collect();

    let mut side = None;
    words.retain(|w| match side_word(w) {
        Some(s) if side.is_none() => {
            side = Some(s);
            false
        }
        _ => true,
    });
    let mut part: String = words.concat();
    if side.is_none() {
        if let Some((s, rest)) = camel_side_prefix(&part) {
            side = Some(s);
            part = rest.to_string();
        } else if let Some(s) = glued_side {
            side = Some(s);
            part.remove(0);
        }
    }
    let part = part
        .trim_end_matches(|c: char| c.is_ascii_digit())
        .to_string();
    NameParts { side, part }
}

fn side_word(word: &str) -> Option<Side> {
    match word {
        "l" | "left" | "lft" => Some(Side::Left),
        "r" | "right" | "rgt" => Some(Side::Right),
        _ => None,
    }
}

/// `leftupleg` → (Left, `upleg`).
fn camel_side_prefix(part: &str) -> Option<(Side, &str)> {
    for (prefix, side) in [("left", Side::Left), ("right", Side::Right)] {
        if let Some(rest) = part.strip_prefix(prefix)
            && !rest.is_empty()
        {
            return Some((side, rest));
        }
    }
    None
}

/// `lShldr` / `RHand` → the side of the first letter.
fn glued_side_letter(name: &str) -> Option<Side> {
    let mut chars = name.chars();
    let first = chars.next()?;
    let second = chars.next()?;
    if !second.is_ascii_uppercase() {
        return None;
    }
    match first {
        'l' | 'L' => Some(Side::Left),
        'r' | 'R' => Some(Side::Right),
        _ => None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parts(name: &str) -> (Option<Side>, String) {
        let p = split_name(name);
        (p.side, p.part)
    }

    #[test]
    fn common_rig_names() {
        use Side::*;
        assert_eq!(parts("UpperLeg_L"), (Some(Left), "upperleg".into()));
        assert_eq!(parts("Shoulder_R"), (Some(Right), "shoulder".into()));
        assert_eq!(parts("mixamorig:LeftUpLeg"), (Some(Left), "upleg".into()));
        assert_eq!(parts("mixamorig:Spine2"), (None, "spine".into()));
        assert_eq!(parts("RightForeArm"), (Some(Right), "forearm".into()));
        assert_eq!(parts("LeftToeBase"), (Some(Left), "toebase".into()));
        assert_eq!(parts("Bip01 L Thigh"), (Some(Left), "thigh".into()));
        assert_eq!(parts("thigh.R"), (Some(Right), "thigh".into()));
        assert_eq!(parts("l_knee"), (Some(Left), "knee".into()));
        assert_eq!(parts("m_avg_L_Hip"), (Some(Left), "hip".into()));
        assert_eq!(parts("lShldr"), (Some(Left), "shldr".into()));
        assert_eq!(parts("left_collar"), (Some(Left), "collar".into()));
        assert_eq!(parts("joint_Root"), (None, "root".into()));
        assert_eq!(parts("Hips"), (None, "hips".into()));
        assert_eq!(parts("LowerBack"), (None, "lowerback".into()));
        assert_eq!(parts("Root"), (None, "root".into()));
        assert_eq!(parts("LHipJoint"), (Some(Left), "hipjoint".into()));
        assert_eq!(parts("neck_01"), (None, "neck".into()));
    }
}
