//! Dense symmetric linear algebra in f64 for FID: the cyclic Jacobi eigen-decomposition
//! and the square root of a symmetric positive semi-definite matrix.
//!
//! Matrices are row-major `Vec<f64>` of `n × n`. Jacobi is slow (O(n³) per sweep, about
//! ten sweeps) but exact to rounding and has no failure modes on symmetric input; at
//! n = 256 it takes well under a second.

/// Eigen-decomposition of a symmetric matrix.
#[derive(Clone, Debug, PartialEq)]
pub struct SymmetricEigen {
    /// Eigenvalues, in no particular order.
    pub values: Vec<f64>,
    /// Row-major `n × n`; column k is the unit eigenvector of `values[k]`.
    pub vectors: Vec<f64>,
}

/// Errors of the decompositions.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum LinalgError {
    /// Input of the wrong size.
    #[error("expected a {n}×{n} matrix ({} values), got {got} values", n * n)]
    Shape {
        /// Side.
        n: usize,
        /// Values given.
        got: usize,
    },
    /// NaN or infinite entries.
    #[error("the matrix has non-finite entries")]
    NonFinite,
    /// The input is not symmetric.
    #[error("the matrix is not symmetric (|a_ij − a_ji| up to {0:e})")]
    NotSymmetric(f64),
    /// Jacobi did not converge (cannot happen for finite symmetric input).
    #[error("Jacobi eigen-decomposition did not converge in {0} sweeps")]
    NoConvergence(usize),
}

const MAX_SWEEPS: usize = 60;

fn check_square(a: &[f64], n: usize) -> Result<(), LinalgError> {
    if a.len() != n * n {
        return Err(LinalgError::Shape { n, got: a.len() });
    }
    if a.iter().any(|v| !v.is_finite()) {
        return Err(LinalgError::NonFinite);
    }
    let scale = a.iter().fold(0.0f64, |m, v| m.max(v.abs())).max(1e-300);
    let mut worst = 0.0f64;
    for i in 0..n {
        for j in i + 1..n {
            worst = worst.max((a[i * n + j] - a[j * n + i]).abs());
        }
    }
    if worst > 1e-9 * scale {
        return Err(LinalgError::NotSymmetric(worst));
    }
    Ok(())
}

/// Eigenvalues and eigenvectors of the symmetric `n × n` matrix `a` (cyclic Jacobi).
pub fn symmetric_eigen(a: &[f64], n: usize) -> Result<SymmetricEigen, LinalgError> {
    check_square(a, n)?;
    // Symmetrise exactly so the rotations keep it symmetric.
    let mut m: Vec<f64> = (0..n * n)
        .map(|k| 0.5 * (a[k] + a[(k % n) * n + k / n]))
        .collect();
    let mut v = vec![0.0f64; n * n];
    for i in 0..n {
        v[i * n + i] = 1.0;
    }
    let total: f64 = m.iter().map(|x| x * x).sum();
    // Rounding leaves off-diagonal noise of about ε‖A‖ per entry; stop below 10 n ε‖A‖.
    let tol = (10.0 * n as f64 * f64::EPSILON).powi(2) * total.max(f64::MIN_POSITIVE);
    for _ in 0..MAX_SWEEPS {
        let off: f64 = (0..n)
            .flat_map(|i| (0..n).filter(move |&j| j != i).map(move |j| (i, j)))
            .map(|(i, j)| m[i * n + j].powi(2))
            .sum();
        if off <= tol {
            let values = (0..n).map(|i| m[i * n + i]).collect();
            return Ok(SymmetricEigen { values, vectors: v });
        }
        for p in 0..n {
            for q in p + 1..n {
                rotate(&mut m, &mut v, n, p, q);
            }
        }
    }
    Err(LinalgError::NoConvergence(MAX_SWEEPS))
}

/// One Jacobi rotation M ← PᵀMP, V ← VP that zeroes m[p][q].
fn rotate(m: &mut [f64], v: &mut [f64], n: usize, p: usize, q: usize) {
    let apq = m[p * n + q];
    if apq == 0.0 {
        return;
    }
    // Negligible next to both diagonal entries: set it to zero instead (Numerical Recipes).
    let (app, aqq) = (m[p * n + p].abs(), m[q * n + q].abs());
    if 100.0 * apq.abs() <= f64::EPSILON * app.min(aqq) {
        m[p * n + q] = 0.0;
        m[q * n + p] = 0.0;
        return;
    }
    let theta = (m[q * n + q] - m[p * n + p]) / (2.0 * apq);
    let t = theta.signum() / (theta.abs() + (theta * theta + 1.0).sqrt());
    let c = 1.0 / (t * t + 1.0).sqrt();
    let s = t * c;
    for k in 0..n {
        let (akp, akq) = (m[k * n + p], m[k * n + q]);
        m[k * n + p] = c * akp - s * akq;
        m[k * n + q] = s * akp + c * akq;
    }
    for k in 0..n {
        let (apk, aqk) = (m[p * n + k], m[q * n + k]);
        m[p * n + k] = c * apk - s * aqk;
        m[q * n + k] = s * apk + c * aqk;
    }
    for k in 0..n {
        let (vkp, vkq) = (v[k * n + p], v[k * n + q]);
        v[k * n + p] = c * vkp - s * vkq;
        v[k * n + q] = s * vkp + c * vkq;
    }
}

/// Square root S (symmetric, PSD, S·S = A) of a symmetric PSD matrix; eigenvalues below
/// zero from rounding are clamped to 0.
pub fn sqrt_psd(a: &[f64], n: usize) -> Result<Vec<f64>, LinalgError> {
    let e = symmetric_eigen(a, n)?;
    let roots: Vec<f64> = e.values.iter().map(|l| l.max(0.0).sqrt()).collect();
    let mut s = vec![0.0f64; n * n];
    for i in 0..n {
        for j in i..n {
            let x: f64 = (0..n)
                .map(|k| e.vectors[i * n + k] * roots[k] * e.vectors[j * n + k])
                .sum();
            s[i * n + j] = x;
            s[j * n + i] = x;
        }
    }
    Ok(s)
}

/// Row-major product of two `n × n` matrices.
pub fn matmul(a: &[f64], b: &[f64], n: usize) -> Vec<f64> {
    let mut c = vec![0.0f64; n * n];
    for i in 0..n {
        for k in 0..n {
            let aik = a[i * n + k];
            if aik == 0.0 {
                continue;
            }
            let row = &b[k * n..(k + 1) * n];
            for (cij, bkj) in c[i * n..(i + 1) * n].iter_mut().zip(row) {
                *cij += aik * bkj;
            }
        }
    }
    c
}

/// tr((A·B)^½) for symmetric PSD A and B, computed as Σ √λ(A^½ B A^½) (a symmetric PSD
/// matrix with the same eigenvalues as A·B).
pub fn trace_sqrt_product(a: &[f64], b: &[f64], n: usize) -> Result<f64, LinalgError> {
    check_square(b, n)?;
    let ra = sqrt_psd(a, n)?;
    let mut m = matmul(&matmul(&ra, b, n), &ra, n);
    // Rounding leaves M a hair off symmetric.
    for i in 0..n {
        for j in i + 1..n {
            let x = 0.5 * (m[i * n + j] + m[j * n + i]);
            m[i * n + j] = x;
            m[j * n + i] = x;
        }
    }
    let e = symmetric_eigen(&m, n)?;
    Ok(e.values.iter().map(|l| l.max(0.0).sqrt()).sum())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: &[f64], b: &[f64], tol: f64) {
        for (x, y) in a.iter().zip(b) {
            assert!((x - y).abs() < tol, "{a:?} != {b:?}");
        }
    }

    #[test]
    fn eigen_of_a_known_2x2() {
        let e = symmetric_eigen(&[2.0, 1.0, 1.0, 2.0], 2).unwrap();
        let mut values = e.values.clone();
        values.sort_by(f64::total_cmp);
        close(&values, &[1.0, 3.0], 1e-12);
        // Column of eigenvalue 3 is ±(1, 1)/√2.
        let k = if e.values[0] > e.values[1] { 0 } else { 1 };
        let (x, y) = (e.vectors[k], e.vectors[2 + k]);
        assert!((x.abs() - 0.5f64.sqrt()).abs() < 1e-12 && (x - y).abs() < 1e-12);
    }

    #[test]
    fn square_root_of_known_matrices() {
        // [[2,1],[1,2]]² = [[5,4],[4,5]].
        close(
            &sqrt_psd(&[5.0, 4.0, 4.0, 5.0], 2).unwrap(),
            &[2.0, 1.0, 1.0, 2.0],
            1e-12,
        );
        close(
            &sqrt_psd(&[4.0, 0.0, 0.0, 9.0], 2).unwrap(),
            &[2.0, 0.0, 0.0, 3.0],
            1e-12,
        );
        // A rank-deficient one: [[1,1],[1,1]] = 2·uuᵀ → √2·uuᵀ = [[1,1],[1,1]]/√2.
        let h = 0.5f64.sqrt();
        close(
            &sqrt_psd(&[1.0, 1.0, 1.0, 1.0], 2).unwrap(),
            &[h, h, h, h],
            1e-12,
        );
    }

    #[test]
    fn square_root_squares_back_on_a_large_random_matrix() {
        use rand::{Rng, SeedableRng};
        let n = 40;
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(7);
        let x: Vec<f64> = (0..n * n).map(|_| rng.random_range(-1.0..1.0)).collect();
        let xt: Vec<f64> = (0..n * n).map(|k| x[(k % n) * n + k / n]).collect();
        let a = matmul(&x, &xt, n); // X Xᵀ: symmetric PSD
        let s = sqrt_psd(&a, n).unwrap();
        close(&matmul(&s, &s, n), &a, 1e-9);
        // tr((A·A)^½) = tr(A).
        let tr: f64 = (0..n).map(|i| a[i * n + i]).sum();
        assert!((trace_sqrt_product(&a, &a, n).unwrap() - tr).abs() < 1e-8 * tr);
    }

    #[test]
    fn bad_input_is_an_error() {
        assert_eq!(
            symmetric_eigen(&[1.0, 2.0, 3.0], 2),
            Err(LinalgError::Shape { n: 2, got: 3 })
        );
        assert!(matches!(
            symmetric_eigen(&[1.0, 2.0, 0.0, 1.0], 2),
            Err(LinalgError::NotSymmetric(_))
        ));
        assert_eq!(
            sqrt_psd(&[f64::NAN, 0.0, 0.0, 1.0], 2),
            Err(LinalgError::NonFinite)
        );
    }
}
