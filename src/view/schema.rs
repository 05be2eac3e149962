//! The `meta` fields the viewer draws, read and checked: `meta.overlays` (program
//! geometry, the same primitives as [`render::Overlay`](crate::render::Overlay)),
//! `meta.contacts` (joint pairs between people over frame ranges) and
//! `meta.statement_errors` (one error curve per program statement) and `meta.timeline`
//! (each person's prompts over time, as `mprog run` writes them).
//!
//! Schema (metres, world coordinates, Y up; frames are 0-based and inclusive):
//!
//! ```json
//! "meta": {
//!   "overlays": [
//!     {"kind": "point", "at": [0, 1, 3], "label": "target"},
//!     {"kind": "segment", "from": [0, 0, 0], "to": [1, 0, 2]},
//!     {"kind": "vertical_plane", "point": [0, 0, 4], "normal": [0, 0, 1]},
//!     {"kind": "horizontal_plane", "height": 1.9},
//!     {"kind": "box", "min": [1, 0, 1], "max": [1.5, 0.5, 1.5]}
//!   ],
//!   "contacts": [
//!     {"label": "handshake", "a": {"person": 0, "joint": "right_wrist"},
//!      "b": {"person": 1, "joint": "right_wrist"}, "frames": [40, 80]}
//!   ],
//!   "statement_errors": [
//!     {"label": "line 3: hands apart", "line": 3, "unit": "m", "tolerance": 0.05,
//!      "values": [0.21, 0.18, null, …]}
//!   ],
//!   "timeline": [
//!     [{"from": 0, "to": 160, "prompt": "a person walks forward"},
//!      {"from": 160, "to": 400, "prompt": "a person sits down"}]
//!   ]
//! }
//! ```
//!
//! * `joint` is a name or alias ([`joint_index`]) or an index 0–21; `person` is an index
//!   into the file's people. `frames` may be left out (the whole clip).
//! * `values` has one entry per frame of the longest person; `null` marks frames where the
//!   statement does not apply. `line`, `unit`, `tolerance` and `label` of a contact are
//!   optional.
//! * `timeline` has one list per person (in order; at most one per person, an empty list
//!   for a person without one) of spans covering frames `from ≤ t < to`; a span must
//!   start inside the motion, and one ending past it is cut at its end.
//! * Unknown fields and kinds are errors (a typo must not silently hide geometry); every
//!   error names the entry, e.g. `meta.overlays[2]: …`.
//!
//! [`overlays_to_meta`], [`contacts_to_meta`] and [`statement_errors_to_meta`] write the same
//! schema, so a caller that ran a program can store what it drew.

use super::ViewError;
use crate::motion::Meta;
pub use crate::render::TimelineSpan;
pub use crate::scene::{Contact, JointOf, Overlay};
use crate::skeleton::{JOINT_NAMES, NUM_JOINTS, joint_index};
use glam::{Vec2, Vec3};
use serde::{Deserialize, Serialize};
use serde_json::Value;

/// The error of one program statement over the frames.
#[derive(Clone, Debug, PartialEq)]
pub struct StatementError {
    /// What the chart is titled with (e.g. `line 3: …`).
    pub label: String,
    /// 1-based source line, if known.
    pub line: Option<usize>,
    /// Unit of the values (`m`, `rad`, …).
    pub unit: String,
    /// Value the statement counts as satisfied below, drawn as a dashed line.
    pub tolerance: Option<f64>,
    /// One value per frame; `None` where the statement does not apply.
    pub values: Vec<Option<f64>>,
}

/// Everything the viewer draws besides the people.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ViewExtras {
    /// `meta.timeline`.
    pub timeline: Vec<Vec<TimelineSpan>>,
    /// `meta.overlays`.
    pub overlays: Vec<Overlay>,
    /// `meta.contacts`.
    pub contacts: Vec<Contact>,
    /// `meta.statement_errors`.
    pub statement_errors: Vec<StatementError>,
}

#[derive(Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
enum OverlayDoc {
    Point {
        at: [f32; 3],
        #[serde(default, skip_serializing_if = "Option::is_none")]
        label: Option<String>,
    },
    Segment {
        from: [f32; 3],
        to: [f32; 3],
    },
    VerticalPlane {
        point: [f32; 3],
        normal: [f32; 3],
    },
    HorizontalPlane {
        height: f32,
    },
    Box {
        min: [f32; 3],
        max: [f32; 3],
    },
}

#[derive(Serialize, Deserialize)]
#[serde(untagged)]
enum JointDoc {
    Index(usize),
    Name(String),
}

#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct EndDoc {
    person: usize,
    joint: JointDoc,
}

#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct ContactDoc {
    #[serde(default, skip_serializing_if = "Option::is_none")]
    label: Option<String>,
    a: EndDoc,
    b: EndDoc,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    frames: Option<[usize; 2]>,
}

#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct StatementDoc {
    label: String,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    line: Option<usize>,
    #[serde(default)]
    unit: String,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    tolerance: Option<f64>,
    values: Vec<Option<f64>>,
}

#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct SpanDoc {
    from: usize,
    to: usize,
    prompt: String,
}

/// Reads and checks the viewer's fields of `meta` against `people` people and `frames`
/// frames (of the longest person). Missing fields are empty lists.
pub fn extras_from_meta(
    meta: &Meta,
    people: usize,
    frames: usize,
) -> Result<ViewExtras, ViewError> {
    Ok(ViewExtras {
        timeline: timeline_from_meta(meta, people, frames)?,
        overlays: overlays_from_meta(meta)?,
        contacts: entries(meta, "contacts", |i, doc: ContactDoc| {
            contact(doc, people, frames).map_err(|m| bad("contacts", i, m))
        })?,
        statement_errors: entries(meta, "statement_errors", |i, doc: StatementDoc| {
            statement(doc, frames).map_err(|m| bad("statement_errors", i, m))
        })?,
    })
}

/// Reads and checks `meta.overlays` alone (for renderers that draw only geometry).
pub fn overlays_from_meta(meta: &Meta) -> Result<Vec<Overlay>, ViewError> {
    entries(meta, "overlays", |i, doc: OverlayDoc| {
        overlay(doc).map_err(|m| bad("overlays", i, m))
    })
}

/// Reads and checks `meta.timeline` against `people` people and `frames` frames (for
/// pictures as well as the page); missing, it is empty.
pub fn timeline_from_meta(
    meta: &Meta,
    people: usize,
    frames: usize,
) -> Result<Vec<Vec<TimelineSpan>>, ViewError> {
    let lines = entries(meta, "timeline", |i, docs: Vec<SpanDoc>| {
        docs.into_iter()
            .map(|d| {
                if d.from >= d.to {
                    Err(format!("span {}..{} is empty", d.from, d.to))
                } else if d.from >= frames {
                    Err(format!(
                        "span {}..{} starts past the motion's {frames} frames",
                        d.from, d.to
                    ))
                } else {
                    Ok(TimelineSpan {
                        from: d.from,
                        to: d.to.min(frames),
                        prompt: d.prompt,
                    })
                }
            })
            .collect::<Result<Vec<_>, String>>()
            .map_err(|m| bad("timeline", i, m))
    })?;
    if lines.len() > people {
        return Err(ViewError::BadMeta {
            field: "meta.timeline".into(),
            message: format!(
                "{} timelines for {people} {}",
                lines.len(),
                if people == 1 { "person" } else { "people" }
            ),
        });
    }
    Ok(lines)
}

/// `timeline` (one list of spans per person) in the `meta.timeline` schema.
pub fn timeline_to_meta(timeline: &[Vec<TimelineSpan>]) -> Value {
    let docs: Vec<Vec<SpanDoc>> = timeline
        .iter()
        .map(|line| {
            line.iter()
                .map(|s| SpanDoc {
                    from: s.from,
                    to: s.to,
                    prompt: s.prompt.clone(),
                })
                .collect()
        })
        .collect();
    serde_json::to_value(docs).unwrap_or(Value::Null)
}

/// `overlays` in the `meta.overlays` schema.
pub fn overlays_to_meta(overlays: &[Overlay]) -> Value {
    let docs: Vec<OverlayDoc> = overlays
        .iter()
        .map(|o| match o {
            Overlay::Point { at, label } => OverlayDoc::Point {
                at: at.to_array(),
                label: label.clone(),
            },
            Overlay::Segment { from, to } => OverlayDoc::Segment {
                from: from.to_array(),
                to: to.to_array(),
            },
            Overlay::VerticalPlane { point, normal } => OverlayDoc::VerticalPlane {
                point: point.to_array(),
                normal: normal.to_array(),
            },
            Overlay::HorizontalPlane { height } => OverlayDoc::HorizontalPlane { height: *height },
            Overlay::Box { min, max } => OverlayDoc::Box {
                min: min.to_array(),
                max: max.to_array(),
            },
        })
        .collect();
    serde_json::to_value(docs).unwrap_or(Value::Null)
}

/// `contacts` in the `meta.contacts` schema (joints by canonical name).
pub fn contacts_to_meta(contacts: &[Contact]) -> Value {
    let end = |e: &JointOf| EndDoc {
        person: e.person,
        joint: match JOINT_NAMES.get(e.joint) {
            Some(name) => JointDoc::Name(name.to_string()),
            None => JointDoc::Index(e.joint),
        },
    };
    let docs: Vec<ContactDoc> = contacts
        .iter()
        .map(|c| ContactDoc {
            label: c.label.clone(),
            a: end(&c.a),
            b: end(&c.b),
            frames: Some([c.frames.0, c.frames.1]),
        })
        .collect();
    serde_json::to_value(docs).unwrap_or(Value::Null)
}

/// `errors` in the `meta.statement_errors` schema.
pub fn statement_errors_to_meta(errors: &[StatementError]) -> Value {
    let docs: Vec<StatementDoc> = errors
        .iter()
        .map(|e| StatementDoc {
            label: e.label.clone(),
            line: e.line,
            unit: e.unit.clone(),
            tolerance: e.tolerance,
            values: e.values.clone(),
        })
        .collect();
    serde_json::to_value(docs).unwrap_or(Value::Null)
}

fn bad(field: &str, index: usize, message: String) -> ViewError {
    ViewError::BadMeta {
        field: format!("meta.{field}[{index}]"),
        message,
    }
}

/// Parses every entry of the list `meta.<field>` with `check`.
fn entries<D, T>(
    meta: &Meta,
    field: &str,
    check: impl Fn(usize, D) -> Result<T, ViewError>,
) -> Result<Vec<T>, ViewError>
where
    D: serde::de::DeserializeOwned,
{
    let list = match meta.get(field) {
        None | Some(Value::Null) => return Ok(Vec::new()),
        Some(Value::Array(list)) => list,
        Some(other) => {
            return Err(ViewError::BadMeta {
                field: format!("meta.{field}"),
                message: format!("expected a list, found {}", kind_of(other)),
            });
        }
    };
    list.iter()
        .enumerate()
        .map(|(i, v)| {
            let doc = D::deserialize(v).map_err(|e| bad(field, i, e.to_string()))?;
            check(i, doc)
        })
        .collect()
}

fn kind_of(v: &Value) -> &'static str {
    match v {
        Value::Null => "null",
        Value::Bool(_) => "a boolean",
        Value::Number(_) => "a number",
        Value::String(_) => "a string",
        Value::Array(_) => "a list",
        Value::Object(_) => "an object",
    }
}

fn point(v: [f32; 3], what: &str) -> Result<Vec3, String> {
    let p = Vec3::from(v);
    if p.is_finite() {
        Ok(p)
    } else {
        Err(format!("`{what}` is not finite"))
    }
}

fn overlay(doc: OverlayDoc) -> Result<Overlay, String> {
    Ok(match doc {
        OverlayDoc::Point { at, label } => Overlay::Point {
            at: point(at, "at")?,
            label,
        },
        OverlayDoc::Segment { from, to } => Overlay::Segment {
            from: point(from, "from")?,
            to: point(to, "to")?,
        },
        OverlayDoc::VerticalPlane { point: p, normal } => {
            let normal = point(normal, "normal")?;
            if Vec2::new(normal.x, normal.z).length() < 1e-6 {
                return Err("a vertical plane's `normal` needs a horizontal (x or z) part".into());
            }
            Overlay::VerticalPlane {
                point: point(p, "point")?,
                normal,
            }
        }
        OverlayDoc::HorizontalPlane { height } if height.is_finite() => {
            Overlay::HorizontalPlane { height }
        }
        OverlayDoc::HorizontalPlane { .. } => return Err("`height` is not finite".into()),
        OverlayDoc::Box { min, max } => {
            let (min, max) = (point(min, "min")?, point(max, "max")?);
            if min.cmpgt(max).any() {
                return Err(format!("`min` {min:?} is above `max` {max:?} on some axis"));
            }
            Overlay::Box { min, max }
        }
    })
}

fn end(doc: EndDoc, people: usize, which: &str) -> Result<JointOf, String> {
    if doc.person >= people {
        return Err(format!(
            "`{which}.person` is {}, but there {} {people} {} (indices start at 0)",
            doc.person,
            if people == 1 { "is" } else { "are" },
            if people == 1 { "person" } else { "people" },
        ));
    }
    let joint = match doc.joint {
        JointDoc::Index(j) if j < NUM_JOINTS => j,
        JointDoc::Index(j) => {
            return Err(format!(
                "`{which}.joint` {j} is out of range 0–{}",
                NUM_JOINTS - 1
            ));
        }
        JointDoc::Name(name) => joint_index(&name).ok_or_else(|| {
            format!("`{which}.joint` \"{name}\" is not a joint name (see `mprog joints`)")
        })?,
    };
    Ok(JointOf {
        person: doc.person,
        joint,
    })
}

fn contact(doc: ContactDoc, people: usize, frames: usize) -> Result<Contact, String> {
    let last = frames.saturating_sub(1);
    let range = doc.frames.unwrap_or([0, last]);
    if range[0] > range[1] {
        return Err(format!(
            "`frames` [{}, {}] ends before it starts",
            range[0], range[1]
        ));
    }
    if range[1] > last {
        return Err(format!(
            "`frames` [{}, {}] goes past the last frame {last}",
            range[0], range[1]
        ));
    }
    Ok(Contact {
        label: doc.label,
        a: end(doc.a, people, "a")?,
        b: end(doc.b, people, "b")?,
        frames: (range[0], range[1]),
    })
}

fn statement(doc: StatementDoc, frames: usize) -> Result<StatementError, String> {
    if doc.values.len() != frames {
        return Err(format!(
            "`values` has {} entries, but the motion has {frames} frames (one value per frame; null where the statement does not apply)",
            doc.values.len()
        ));
    }
    if let Some(f) = doc
        .values
        .iter()
        .position(|v| v.is_some_and(|v| !v.is_finite()))
    {
        return Err(format!("`values` at frame {f} is not finite"));
    }
    if let Some(t) = doc.tolerance
        && !t.is_finite()
    {
        return Err("`tolerance` is not finite".into());
    }
    Ok(StatementError {
        label: doc.label,
        line: doc.line,
        unit: doc.unit,
        tolerance: doc.tolerance,
        values: doc.values,
    })
}
