//! A motion: global joint positions of the 22-joint skeleton over time.
//!
//! Layout written down once: frame-major, `[frames, 22, 3]`, metres, Y up, 20 fps.
//! Tensor code uses `[batch, people, frames, 22, 3]`; [`Motion::to_flat`] gives the
//! innermost three axes.

use crate::skeleton::{FPS, NUM_JOINTS};
use glam::Vec3;

/// Free-form metadata that travels with a motion (seed, program, solver settings, scene
/// geometry); files that have room for it store it (`.json`, `.npy` sidecars).
pub type Meta = serde_json::Map<String, serde_json::Value>;

/// One pose: the 22 global joint positions of a frame.
pub type Pose = [Vec3; NUM_JOINTS];

/// Global joint positions over time.
#[derive(Clone, Debug, PartialEq)]
pub struct Motion {
    /// One pose per frame.
    pub frames: Vec<Pose>,
    /// Frames per second (mprog works at [`FPS`]; imports resample to it).
    pub fps: f32,
}

impl Motion {
    /// A motion at mprog's frame rate.
    pub fn new(frames: Vec<Pose>) -> Self {
        Motion { frames, fps: FPS }
    }

    /// Number of frames.
    pub fn len(&self) -> usize {
        self.frames.len()
    }

    /// True when the motion has no frames.
    pub fn is_empty(&self) -> bool {
        self.frames.is_empty()
    }

    /// Duration in seconds.
    pub fn seconds(&self) -> f32 {
        self.frames.len() as f32 / self.fps
    }

    /// Flat `[frames, 22, 3]` array.
    pub fn to_flat(&self) -> Vec<f32> {
        self.frames
            .iter()
            .flat_map(|p| p.iter().flat_map(|v| v.to_array()))
            .collect()
    }

    /// Builds a motion from a flat `[frames, 22, 3]` array.
    ///
    /// # Panics
    /// If the length is not a multiple of 66 (callers check shapes first).
    pub fn from_flat(data: &[f32]) -> Self {
        assert_eq!(data.len() % (NUM_JOINTS * 3), 0, "flat motion length");
        let frames = data
            .chunks_exact(NUM_JOINTS * 3)
            .map(|f| std::array::from_fn(|j| Vec3::from_slice(&f[3 * j..3 * j + 3])))
            .collect();
        Motion::new(frames)
    }

    /// Trajectory of one joint.
    pub fn joint_track(&self, joint: usize) -> Vec<Vec3> {
        self.frames.iter().map(|p| p[joint]).collect()
    }

    /// Axis-aligned bounds over all joints and frames.
    pub fn bounds(&self) -> (Vec3, Vec3) {
        let mut lo = Vec3::splat(f32::INFINITY);
        let mut hi = Vec3::splat(f32::NEG_INFINITY);
        for p in self.frames.iter().flatten() {
            lo = lo.min(*p);
            hi = hi.max(*p);
        }
        (lo, hi)
    }

    /// True when every coordinate is finite.
    pub fn is_finite(&self) -> bool {
        self.frames.iter().flatten().all(|p| p.is_finite())
    }

    /// Resamples to `fps` by linear interpolation between neighbouring frames.
    pub fn resample(&self, fps: f32) -> Motion {
        if self.frames.len() < 2 || (fps - self.fps).abs() < 1e-6 {
            return Motion {
                frames: self.frames.clone(),
                fps,
            };
        }
        let duration = (self.frames.len() - 1) as f32 / self.fps;
        let count = (duration * fps).floor() as usize + 1;
        let frames = (0..count)
            .map(|i| {
                let src = i as f32 / fps * self.fps;
                let i0 = (src.floor() as usize).min(self.frames.len() - 1);
                let i1 = (i0 + 1).min(self.frames.len() - 1);
                let t = src - i0 as f32;
                std::array::from_fn(|j| self.frames[i0][j].lerp(self.frames[i1][j], t))
            })
            .collect();
        Motion { frames, fps }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::skeleton::rest_pose;

    #[test]
    fn flat_round_trip() {
        let m = Motion::new(vec![rest_pose(); 3]);
        assert_eq!(Motion::from_flat(&m.to_flat()), m);
    }

    #[test]
    fn resample_30_to_20_keeps_duration_and_interpolates() {
        let frames: Vec<Pose> = (0..31)
            .map(|i| [Vec3::new(i as f32, 0.0, 0.0); NUM_JOINTS])
            .collect();
        let m = Motion { frames, fps: 30.0 }.resample(20.0);
        assert_eq!(m.len(), 21);
        assert!((m.frames[1][0].x - 1.5).abs() < 1e-5);
        assert!((m.frames[20][0].x - 30.0).abs() < 1e-5);
    }
}
