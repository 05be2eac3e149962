//! `.npy` arrays of joints or HumanML3D features.
//!
//! In: `.npy` bytes of a float array (`<f4`, `>f4`, `<f8`, `>f8`; C or Fortran order).
//! Out: an [`NpyArray`] (shape + C-order `f32` data) and its meaning, [`MotionFile`]:
//! `[N, 22, 3]` / `[P, N, 22, 3]` global joint positions (HumanML3D's `new_joints`) or
//! `[N, 263]` features (`new_joint_vecs`; turned into joints by `recover_from_ric`
//! elsewhere). Writing: [`write_joints_npy`] stores `[N, 22, 3]` (one person) or
//! `[P, N, 22, 3]` little-endian `f32`, through [`crate::fsutil::write_atomic`].

use crate::motion::Motion;
use crate::skeleton::NUM_JOINTS;
use npyz::{DType, Order, TypeChar, WriterBuilder};
use std::path::Path;

/// Width of a HumanML3D feature row.
pub const FEATURE_DIM: usize = 263;

/// Largest accepted array (elements); far above any motion clip.
const MAX_ELEMENTS: u64 = 500_000_000;

/// A float array read from `.npy`, converted to `f32` and C order.
#[derive(Clone, Debug, PartialEq)]
pub struct NpyArray {
    pub shape: Vec<usize>,
    pub data: Vec<f32>,
}

/// What an `.npy` file holds, told by its shape.
#[derive(Clone, Debug, PartialEq)]
pub enum MotionFile {
    /// Global joint positions, one motion per person (at mprog's 20 fps: `.npy` has no
    /// frame rate, and HumanML3D arrays are 20 fps).
    Joints(Vec<Motion>),
    /// `[N, 263]` HumanML3D feature rows (or `[B, N, 263]`), raw.
    Features(NpyArray),
}

/// An `.npy` problem; every message names the file.
#[derive(Debug, thiserror::Error)]
pub enum NpyError {
    #[error("{origin}: cannot read: {source}")]
    Io {
        origin: String,
        source: std::io::Error,
    },
    #[error("{origin}: not a valid .npy file: {message}")]
    Header { origin: String, message: String },
    #[error(
        "{origin}: unsupported dtype `{dtype}`: expected float32 or float64 (`<f4`, `>f4`, `<f8`, `>f8`)"
    )]
    DType { origin: String, dtype: String },
    #[error("{origin}: array has shape {shape:?}; expected {expected}")]
    Shape {
        origin: String,
        shape: Vec<u64>,
        expected: &'static str,
    },
    #[error(
        "{origin}: array of shape {shape:?} has {elements} elements, over the limit of {MAX_ELEMENTS}"
    )]
    TooLarge {
        origin: String,
        shape: Vec<u64>,
        elements: u64,
    },
    #[error(
        "{origin}: data is truncated: shape {shape:?} needs {needed} bytes after the header, the file has {found}"
    )]
    Truncated {
        origin: String,
        shape: Vec<u64>,
        needed: u64,
        found: u64,
    },
    #[error("{origin}: value at index {index:?} is not finite ({value})")]
    NonFinite {
        origin: String,
        index: Vec<usize>,
        value: f32,
    },
    #[error("{path}: cannot write: {source}")]
    Write {
        path: String,
        source: std::io::Error,
    },
    #[error("{path}: cannot write {count} people of different lengths {lengths:?} as one array")]
    RaggedPeople {
        path: String,
        count: usize,
        lengths: Vec<usize>,
    },
}

/// Reads any float `.npy` file.
pub fn read_npy(path: &Path) -> Result<NpyArray, NpyError> {
    let origin = path.display().to_string();
    let bytes = std::fs::read(path).map_err(|source| NpyError::Io {
        origin: origin.clone(),
        source,
    })?;
    read_npy_bytes(&origin, &bytes)
}

/// Reads `.npy` bytes; `origin` names them in errors.
pub fn read_npy_bytes(origin: &str, bytes: &[u8]) -> Result<NpyArray, NpyError> {
    let header_err = |message: String| NpyError::Header {
        origin: origin.into(),
        message,
    };
    if let Some(text) = header_text(bytes) {
        let brackets = text.iter().filter(|b| b"([{".contains(b)).count();
        if brackets > 2 {
            // A float array's header is `{'descr': '<f4', 'fortran_order': False, 'shape':
            // (…), }`. npyz's header parser backtracks exponentially on nested brackets
            // (a fuzzing finding: 25 `[` took 15 s), so anything else is refused here.
            return Err(header_err(format!(
                "the header has {brackets} brackets; expected `{{'descr': …, 'fortran_order': …, 'shape': (…)}}` \
                 (structured dtypes are not supported)"
            )));
        }
    }
    let mut rest = bytes;
    let header = npyz::NpyHeader::from_reader(&mut rest).map_err(|e| header_err(e.to_string()))?;
    let npy = npyz::NpyFile::with_header(header, rest);
    let shape = npy.shape().to_vec();
    let elements = shape
        .iter()
        .try_fold(1u64, |acc, &d| acc.checked_mul(d))
        .unwrap_or(u64::MAX);
    if elements > MAX_ELEMENTS {
        return Err(NpyError::TooLarge {
            origin: origin.into(),
            shape,
            elements,
        });
    }
    let item_size = match npy.dtype() {
        DType::Plain(ts)
            if ts.type_char() == TypeChar::Float && matches!(ts.size_field(), 4 | 8) =>
        {
            ts.size_field()
        }
        other => {
            return Err(NpyError::DType {
                origin: origin.into(),
                dtype: other.descr().trim_matches('\'').to_string(),
            });
        }
    };
    let needed = elements * item_size;
    if (rest.len() as u64) < needed {
        return Err(NpyError::Truncated {
            origin: origin.into(),
            shape,
            needed,
            found: rest.len() as u64,
        });
    }
    let order = npy.order();
    let io_err = |e: std::io::Error| header_err(e.to_string());
    let raw: Vec<f32> = if item_size == 4 {
        npy.into_vec::<f32>().map_err(io_err)?
    } else {
        npy.into_vec::<f64>()
            .map_err(io_err)?
            .into_iter()
            .map(|v| v as f32)
            .collect()
    };
    let shape: Vec<usize> = shape.iter().map(|&d| d as usize).collect();
    let data = match order {
        Order::C => raw,
        Order::Fortran => fortran_to_c(&raw, &shape),
    };
    if let Some(i) = data.iter().position(|v| !v.is_finite()) {
        return Err(NpyError::NonFinite {
            origin: origin.into(),
            index: unravel(i, &shape),
            value: data[i],
        });
    }
    Ok(NpyArray { shape, data })
}

/// The header dictionary's bytes (possibly cut short by the file's end), if `bytes`
/// starts like an `.npy` file of a known version.
fn header_text(bytes: &[u8]) -> Option<&[u8]> {
    if bytes.len() < 10 || &bytes[..6] != b"\x93NUMPY" {
        return None;
    }
    let (len, start): (usize, usize) = match bytes[6] {
        1 => (usize::from(u16::from_le_bytes([bytes[8], bytes[9]])), 10),
        2 | 3 => {
            let len = bytes.get(8..12)?;
            (
                u32::from_le_bytes([len[0], len[1], len[2], len[3]]) as usize,
                12,
            )
        }
        _ => return None,
    };
    let end = start.saturating_add(len).min(bytes.len());
    bytes.get(start..end)
}

/// Reorders column-major data to row-major.
fn fortran_to_c(raw: &[f32], shape: &[usize]) -> Vec<f32> {
    (0..raw.len())
        .map(|c_index| {
            let index = unravel(c_index, shape);
            let mut f_index = 0;
            for (axis, &i) in index.iter().enumerate().rev() {
                f_index = f_index * shape[axis] + i;
            }
            raw[f_index]
        })
        .collect()
}

/// Multi-index of flat C-order position `i`.
fn unravel(mut i: usize, shape: &[usize]) -> Vec<usize> {
    let mut index = vec![0; shape.len()];
    for (axis, &dim) in shape.iter().enumerate().rev() {
        index[axis] = i % dim.max(1);
        i /= dim.max(1);
    }
    index
}

/// Classifies an array by its last dimensions.
pub fn classify(origin: &str, array: NpyArray) -> Result<MotionFile, NpyError> {
    let shape = array.shape.clone();
    let bad = || NpyError::Shape {
        origin: origin.into(),
        shape: shape.iter().map(|&d| d as u64).collect(),
        expected: "[frames, 22, 3] or [people, frames, 22, 3] joints, or [frames, 263] features",
    };
    match shape.as_slice() {
        [.., 0, _] | [0, ..] => Err(bad()),
        [_, FEATURE_DIM] | [_, _, FEATURE_DIM] => Ok(MotionFile::Features(array)),
        [frames, NUM_JOINTS, 3] => Ok(MotionFile::Joints(vec![motion_from(&array.data, *frames)])),
        [people, frames, NUM_JOINTS, 3] => {
            let per = frames * NUM_JOINTS * 3;
            Ok(MotionFile::Joints(
                (0..*people)
                    .map(|p| motion_from(&array.data[p * per..(p + 1) * per], *frames))
                    .collect(),
            ))
        }
        _ => Err(bad()),
    }
}

fn motion_from(data: &[f32], frames: usize) -> Motion {
    debug_assert_eq!(data.len(), frames * NUM_JOINTS * 3);
    Motion::from_flat(data)
}

/// Reads and classifies an `.npy` motion file.
pub fn read_motion_npy(path: &Path) -> Result<MotionFile, NpyError> {
    classify(&path.display().to_string(), read_npy(path)?)
}

/// Writes motions as `float32`: `[N, 22, 3]` for one, `[P, N, 22, 3]` for several
/// (all the same length), atomically.
pub fn write_joints_npy(path: &Path, motions: &[Motion]) -> Result<(), NpyError> {
    let name = path.display().to_string();
    let bytes = joints_npy_bytes(&name, motions)?;
    crate::fsutil::write_bytes_atomic(path, &bytes)
        .map_err(|source| NpyError::Write { path: name, source })
}

/// The bytes of the `.npy` file [`write_joints_npy`] writes; `origin` names it in errors.
pub fn joints_npy_bytes(origin: &str, motions: &[Motion]) -> Result<Vec<u8>, NpyError> {
    let lengths: Vec<usize> = motions.iter().map(Motion::len).collect();
    if motions.is_empty() || lengths.iter().any(|&l| l != lengths[0]) {
        return Err(NpyError::RaggedPeople {
            path: origin.to_string(),
            count: motions.len(),
            lengths,
        });
    }
    let frames = lengths[0] as u64;
    let shape: Vec<u64> = match motions.len() {
        1 => vec![frames, NUM_JOINTS as u64, 3],
        p => vec![p as u64, frames, NUM_JOINTS as u64, 3],
    };
    let mut bytes = Vec::new();
    let encode = |w: &mut Vec<u8>| -> std::io::Result<()> {
        let mut writer = npyz::WriteOptions::new()
            .default_dtype()
            .shape(&shape)
            .writer(w)
            .begin_nd()?;
        for m in motions {
            writer.extend(m.to_flat())?;
        }
        writer.finish()
    };
    encode(&mut bytes).map_err(|source| NpyError::Write {
        path: origin.to_string(),
        source,
    })?;
    Ok(bytes)
}
