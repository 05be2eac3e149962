//! The two small geometric solvers of retargeting.
//!
//! * [`best_rotation`]: the rotation that best turns a set of rest directions onto current
//!   directions (least squares on unit vectors, Horn's quaternion method: the eigenvector of
//!   the largest eigenvalue of a symmetric 4×4 matrix, found by Jacobi rotations). Used where
//!   the body branches: the pelvis (both hips and the spine), the chest (neck and collars).
//! * [`knee_position`]: two-bone IK: where the knee goes so that a thigh and a shin of given
//!   lengths reach from the hip to the ankle target, bending towards a pole direction.

use glam::{DQuat, DVec3};

/// The rotation `q` minimising Σ‖q·â − b̂‖² over the pairs (a, b) (directions; zero vectors
/// are skipped). `None` when the directions do not fix a rotation (fewer than two that are
/// not parallel).
pub fn best_rotation(pairs: &[(DVec3, DVec3)]) -> Option<DQuat> {
    let mut s = [[0.0f64; 3]; 3];
    let mut used = Vec::new();
    for (a, b) in pairs {
        let (Some(a), Some(b)) = (a.try_normalize(), b.try_normalize()) else {
            continue;
        };
        used.push(a);
        for (i, ai) in a.to_array().into_iter().enumerate() {
            for (j, bj) in b.to_array().into_iter().enumerate() {
                s[i][j] += ai * bj;
            }
        }
    }
    let spread = used
        .iter()
        .flat_map(|a| used.iter().map(move |b| a.cross(*b).length()))
        .fold(0.0, f64::max);
    if spread < 1e-3 {
        return None;
    }
    let [[xx, xy, xz], [yx, yy, yz], [zx, zy, zz]] = s;
    let n = [
        [xx + yy + zz, yz - zy, zx - xz, xy - yx],
        [yz - zy, xx - yy - zz, xy + yx, zx + xz],
        [zx - xz, xy + yx, -xx + yy - zz, yz + zy],
        [xy - yx, zx + xz, yz + zy, -xx - yy + zz],
    ];
    let (values, vectors) = jacobi4(n);
    let k = (0..4).max_by(|&a, &b| values[a].total_cmp(&values[b]))?;
    let q = DQuat::from_xyzw(vectors[1][k], vectors[2][k], vectors[3][k], vectors[0][k]);
    q.try_normalize().map(|q| if q.w < 0.0 { -q } else { q })
}

trait TryNormalize: Sized {
    fn try_normalize(self) -> Option<Self>;
}

impl TryNormalize for DQuat {
    fn try_normalize(self) -> Option<Self> {
        let len = self.length();
        (len.is_finite() && len > 1e-12).then(|| self / len)
    }
}

/// Eigenvalues and eigenvectors (columns) of a symmetric 4×4 matrix, by cyclic Jacobi.
fn jacobi4(mut a: [[f64; 4]; 4]) -> ([f64; 4], [[f64; 4]; 4]) {
    let mut v = [[0.0; 4]; 4];
    for (i, row) in v.iter_mut().enumerate() {
        row[i] = 1.0;
    }
    for _sweep in 0..50 {
        let off: f64 = (0..4)
            .flat_map(|p| (0..4).filter(move |&q| q != p).map(move |q| (p, q)))
            .map(|(p, q)| a[p][q] * a[p][q])
            .sum();
        if off < 1e-30 {
            break;
        }
        for p in 0..3 {
            for q in p + 1..4 {
                if a[p][q].abs() < 1e-300 {
                    continue;
                }
                let theta = (a[q][q] - a[p][p]) / (2.0 * a[p][q]);
                let t = theta.signum() / (theta.abs() + (theta * theta + 1.0).sqrt());
                let t = if theta == 0.0 { 1.0 } else { t };
                let c = 1.0 / (t * t + 1.0).sqrt();
                let s = t * c;
                for row in a.iter_mut() {
                    let (akp, akq) = (row[p], row[q]);
                    row[p] = c * akp - s * akq;
                    row[q] = s * akp + c * akq;
                }
                let (rp, rq) = (a[p], a[q]);
                a[p] = std::array::from_fn(|k| c * rp[k] - s * rq[k]);
                a[q] = std::array::from_fn(|k| s * rp[k] + c * rq[k]);
                for row in v.iter_mut() {
                    let (vp, vq) = (row[p], row[q]);
                    row[p] = c * vp - s * vq;
                    row[q] = s * vp + c * vq;
                }
            }
        }
    }
    ([a[0][0], a[1][1], a[2][2], a[3][3]], v)
}

/// Where the knee goes for a thigh of length `thigh` from `hip` and a shin of length `shin`
/// ending at `target` (or as close as the leg reaches), bent towards `pole` (a direction;
/// only its part across the hip–target line counts).
pub fn knee_position(hip: DVec3, target: DVec3, pole: DVec3, thigh: f64, shin: f64) -> DVec3 {
    let v = target - hip;
    let u = v.try_normalize().unwrap_or(DVec3::NEG_Y);
    let lo = (thigh - shin).abs() + 1e-9;
    let hi = (thigh + shin - 1e-9).max(lo);
    let d = v.length().clamp(lo, hi);
    let cos = ((thigh * thigh + d * d - shin * shin) / (2.0 * thigh * d)).clamp(-1.0, 1.0);
    let sin = (1.0 - cos * cos).max(0.0).sqrt();
    let across = (pole - u * pole.dot(u))
        .try_normalize()
        .unwrap_or_else(|| u.any_orthonormal_vector());
    hip + u * (thigh * cos) + across * (thigh * sin)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn best_rotation_recovers_a_rotation() {
        let q = DQuat::from_euler(glam::EulerRot::YXZ, 2.5, -0.4, 0.9);
        let rest = [DVec3::X, DVec3::NEG_X + DVec3::NEG_Y * 0.2, DVec3::Y * 1.3];
        let pairs: Vec<_> = rest.iter().map(|&a| (a, q * a * 2.0)).collect();
        let got = best_rotation(&pairs).unwrap();
        assert!(got.dot(q).abs() > 1.0 - 1e-9, "{got} vs {q}");
        // A half turn (the hardest case for methods that divide by 1 + cos).
        let half = DQuat::from_rotation_y(std::f64::consts::PI);
        let pairs: Vec<_> = rest.iter().map(|&a| (a, half * a)).collect();
        assert!(best_rotation(&pairs).unwrap().dot(half).abs() > 1.0 - 1e-9);
        // Parallel directions do not fix a rotation.
        assert!(best_rotation(&[(DVec3::X, DVec3::Y), (DVec3::X * 2.0, DVec3::Y)]).is_none());
        assert!(best_rotation(&[]).is_none());
    }

    #[test]
    fn knee_reaches_the_target_and_bends_to_the_pole() {
        let hip = DVec3::new(0.1, 1.0, 0.0);
        let target = DVec3::new(0.1, 0.3, 0.2);
        let knee = knee_position(hip, target, DVec3::Z, 0.4, 0.42);
        assert!((knee.distance(hip) - 0.4).abs() < 1e-9);
        assert!((knee.distance(target) - 0.42).abs() < 1e-9);
        assert!(knee.z > 0.1, "bends forward: {knee}");
        // Out of reach: a straight leg towards the target.
        let far = knee_position(hip, DVec3::new(0.1, -1.0, 0.0), DVec3::Z, 0.4, 0.42);
        assert!((far - DVec3::new(0.1, 0.6, 0.0)).length() < 1e-4, "{far}");
    }
}
