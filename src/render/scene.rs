//! A validated scene: the people (motions) and overlays to draw, checked once (non-empty,
//! finite, one frame rate), with what every view needs derived from the whole clip — the
//! bounds the fixed cameras fit, the floor area, the heading of the side camera, and each
//! frame's pose and facing direction.

use super::error::RenderError;
use super::options::{Overlay, RenderOptions};
use super::overlay_geom::{Prim, overlay_prims};
use crate::motion::{Motion, Pose};
use crate::skeleton::FACE_JOINTS;
use glam::{Vec2, Vec3};

/// Space left around the clip's horizontal extent on the floor (metres).
const FLOOR_MARGIN: f32 = 0.5;
/// Net root travel (metres) above which the side camera follows the travel direction.
const TRAVEL_FOR_HEADING: f32 = 0.5;

/// People and overlays ready to draw.
pub(crate) struct Scene<'a> {
    people: &'a [Motion],
    /// Frames per second shared by all people.
    pub fps: f32,
    /// Frames in the scene (the longest person; shorter ones hold their last pose).
    pub len: usize,
    /// Floor rectangle as (x, z) corners.
    pub floor_lo: Vec2,
    /// See `floor_lo`.
    pub floor_hi: Vec2,
    /// Overlays as lines and dots.
    pub prims: Vec<Prim>,
    /// Side camera heading about +Y (radians); 0 looks at a +Z walk from its right-front.
    pub yaw: f32,
}

impl<'a> Scene<'a> {
    /// Checks the people and overlays and derives the fixed framing.
    pub fn new(people: &'a [Motion], opts: &RenderOptions) -> Result<Self, RenderError> {
        let fps = validate_people(people)?;
        let len = people.iter().map(Motion::len).max().unwrap_or(0);
        let (mut lo, mut hi) = (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY));
        for m in people {
            let (a, b) = m.bounds();
            lo = lo.min(a);
            hi = hi.max(b);
        }
        for (index, o) in opts.overlays.iter().enumerate() {
            for p in anchor_points(o, index)? {
                lo = lo.min(p);
                hi = hi.max(p);
            }
            // A horizontal plane spans the floor area; only its height must be in view.
            if let Overlay::HorizontalPlane { height } = o {
                lo.y = lo.y.min(*height);
                hi.y = hi.y.max(*height);
            }
        }
        // The floor is always in view, and a person is at least standing height tall.
        lo.y = lo.y.min(0.0);
        hi.y = hi.y.max(lo.y + 1.0);
        let floor_lo = Vec2::new(lo.x, lo.z) - FLOOR_MARGIN;
        let floor_hi = Vec2::new(hi.x, hi.z) + FLOOR_MARGIN;
        let prims = overlay_prims(&opts.overlays, floor_lo, floor_hi, lo.y, hi.y);
        let mut scene = Scene {
            people,
            fps,
            len,
            floor_lo,
            floor_hi,
            prims,
            yaw: 0.0,
        };
        scene.yaw = match opts.camera_yaw_deg {
            Some(d) if d.is_finite() => d.to_radians(),
            Some(d) => {
                return Err(RenderError::BadOption(format!(
                    "camera yaw {d} is not finite"
                )));
            }
            None => scene.auto_yaw(),
        };
        Ok(scene)
    }

    /// Number of people.
    pub fn people(&self) -> usize {
        self.people.len()
    }

    /// Pose of `person` at `frame`; a clip shorter than the scene holds its last pose.
    pub fn pose(&self, person: usize, frame: usize) -> &Pose {
        let frames = &self.people[person].frames;
        &frames[frame.min(frames.len() - 1)]
    }

    /// Root (pelvis) positions of `person` over the whole clip.
    pub fn root_trail(&self, person: usize) -> Vec<Vec3> {
        self.people[person].joint_track(0)
    }

    /// What the side camera must keep in view: the floor rectangle, every joint of every
    /// frame, and the overlays. Fitting these rather than the bounding box leaves no empty
    /// corners above the far end of a long walk.
    pub fn fit_points(&self) -> Vec<Vec3> {
        let (l, h) = (self.floor_lo, self.floor_hi);
        let mut pts = vec![
            Vec3::new(l.x, 0.0, l.y),
            Vec3::new(h.x, 0.0, l.y),
            Vec3::new(h.x, 0.0, h.y),
            Vec3::new(l.x, 0.0, h.y),
        ];
        for m in self.people {
            pts.extend(m.frames.iter().flatten());
        }
        pts.extend(self.prims.iter().flat_map(|p| p.points()));
        pts
    }

    /// Spacing of the floor grid in metres: 1 m, or a power of ten keeping it to at
    /// most 100 lines per axis on a huge floor (data in millimetres, say).
    pub fn grid_step(&self) -> f32 {
        let span = (self.floor_hi - self.floor_lo).max_element();
        let mut step = 1.0;
        while span / step > 100.0 {
            step *= 10.0;
        }
        step
    }

    /// Seconds at `frame`.
    pub fn time(&self, frame: usize) -> f32 {
        frame as f32 / self.fps
    }

    /// Heading that shows person 0 travelling rightwards, or facing the camera's side.
    fn auto_yaw(&self) -> f32 {
        let first = self.pose(0, 0)[0];
        let last = self.pose(0, self.len - 1)[0];
        let travel = Vec2::new(last.x - first.x, last.z - first.z);
        let dir = if travel.length() > TRAVEL_FOR_HEADING {
            travel
        } else {
            facing(self.pose(0, 0)).map_or(Vec2::Y, |f| Vec2::new(f.x, f.z))
        };
        dir.x.atan2(dir.y)
    }
}

/// Horizontal unit facing direction of a pose by HumanML3D's rule, up × across with
/// across = (right hip − left hip) + (right shoulder − left shoulder); `None` when the hips
/// and shoulders give no horizontal direction.
pub(crate) fn facing(pose: &Pose) -> Option<Vec3> {
    let [r_hip, l_hip, r_sh, l_sh] = FACE_JOINTS;
    let across = (pose[r_hip] - pose[l_hip]) + (pose[r_sh] - pose[l_sh]);
    let f = Vec3::Y.cross(across);
    let f = Vec3::new(f.x, 0.0, f.z);
    (f.length() > 1e-6).then(|| f.normalize())
}

/// Checks every motion; returns the shared frame rate.
fn validate_people(people: &[Motion]) -> Result<f32, RenderError> {
    let first = people.first().ok_or(RenderError::NoPeople)?;
    for (person, m) in people.iter().enumerate() {
        if m.is_empty() {
            return Err(RenderError::EmptyMotion { person });
        }
        if !(m.fps.is_finite() && m.fps > 0.0) {
            return Err(RenderError::BadFps { person, fps: m.fps });
        }
        if (m.fps - first.fps).abs() > 1e-4 {
            return Err(RenderError::FpsMismatch {
                person,
                fps: m.fps,
                first: first.fps,
            });
        }
        for (frame, pose) in m.frames.iter().enumerate() {
            if let Some(joint) = pose.iter().position(|p| !p.is_finite()) {
                return Err(RenderError::NonFinite {
                    person,
                    frame,
                    joint,
                });
            }
        }
    }
    Ok(first.fps)
}

/// Points of an overlay that must be in view; rejects non-finite or degenerate overlays.
fn anchor_points(o: &Overlay, index: usize) -> Result<Vec<Vec3>, RenderError> {
    let bad = |reason: &str| RenderError::BadOverlay {
        index,
        reason: reason.to_string(),
    };
    let points = match o {
        Overlay::Point { at, .. } => vec![*at],
        Overlay::Segment { from, to } => vec![*from, *to],
        Overlay::VerticalPlane { point, normal } => {
            if !normal.is_finite() || Vec2::new(normal.x, normal.z).length() < 1e-6 {
                return Err(bad(
                    "a vertical plane needs a finite normal with a horizontal part",
                ));
            }
            vec![*point]
        }
        Overlay::HorizontalPlane { height } if height.is_finite() => vec![],
        Overlay::HorizontalPlane { .. } => return Err(bad("plane height is not finite")),
        Overlay::Box { min, max } => {
            if min.is_finite() && max.is_finite() && min.cmpgt(*max).any() {
                return Err(bad("box min corner is above its max corner"));
            }
            vec![*min, *max]
        }
    };
    if points.iter().all(|p| p.is_finite()) {
        Ok(points)
    } else {
        Err(bad("coordinates are not finite"))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::test_motion::{test_walk, walk};

    #[test]
    fn framing_covers_the_clip_and_follows_travel() {
        let opts = RenderOptions::default();
        let m = [test_walk()];
        let s = Scene::new(&m, &opts).unwrap();
        assert_eq!((s.len, s.people(), s.grid_step()), (40, 1, 1.0));
        let (lo, hi) = m[0].bounds();
        assert!(s.floor_lo.x < lo.x && s.floor_hi.y > hi.z);
        // Walking along +Z gives heading 0; along +X a quarter turn.
        assert!(s.yaw.abs() < 1e-3);
        let along_x = [walk(40, 1.2, Vec3::ZERO, Vec3::X)];
        let sx = Scene::new(&along_x, &opts).unwrap();
        assert!((sx.yaw - std::f32::consts::FRAC_PI_2).abs() < 1e-3);
        // An explicit yaw wins; a shorter person holds their last pose.
        let two = [test_walk(), walk(10, 1.0, Vec3::X, Vec3::Z)];
        let st = Scene::new(
            &two,
            &RenderOptions {
                camera_yaw_deg: Some(90.0),
                ..opts.clone()
            },
        )
        .unwrap();
        assert!((st.yaw - std::f32::consts::FRAC_PI_2).abs() < 1e-6);
        assert_eq!(st.pose(1, 30), &two[1].frames[9]);
        // Millimetre-sized data gets a coarser grid instead of thousands of lines.
        let mm = [Motion::new(
            test_walk()
                .frames
                .iter()
                .map(|p| p.map(|v| v * 1000.0))
                .collect(),
        )];
        assert!(Scene::new(&mm, &opts).unwrap().grid_step() >= 100.0);
    }

    #[test]
    fn facing_follows_the_hips_and_shoulders() {
        let f = facing(&crate::skeleton::rest_pose()).unwrap();
        assert!((f - Vec3::Z).length() < 1e-5);
        let turned = walk(2, 0.0, Vec3::ZERO, Vec3::NEG_X);
        assert!((facing(&turned.frames[0]).unwrap() - Vec3::NEG_X).length() < 1e-4);
    }
}
