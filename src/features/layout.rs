//! The 263-dim HumanML3D frame layout (block ranges) and [`Features`], a `[frames, 263]`
//! array of rows in that layout.
//!
//! | range | size | content |
//! | --- | --- | --- |
//! | [`ROOT_YAW_VEL`] | 1 | root yaw velocity, the **half**-angle (rad) of the per-frame y rotation |
//! | [`ROOT_VEL`] | 2 | root XZ displacement to the next frame, in the facing frame of the next frame |
//! | [`ROOT_Y`] | 1 | root height (floor = 0) |
//! | [`RIC`] | 63 | joints 1..21 relative to the root in XZ (absolute y), in the frame's facing frame |
//! | [`ROT`] | 126 | joints 1..21 local rotations, 6-D (first then second matrix column) |
//! | [`LOCAL_VEL`] | 66 | all 22 joints' displacement to the next frame, in the frame's facing frame |
//! | [`CONTACT`] | 4 | foot contacts: left ankle, left foot, right ankle, right foot |

use super::FeatureError;
use std::ops::Range;

/// Width of one feature frame.
pub const FEATURE_DIM: usize = 263;
/// Root yaw velocity (half-angle, radians).
pub const ROOT_YAW_VEL: Range<usize> = 0..1;
/// Root linear velocity (x, z).
pub const ROOT_VEL: Range<usize> = 1..3;
/// Root height.
pub const ROOT_Y: Range<usize> = 3..4;
/// Root-relative joint positions of joints 1..21.
pub const RIC: Range<usize> = 4..67;
/// 6-D local rotations of joints 1..21.
pub const ROT: Range<usize> = 67..193;
/// Local velocities of the 22 joints.
pub const LOCAL_VEL: Range<usize> = 193..259;
/// Foot contacts (7, 10, 8, 11).
pub const CONTACT: Range<usize> = 259..263;
/// The blocks in order, as used by HumanML3D's Std averaging.
pub const BLOCKS: [Range<usize>; 7] =
    [ROOT_YAW_VEL, ROOT_VEL, ROOT_Y, RIC, ROT, LOCAL_VEL, CONTACT];

/// A clip in the 263-dim representation: row-major `[frames, 263]`.
#[derive(Clone, Debug, PartialEq)]
pub struct Features {
    data: Vec<f32>,
}

impl Features {
    /// Wraps a flat `[frames, 263]` array; its length must be a multiple of 263.
    pub fn from_vec(data: Vec<f32>) -> Result<Self, FeatureError> {
        if !data.len().is_multiple_of(FEATURE_DIM) {
            return Err(FeatureError::BadFeatureLength {
                len: data.len(),
                dim: FEATURE_DIM,
            });
        }
        Ok(Features { data })
    }

    /// Number of frames.
    pub fn frames(&self) -> usize {
        self.data.len() / FEATURE_DIM
    }

    /// The flat `[frames, 263]` data.
    pub fn as_slice(&self) -> &[f32] {
        &self.data
    }

    /// Gives the flat data back.
    pub fn into_vec(self) -> Vec<f32> {
        self.data
    }

    /// One frame.
    ///
    /// # Panics
    /// If `t >= frames()`, like slice indexing.
    pub fn row(&self, t: usize) -> &[f32] {
        &self.data[t * FEATURE_DIM..(t + 1) * FEATURE_DIM]
    }

    /// The frames in order.
    pub fn rows(&self) -> impl Iterator<Item = &[f32]> {
        self.data.chunks_exact(FEATURE_DIM)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn blocks_tile_the_frame() {
        let mut next = 0;
        for b in BLOCKS {
            assert_eq!(b.start, next);
            next = b.end;
        }
        assert_eq!(next, FEATURE_DIM);
        assert_eq!(RIC.len(), 21 * 3);
        assert_eq!(ROT.len(), 21 * 6);
        assert_eq!(LOCAL_VEL.len(), 22 * 3);
    }

    #[test]
    fn rejects_ragged_data() {
        assert!(matches!(
            Features::from_vec(vec![0.0; 264]),
            Err(FeatureError::BadFeatureLength { len: 264, dim: 263 })
        ));
        let f = Features::from_vec((0..526).map(|i| i as f32).collect()).unwrap();
        assert_eq!(f.frames(), 2);
        assert_eq!(f.row(1)[0], 263.0);
    }
}
