//! The user's mapping file (`--rig-map map.toml`): for the joints mprog cannot match by
//! name, which rig joint is which HumanML3D joint.
//!
//! In: TOML text, one `humanml3d_joint = "rig joint"` per line (joint names or their
//! aliases, `mprog joints` lists them), and the rig's joints. Out: (HumanML3D joint, rig
//! joint, line) triples. A rig joint name matches exactly, else ignoring case, else ignoring
//! a namespace such as `mixamorig:`. Every mistake is an error at its line, with the
//! nearest names as suggestions.

use super::error::{RigError, RigErrorKind};
use crate::formats::bvh::BvhJoint;
use crate::skeleton::{JOINT_NAMES, all_joint_names, joint_index};

/// One line of the mapping file.
#[derive(Clone, Debug, PartialEq)]
pub struct MapEntry {
    /// HumanML3D joint.
    pub joint: usize,
    /// Rig joint (index into the rig's joints).
    pub rig_joint: usize,
    /// Line of the entry.
    pub line: usize,
}

/// Reads a mapping file's text; `origin` names it in errors.
pub fn parse_map(origin: &str, text: &str, rig: &[BvhJoint]) -> Result<Vec<MapEntry>, RigError> {
    let table: toml::Table = toml::from_str(text).map_err(|e| {
        let line = e.span().map_or(1, |s| line_of_offset(text, s.start));
        RigError::at(
            origin,
            line,
            RigErrorKind::MapSyntax(e.message().trim().to_string()),
        )
    })?;
    let mut lines: Vec<(usize, &String, &toml::Value)> = table
        .iter()
        .map(|(key, value)| (line_of_key(text, key), key, value))
        .collect();
    lines.sort_by_key(|(line, _, _)| *line);
    let mut entries: Vec<MapEntry> = Vec::new();
    for (line, key, value) in lines {
        let at = |kind| RigError::at(origin, line, kind);
        let joint = joint_index(key).ok_or_else(|| {
            at(RigErrorKind::MapUnknownJoint {
                key: key.clone(),
                suggestions: nearest(key, all_joint_names(), 3),
            })
        })?;
        let Some(value) = value.as_str() else {
            return Err(at(RigErrorKind::MapNotString { key: key.clone() }));
        };
        let rig_joint = find_rig_joint(rig, value).ok_or_else(|| {
            let names = rig.iter().filter(|j| !j.end_site).map(|j| j.name.as_str());
            at(RigErrorKind::MapUnknownRigJoint {
                key: key.clone(),
                value: value.to_string(),
                suggestions: nearest(value, names, 3),
            })
        })?;
        if let Some(first) = entries.iter().find(|e| e.rig_joint == rig_joint) {
            return Err(at(RigErrorKind::MapTwice {
                value: value.to_string(),
                first: JOINT_NAMES[first.joint],
                second: JOINT_NAMES[joint],
            }));
        }
        entries.push(MapEntry {
            joint,
            rig_joint,
            line,
        });
    }
    Ok(entries)
}

/// The rig joint called `name`: exactly, else ignoring case, else ignoring namespaces.
fn find_rig_joint(rig: &[BvhJoint], name: &str) -> Option<usize> {
    let bare = |s: &str| s.rsplit(':').next().unwrap_or(s).to_ascii_lowercase();
    let joints = || rig.iter().enumerate().filter(|(_, j)| !j.end_site);
    joints()
        .find(|(_, j)| j.name == name)
        .or_else(|| joints().find(|(_, j)| j.name.eq_ignore_ascii_case(name)))
        .or_else(|| joints().find(|(_, j)| bare(&j.name) == bare(name)))
        .map(|(i, _)| i)
}

/// 1-based line of a byte offset.
fn line_of_offset(text: &str, offset: usize) -> usize {
    text[..offset.min(text.len())].matches('\n').count() + 1
}

/// 1-based line where `key` is assigned (1 if it cannot be found).
fn line_of_key(text: &str, key: &str) -> usize {
    text.lines()
        .position(|l| {
            let l = l.trim_start();
            let rest = l
                .strip_prefix(key)
                .or_else(|| l.strip_prefix(&format!("\"{key}\"")))
                .or_else(|| l.strip_prefix(&format!("'{key}'")));
            rest.is_some_and(|r| r.trim_start().starts_with('='))
        })
        .map_or(1, |i| i + 1)
}

/// Up to `count` of `names` closest to `word` (edit distance on lower case, within a
/// third of the word's length), closest first.
pub fn nearest<'a>(word: &str, names: impl Iterator<Item = &'a str>, count: usize) -> Vec<String> {
    let w = word.to_ascii_lowercase();
    let mut scored: Vec<(usize, String)> = names
        .map(|n| (edit_distance(&w, &n.to_ascii_lowercase()), n.to_string()))
        .filter(|(d, _)| *d <= (w.chars().count() / 3).max(1))
        .collect();
    scored.sort();
    scored.dedup_by(|a, b| a.1 == b.1);
    scored.into_iter().take(count).map(|(_, n)| n).collect()
}

/// Levenshtein distance between two strings, by characters.
pub fn edit_distance(a: &str, b: &str) -> usize {
    let b: Vec<char> = b.chars().collect();
    let mut row: Vec<usize> = (0..=b.len()).collect();
    for (i, ca) in a.chars().enumerate() {
        let mut prev = row[0];
        row[0] = i + 1;
        for (j, &cb) in b.iter().enumerate() {
            let cur = row[j + 1];
            row[j + 1] = (prev + usize::from(ca != cb)).min(row[j] + 1).min(cur + 1);
            prev = cur;
        }
    }
    row[b.len()]
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    fn rig(names: &[&str]) -> Vec<BvhJoint> {
        names
            .iter()
            .enumerate()
            .map(|(i, n)| BvhJoint {
                name: n.to_string(),
                parent: i.checked_sub(1),
                offset: Vec3::Y,
                channels: Vec::new(),
                first_channel: 0,
                end_site: false,
                line: i + 2,
            })
            .collect()
    }

    #[test]
    fn entries_resolve_names_aliases_and_namespaces() {
        let r = rig(&["Root_M", "mixamorig:Knee_L", "Hip_L"]);
        let text = "# mine\npelvis = \"Root_M\"\nl_knee = \"knee_l\"\n\"left_hip\" = \"Hip_L\"\n";
        let got = parse_map("m.toml", text, &r).unwrap();
        let pairs: Vec<_> = got.iter().map(|e| (e.joint, e.rig_joint, e.line)).collect();
        assert_eq!(pairs, [(0, 0, 2), (4, 1, 3), (1, 2, 4)]);
    }

    #[test]
    fn mistakes_are_located_with_suggestions() {
        let r = rig(&["Root_M", "Knee_L", "Hip_L"]);
        let err = |text: &str| parse_map("m.toml", text, &r).unwrap_err().to_string();
        assert_eq!(
            err("pelvis = \"Root_M\"\nleft_knea = \"Knee_L\"\n"),
            "m.toml:2: `left_knea` is not a HumanML3D joint; did you mean one of `left_knee`, `left_toe`?"
        );
        assert_eq!(
            err("left_knee = \"Kne_L\"\n"),
            "m.toml:1: `left_knee = \"Kne_L\"`: the rig has no joint `Kne_L`; did you mean `Knee_L`?"
        );
        assert!(err("left_knee = 3\n").starts_with("m.toml:1: `left_knee` must be"));
        assert!(err("\n\nleft_knee = \n").starts_with("m.toml:3: invalid mapping file"));
        assert_eq!(
            err("left_knee = \"Knee_L\"\nright_knee = \"Knee_L\"\n"),
            "m.toml:2: `Knee_L` is given to both left_knee and right_knee"
        );
    }
}
