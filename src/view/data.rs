//! The data block embedded in the page: people, skeleton and extras as one compact JSON
//! object that `viewer.js` decodes.
//!
//! ```json
//! {"format": "mprog-view", "version": 1, "title": "…", "fps": 20, "frames": 120,
//!  "joint_names": […22], "parents": […22], "chains": [[0,2,5,8,11], …],
//!  "chain_sides": ["right", "left", "centre", "right", "left"],
//!  "people": [{"name": "person 1", "frames": 120, "mm": [x0, y0, z0, …]}],
//!  "overlays": […], "contacts": […], "statement_errors": […],
//!  "timeline": [[{"from": 0, "to": 160, "prompt": "…"}, …], …]}
//! ```
//!
//! `mm` holds `frames × 22 × 3` integers: frame 0 in millimetres, then every later frame
//! as the millimetre difference from the one before (small numbers, so a 10 s clip is a
//! few tens of kB). Overlays, contacts, statement errors and the timeline use the schema of
//! [`super::schema`], with joints as indices and values rounded to 4 significant digits.

use super::schema::{Contact, StatementError, ViewExtras, overlays_to_meta, timeline_to_meta};
use crate::motion::Motion;
use crate::skeleton::{JOINT_NAMES, KINEMATIC_CHAINS, NUM_JOINTS, PARENTS};
use serde_json::{Value, json};

/// Value of the `format` field of the data block.
pub const DATA_FORMAT: &str = "mprog-view";

/// Which side of the body each of [`KINEMATIC_CHAINS`] is.
const CHAIN_SIDES: [&str; 5] = ["right", "left", "centre", "right", "left"];

/// The data block of `people` (already validated: non-empty, finite, one fps).
pub(crate) fn data_block(
    people: &[Motion],
    names: &[String],
    extras: &ViewExtras,
    title: &str,
) -> Value {
    let frames = people.iter().map(Motion::len).max().unwrap_or(0);
    json!({
        "format": DATA_FORMAT,
        "version": 1,
        "title": title,
        "fps": people.first().map_or(crate::skeleton::FPS, |m| m.fps),
        "frames": frames,
        "joint_names": JOINT_NAMES,
        "parents": PARENTS,
        "chains": KINEMATIC_CHAINS,
        "chain_sides": CHAIN_SIDES,
        "people": people.iter().zip(names).map(|(m, name)| json!({
            "name": name,
            "frames": m.len(),
            "mm": delta_mm(m),
        })).collect::<Vec<_>>(),
        "overlays": overlays_to_meta(&extras.overlays),
        "contacts": extras.contacts.iter().map(contact).collect::<Vec<_>>(),
        "statement_errors": extras.statement_errors.iter().map(statement).collect::<Vec<_>>(),
        "timeline": timeline_to_meta(&extras.timeline),
    })
}

/// Millimetre positions, frame 0 absolute and later frames as differences.
pub(crate) fn delta_mm(m: &Motion) -> Vec<i64> {
    let mut out = Vec::with_capacity(m.len() * NUM_JOINTS * 3);
    let mut prev = [0i64; NUM_JOINTS * 3];
    for pose in &m.frames {
        for (j, p) in pose.iter().enumerate() {
            for (k, v) in p.to_array().into_iter().enumerate() {
                let mm = (f64::from(v) * 1000.0).round() as i64;
                out.push(mm - prev[3 * j + k]);
                prev[3 * j + k] = mm;
            }
        }
    }
    out
}

fn contact(c: &Contact) -> Value {
    json!({
        "label": c.label,
        "a": [c.a.person, c.a.joint],
        "b": [c.b.person, c.b.joint],
        "frames": [c.frames.0, c.frames.1],
    })
}

fn statement(s: &StatementError) -> Value {
    json!({
        "label": s.label,
        "line": s.line,
        "unit": s.unit,
        "tolerance": s.tolerance.map(round4),
        "values": s.values.iter().map(|v| v.map(round4)).collect::<Vec<_>>(),
    })
}

/// `v` to 4 significant digits (so the JSON prints short numbers).
fn round4(v: f64) -> f64 {
    format!("{v:.3e}").parse().unwrap_or(v)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::skeleton::rest_pose;
    use glam::Vec3;

    #[test]
    fn deltas_sum_back_to_millimetres() {
        let frames = (0..5)
            .map(|i| rest_pose().map(|p| p + Vec3::new(0.0123 * i as f32, 0.0, -0.5)))
            .collect();
        let m = Motion::new(frames);
        let d = delta_mm(&m);
        assert_eq!(d.len(), 5 * 66);
        let mut acc = [0i64; 66];
        for (f, chunk) in d.chunks(66).enumerate() {
            for k in 0..66 {
                acc[k] += chunk[k];
                let want = m.frames[f][k / 3].to_array()[k % 3] as f64;
                assert!(
                    (acc[k] as f64 / 1000.0 - want).abs() <= 0.0005 + 1e-6,
                    "frame {f} coord {k}"
                );
            }
        }
        // Later frames of this uniform slide differ by 12 or 13 mm in x, 0 elsewhere.
        assert!(d[66..].iter().all(|&v| v == 0 || v == 12 || v == 13));
    }

    #[test]
    fn round4_keeps_four_significant_digits() {
        assert_eq!(round4(0.0123456), 0.01235);
        assert_eq!(round4(1234.56), 1235.0);
        assert_eq!(round4(0.0), 0.0);
    }
}
