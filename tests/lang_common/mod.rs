//! Shared helpers for the language tests: synthetic motions, evaluation to plain numbers,
//! and a finite-difference gradient check.
#![allow(dead_code)]

use burn::tensor::{Device, Tensor, TensorData};
use mprog::lang::{Program, compile};
use mprog::skeleton::{NUM_JOINTS, rest_pose};

/// Joint positions `[person][frame][joint]` in f64.
pub type Motion = Vec<Vec<[[f64; 3]; NUM_JOINTS]>>;

/// A deterministic walking-ish motion: the rest pose moving forward with wobbles.
/// Person 1 (if any) faces person 0 from 1.5 m away; person 2 stands 1 m to the side.
pub fn motion(people: usize, frames: usize) -> Motion {
    let rest = rest_pose();
    (0..people)
        .map(|p| {
            (0..frames)
                .map(|t| {
                    let tf = t as f64;
                    std::array::from_fn(|j| {
                        let jf = j as f64 + 3.0 * p as f64;
                        let r = rest[j];
                        let x = f64::from(r.x) + 0.05 * (0.7 * tf + jf).sin();
                        let y = f64::from(r.y) + 0.03 * (0.5 * tf + 2.0 * jf).cos();
                        let z = f64::from(r.z) + 0.06 * tf + 0.02 * (jf + tf).sin();
                        match p {
                            0 => [x, y, z],
                            1 => [-x, y, 1.5 - z],
                            _ => [x + 1.0, y, z],
                        }
                    })
                })
                .collect()
        })
        .collect()
}

/// Flattens a motion into `[1, people, frames, 22, 3]` f32 data.
pub fn flat(m: &Motion) -> (Vec<f32>, [usize; 5]) {
    let people = m.len();
    let frames = m[0].len();
    let data = m
        .iter()
        .flat_map(|p| {
            p.iter()
                .flat_map(|f| f.iter().flat_map(|v| v.map(|x| x as f32)))
        })
        .collect();
    (data, [1, people, frames, NUM_JOINTS, 3])
}

/// Compiles or panics with the rendered diagnostics.
pub fn program(src: &str) -> Program {
    match compile(src, "test.mprog", &[]) {
        Ok(p) => p,
        Err(d) => panic!("program does not compile:\n{}", d.render_plain()),
    }
}

/// (total, per-statement) on the flex device without autodiff.
pub fn eval(p: &Program, data: &[f32], shape: [usize; 5]) -> (f64, Vec<f64>) {
    let dev = Device::flex();
    let x = Tensor::<5>::from_data(TensorData::new(data.to_vec(), shape), &dev);
    let e = p.evaluate(x);
    let total = e.total.into_data().try_into_vec::<f32>().unwrap()[0] as f64;
    let per = e.per_statement.into_data().try_into_vec::<f32>().unwrap();
    (total, per.into_iter().map(f64::from).collect())
}

/// Gradient of the total w.r.t. the joints on the autodiff device.
pub fn grad(p: &Program, data: &[f32], shape: [usize; 5]) -> Vec<f32> {
    let dev = Device::flex().autodiff();
    let x = Tensor::<5>::from_data(TensorData::new(data.to_vec(), shape), &dev).require_grad();
    let e = p.evaluate(x.clone());
    let g = e.total.sum().backward();
    x.grad(&g)
        .expect("joints get a gradient")
        .into_data()
        .try_into_vec::<f32>()
        .unwrap()
}

/// Compares the autodiff gradient with central differences on its largest entries and a
/// few fixed others. Panics with details on a mismatch.
pub fn check_gradient(p: &Program, m: &Motion, what: &str) {
    let (data, shape) = flat(m);
    let g = grad(p, &data, shape);
    assert!(
        g.iter().all(|v| v.is_finite()),
        "{what}: non-finite gradient"
    );
    let mut order: Vec<usize> = (0..g.len()).collect();
    order.sort_by(|&a, &b| g[b].abs().total_cmp(&g[a].abs()));
    let mut picks: Vec<usize> = order.iter().take(6).copied().collect();
    picks.extend([7, g.len() / 3, g.len() / 2 + 5, g.len() - 4]);
    let h = 1e-3f32;
    for &i in &picks {
        let mut plus = data.clone();
        plus[i] += h;
        let mut minus = data.clone();
        minus[i] -= h;
        let fd = (eval(p, &plus, shape).0 - eval(p, &minus, shape).0) / (2.0 * f64::from(h));
        let an = f64::from(g[i]);
        let tol = 5e-3 + 2e-2 * an.abs().max(fd.abs());
        assert!(
            (an - fd).abs() <= tol,
            "{what}: d/dx[{i}] autodiff {an} vs finite difference {fd}"
        );
    }
}

// Small vector helpers for the reference computations.
pub fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}
pub fn add(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}
pub fn scale(a: [f64; 3], k: f64) -> [f64; 3] {
    [a[0] * k, a[1] * k, a[2] * k]
}
pub fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}
pub fn norm(a: [f64; 3]) -> f64 {
    dot(a, a).sqrt()
}
pub fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}
pub fn relu(x: f64) -> f64 {
    x.max(0.0)
}
pub fn mean(xs: impl IntoIterator<Item = f64>) -> f64 {
    let v: Vec<f64> = xs.into_iter().collect();
    v.iter().sum::<f64>() / v.len() as f64
}
