//! A simple body for a skeleton, so any glTF viewer shows a figure: one eight-sided prism
//! (with caps) per bone, from the parent's rest position to the joint's, each rigidly bound
//! to the bone's parent joint; a joint with no children at all (the head, the hands and
//! toes of the 22-joint rig) gets a short prism continuing its bone. Thickness follows the
//! body part of the joint a bone starts at (torso, thigh, forearm, …), scaled with the
//! character's size; bones of joints mprog does not know (fingers) are thin.

use crate::formats::posed::Posed;
use glam::DVec3;

/// Triangles bound rigidly to joints.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct BodyMesh {
    pub positions: Vec<[f32; 3]>,
    pub normals: Vec<[f32; 3]>,
    /// Skin joint of each vertex (index into the skin's joint list).
    pub joints: Vec<u16>,
    pub indices: Vec<u32>,
}

/// Sides of each prism.
const SIDES: usize = 8;

/// Rigs with more joints than this draw only the bones of the joints mprog maps.
const MAX_DRAWN: usize = 2000;

/// Radius (m, for a HumanML3D-sized body) of a bone starting at HumanML3D joint `j`.
fn radius(j: usize) -> f64 {
    match j {
        0 => 0.08,
        3 | 6 => 0.11,
        9 => 0.06,
        12 => 0.05,
        15 => 0.085,
        13 | 14 => 0.05,
        16 | 17 => 0.045,
        18 | 19 => 0.037,
        20 | 21 => 0.022,
        1 | 2 => 0.07,
        4 | 5 => 0.05,
        7 | 8 => 0.04,
        _ => 0.03,
    }
}

/// Length (m) of the prism continuing a childless joint's bone.
fn cap_length(j: Option<usize>) -> f64 {
    match j {
        Some(15) => 0.2,
        Some(20 | 21) => 0.09,
        Some(10 | 11) => 0.05,
        _ => 0.03,
    }
}

/// The body of `posed` in its rest pose `rest` (world positions); `skin_joint` gives each
/// joint's index in the skin (None for End Sites).
pub fn body_mesh(posed: &Posed, rest: &[DVec3], skin_joint: &[Option<u16>]) -> BodyMesh {
    let mut mesh = BodyMesh::default();
    let joints = &posed.joints;
    let few = joints.len() <= MAX_DRAWN;
    let mut has_child = vec![false; joints.len()];
    for j in joints {
        if let Some(p) = j.parent {
            has_child[p] = true;
        }
    }
    for (i, j) in joints.iter().enumerate() {
        let Some(p) = j.parent else { continue };
        let Some(bind) = skin_joint[p] else { continue };
        let start = joints[p].body;
        if start.is_none() && !few {
            continue;
        }
        let len = rest[p].distance(rest[i]);
        if len < 1e-3 * posed.size {
            continue;
        }
        let r = match start {
            Some(b) => radius(b) * posed.size,
            None => (0.25 * len).clamp(0.004 * posed.size, 0.01 * posed.size),
        };
        prism(&mut mesh, rest[p], rest[i], r, bind);
        // A joint with nothing below it continues its bone a little.
        if !has_child[i]
            && !j.end_site
            && let Some(own) = skin_joint[i]
        {
            let dir = (rest[i] - rest[p]) / len;
            let r = j.body.map_or(r, |b| radius(b) * posed.size);
            let cap = cap_length(j.body) * posed.size;
            prism(&mut mesh, rest[i], rest[i] + dir * cap, r, own);
        }
    }
    mesh
}

/// Appends a capped prism of radius `r` from `a` to `b`, bound to skin joint `joint`.
fn prism(mesh: &mut BodyMesh, a: DVec3, b: DVec3, r: f64, joint: u16) {
    let Some(dir) = (b - a).try_normalize() else {
        return;
    };
    let e1 = dir.any_orthonormal_vector();
    let e2 = dir.cross(e1);
    let radial: Vec<DVec3> = (0..SIDES)
        .map(|k| {
            let t = std::f64::consts::TAU * k as f64 / SIDES as f64;
            e1 * t.cos() + e2 * t.sin()
        })
        .collect();
    let push = |m: &mut BodyMesh, p: DVec3, n: DVec3| -> u32 {
        m.positions.push(p.as_vec3().to_array());
        m.normals.push(n.as_vec3().to_array());
        m.joints.push(joint);
        (m.positions.len() - 1) as u32
    };
    // Sides: counter-clockwise seen from outside.
    let ring_a: Vec<u32> = radial.iter().map(|&d| push(mesh, a + d * r, d)).collect();
    let ring_b: Vec<u32> = radial.iter().map(|&d| push(mesh, b + d * r, d)).collect();
    for k in 0..SIDES {
        let n = (k + 1) % SIDES;
        mesh.indices.extend([
            ring_a[k], ring_a[n], ring_b[k], ring_b[k], ring_a[n], ring_b[n],
        ]);
    }
    // Caps.
    for (centre, normal) in [(a, -dir), (b, dir)] {
        let c = push(mesh, centre, normal);
        let ring: Vec<u32> = radial
            .iter()
            .map(|&d| push(mesh, centre + d * r, normal))
            .collect();
        for k in 0..SIDES {
            let n = (k + 1) % SIDES;
            if normal.dot(dir) > 0.0 {
                mesh.indices.extend([c, ring[k], ring[n]]);
            } else {
                mesh.indices.extend([c, ring[n], ring[k]]);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn prism_faces_point_outwards() {
        let mut m = BodyMesh::default();
        prism(&mut m, DVec3::ZERO, DVec3::new(0.0, 0.0, 1.0), 0.1, 3);
        assert_eq!(m.positions.len(), 2 * SIDES + 2 * (SIDES + 1));
        assert!(m.joints.iter().all(|&j| j == 3));
        let centre = DVec3::new(0.0, 0.0, 0.5);
        for tri in m.indices.chunks_exact(3) {
            let p: [DVec3; 3] =
                std::array::from_fn(|k| DVec3::from(m.positions[tri[k] as usize].map(f64::from)));
            let n = (p[1] - p[0]).cross(p[2] - p[0]);
            let mid = (p[0] + p[1] + p[2]) / 3.0;
            assert!(n.dot(mid - centre) > 0.0, "{tri:?} faces inwards");
        }
    }
}
