//! The run's loss logs: `loss.csv` (step, train loss, learning rate, seconds) and
//! `val.csv` (step, validation loss of the EMA, seconds), appended at every checkpoint.

use super::{TrainError, file_err};
use std::io::Write;
use std::path::Path;

/// `(step, value)` pairs of column `col` of a CSV written by [`append`] (`loss.csv`,
/// `val.csv`).
pub fn read_curve(path: &Path, col: usize) -> Vec<(f32, f32)> {
    let Ok(text) = std::fs::read_to_string(path) else {
        return Vec::new();
    };
    text.lines()
        .skip(1)
        .filter_map(|l| {
            let mut f = l.split(',');
            let step = f.next()?.parse().ok()?;
            let v = f.nth(col - 1)?.parse().ok()?;
            Some((step, v))
        })
        .collect()
}

pub(super) fn append(path: &Path, header: &str, rows: &str) -> Result<(), TrainError> {
    let new = !path.exists();
    let mut f = std::fs::OpenOptions::new()
        .create(true)
        .append(true)
        .open(path)
        .map_err(|e| file_err(path, e))?;
    if new {
        f.write_all(header.as_bytes())
            .map_err(|e| file_err(path, e))?;
    }
    f.write_all(rows.as_bytes()).map_err(|e| file_err(path, e))
}
