//! What a program adds to a motion's viewer page: each statement's error on every frame
//! (the timeline) and the constant geometry it names (walls, targets, regions).

use super::schema::{contacts_to_meta, overlays_to_meta};
use crate::lang::{EvalError, Program};
use crate::motion::Meta;
use crate::motion::Motion;
use burn::prelude::*;

/// `[1, people, frames, 22, 3]` of one sample (the shortest person sets the frames).
pub fn people_tensor(people: &[Motion], device: &Device) -> Tensor<5> {
    let frames = people.iter().map(Motion::len).min().unwrap_or(0);
    let data: Vec<f32> = people
        .iter()
        .flat_map(|m| Motion::new(m.frames[..frames].to_vec()).to_flat())
        .collect();
    Tensor::from_data(
        TensorData::new(data, [1, people.len(), frames, 22, 3]),
        device,
    )
}

/// `statement_errors` (`[{label, line, unit, values}]`, one value per frame, null where a
/// statement does not apply) and, when the program names any, `overlays` and `contacts`.
pub fn program_meta(
    program: &Program,
    people: &[Motion],
    device: &Device,
) -> Result<Meta, EvalError> {
    let total = people.iter().map(Motion::len).min().unwrap_or(0);
    let frames = program.evaluate_frames(people_tensor(people, device))?;
    let list: Vec<serde_json::Value> = program
        .statements()
        .iter()
        .zip(frames)
        .map(|(s, f)| {
            let mut values: Vec<Option<f32>> = vec![None; total];
            for ((&t, v), a) in f.frames.iter().zip(&f.errors[0]).zip(&f.applies[0]) {
                if *a && t < total {
                    values[t] = Some(*v);
                }
            }
            serde_json::json!({"label": s.label, "line": s.line, "unit": s.unit, "values": values})
        })
        .collect();
    let mut meta = Meta::new();
    meta.insert("statement_errors".into(), serde_json::Value::Array(list));
    if !program.overlays().is_empty() {
        meta.insert("overlays".into(), overlays_to_meta(program.overlays()));
    }
    if !program.contacts().is_empty() {
        meta.insert("contacts".into(), contacts_to_meta(program.contacts()));
    }
    Ok(meta)
}
