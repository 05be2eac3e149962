//! Geometry a program names (targets, walls, height limits, regions), in world
//! coordinates: produced by the language's checker, drawn by the renderer and the viewer.

use glam::Vec3;

/// A piece of geometry to draw into the scene (metres, world coordinates, Y up).
///
/// Planes are unbounded, so they are drawn as outlines clipped to the floor area of the
/// scene (the clip's horizontal extent plus a margin) and its height range.
#[derive(Clone, Debug, PartialEq)]
pub enum Overlay {
    /// A marked point, e.g. a target, with an optional text label.
    Point {
        /// Position.
        at: Vec3,
        /// Label drawn beside the point.
        label: Option<String>,
    },
    /// A straight line segment.
    Segment {
        /// Start.
        from: Vec3,
        /// End.
        to: Vec3,
    },
    /// A vertical plane (a wall) through `point` with horizontal normal `normal`
    /// (its Y component is ignored).
    VerticalPlane {
        /// Any point on the plane; it is kept inside the camera's view.
        point: Vec3,
        /// Plane normal; must have a non-zero horizontal part.
        normal: Vec3,
    },
    /// A horizontal plane `y = height` (a floor, a ceiling, a height limit).
    HorizontalPlane {
        /// Height in metres.
        height: f32,
    },
    /// An axis-aligned box between two corners.
    Box {
        /// Lowest corner.
        min: Vec3,
        /// Highest corner.
        max: Vec3,
    },
}
