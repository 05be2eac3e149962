//! Which burn device the command line computes on.
//!
//! Library code takes a `Device`; only the binary picks one. The default is burn's flex
//! CPU backend. A build with the `cuda` or `wgpu` cargo feature can run the same code on
//! a GPU by setting `MPROG_DEVICE=cuda` (or `wgpu`); asking for a backend the binary was
//! built without is an error that says which feature to enable.

use burn::prelude::Device;

/// The environment variable that names the backend.
pub const DEVICE_ENV: &str = "MPROG_DEVICE";

/// The backends this binary was built with, by name.
pub fn available() -> Vec<&'static str> {
    let mut names = vec!["flex"];
    if cfg!(feature = "cuda") {
        names.push("cuda");
    }
    if cfg!(feature = "wgpu") {
        names.push("wgpu");
    }
    if cfg!(feature = "ndarray") {
        names.push("ndarray");
    }
    names
}

/// The device named by `name` (`flex`/`cpu`, `cuda`, `wgpu`, `ndarray`).
pub fn device_named(name: &str) -> Result<Device, String> {
    match name.trim().to_ascii_lowercase().as_str() {
        "" | "flex" | "cpu" => Ok(Device::flex()),
        #[cfg(feature = "cuda")]
        "cuda" => Ok(Device::cuda(0)),
        #[cfg(feature = "wgpu")]
        "wgpu" => Ok(Device::wgpu(Default::default())),
        #[cfg(feature = "ndarray")]
        #[allow(deprecated)]
        "ndarray" => Ok(Device::ndarray()),
        other @ ("cuda" | "wgpu" | "ndarray") => Err(format!(
            "{DEVICE_ENV}={other}, but this mprog was built without the `{other}` feature \
             (rebuild with `cargo build --release --features {other}`); available: {}",
            available().join(", ")
        )),
        other => Err(format!(
            "{DEVICE_ENV}={other} is not a backend; available: {}",
            available().join(", ")
        )),
    }
}

/// The device from `MPROG_DEVICE`, flex when unset.
pub fn device_from_env() -> Result<Device, String> {
    match std::env::var(DEVICE_ENV) {
        Ok(name) => device_named(&name),
        Err(_) => Ok(Device::flex()),
    }
}

/// Name of the backend `MPROG_DEVICE` selects (`flex` when unset), for reports.
pub fn backend_name() -> String {
    std::env::var(DEVICE_ENV)
        .map(|n| n.trim().to_ascii_lowercase())
        .ok()
        .filter(|n| !n.is_empty() && n != "cpu")
        .unwrap_or_else(|| "flex".into())
}

/// The widest vector instructions this CPU offers that the matrix kernels use: gemm picks
/// its AVX-512 kernels at run time where the CPU has them (the `x86-v4` feature it is
/// built with), else AVX2 with FMA.
pub fn vector_width() -> &'static str {
    #[cfg(target_arch = "x86_64")]
    {
        if std::arch::is_x86_feature_detected!("avx512f") {
            return "AVX-512";
        }
        if std::arch::is_x86_feature_detected!("avx2") && std::arch::is_x86_feature_detected!("fma")
        {
            return "AVX2";
        }
        "SSE"
    }
    #[cfg(target_arch = "aarch64")]
    {
        "NEON"
    }
    #[cfg(not(any(target_arch = "x86_64", target_arch = "aarch64")))]
    {
        "scalar"
    }
}

/// One line about this machine: CPU model, its vector width and logical cores, plus the
/// GPU's name when `nvidia-smi` answers (best effort; for benchmark headers).
pub fn machine_description() -> String {
    let cpu = std::fs::read_to_string("/proc/cpuinfo")
        .ok()
        .and_then(|s| {
            s.lines()
                .find(|l| l.starts_with("model name"))
                .and_then(|l| l.split_once(':'))
                .map(|(_, v)| v.trim().to_string())
        })
        .unwrap_or_else(|| std::env::consts::ARCH.to_string());
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    let gpu = std::process::Command::new("nvidia-smi")
        .args(["--query-gpu=name", "--format=csv,noheader"])
        .output()
        .ok()
        .filter(|o| o.status.success())
        .map(|o| String::from_utf8_lossy(&o.stdout).trim().to_string())
        .filter(|s| !s.is_empty());
    let width = vector_width();
    match gpu {
        Some(g) => format!("{cpu} ({width}), {cores} cores; GPU {g}"),
        None => format!("{cpu} ({width}), {cores} cores"),
    }
}

/// Stack of the compute pool's threads: the main thread's usual 8 MiB, since the whole
/// command runs on one of them (parsing an untrusted program recurses).
const POOL_STACK_BYTES: usize = 8 << 20;

/// Runs `f` on a thread of rayon's global pool, the pool burn-flex splits its large
/// element-wise ops, reductions and matrix products across.
///
/// Called from outside the pool, every such op hands its pieces to the pool's threads and
/// puts the caller to sleep on a futex until they are done: two context switches per op,
/// and the caller's own core idle meanwhile. A program's error + gradient at batch 32 is
/// ~60 such ops of 140K elements, and `perf` put a quarter of its samples in that hand-off
/// (`LockLatch::wait_and_reset`, `sched_yield`, `try_to_wake_up`). Run from a pool thread,
/// an op forks in place and the calling thread works one of the pieces itself (HSI-3's
/// gradient at batch 32: 2.5–2.6 ms → 1.4 ms; book, benchmarks page).
///
/// `MPROG_COMPUTE_ON_POOL=0` runs `f` on the calling thread instead (to measure the
/// difference). The pool is built here with 8 MiB stacks unless something
/// built it already.
pub fn on_compute_pool<T: Send>(f: impl FnOnce() -> T + Send) -> T {
    if std::env::var("MPROG_COMPUTE_ON_POOL").is_ok_and(|v| v.trim() == "0") {
        return f();
    }
    // An error means the global pool exists already; it is used as it is.
    let _ = rayon::ThreadPoolBuilder::new()
        .stack_size(POOL_STACK_BYTES)
        .build_global();
    rayon::scope(|_| f())
}

/// glibc hands every freed block above 128 KiB back to the kernel, so each training step,
/// sampling step or solver iteration faults its activations in again as fresh zeroed pages:
/// 52,000 page faults a second and a third of the CPU in the kernel while training (measured
/// on the 2-core machine). Keeping blocks up to 32 MiB (the largest glibc allows for this)
/// on the heap, and not trimming it, reuses them instead. glibc's own settings win: with
/// any `MALLOC_*_` variable or `GLIBC_TUNABLES` set nothing is changed (so
/// `MALLOC_TOP_PAD_=131072`, glibc's default, measures the untuned allocator).
///
/// Call it first thing in `main`: the binary does, and so do the benchmarks, so they time what the binary runs (a program's error + gradient at batch
/// 32 took 3–5 ms untuned against 0.45 ms tuned, all of the difference page faults).
#[cfg(all(target_os = "linux", target_env = "gnu"))]
pub fn tune_allocator() {
    let user_set = std::env::vars_os().any(|(k, _)| {
        let k = k.to_string_lossy();
        k == "GLIBC_TUNABLES" || (k.starts_with("MALLOC_") && k.ends_with('_'))
    });
    if user_set {
        return;
    }
    // SAFETY: mallopt only sets allocator parameters, under glibc's arena lock.
    unsafe {
        libc::mallopt(libc::M_MMAP_THRESHOLD, 32 << 20);
        libc::mallopt(libc::M_TRIM_THRESHOLD, 1 << 30);
        libc::mallopt(libc::M_TOP_PAD, 256 << 20);
    }
}

/// Does nothing: the tuning is for glibc's allocator.
#[cfg(not(all(target_os = "linux", target_env = "gnu")))]
pub fn tune_allocator() {}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn flex_is_always_there_and_unknown_names_are_refused() {
        assert!(device_named("flex").is_ok());
        assert!(device_named(" CPU ").is_ok());
        let err = device_named("tpu").unwrap_err();
        assert!(
            err.contains("not a backend") && err.contains("flex"),
            "{err}"
        );
        if !cfg!(feature = "cuda") {
            let err = device_named("cuda").unwrap_err();
            assert!(err.contains("--features cuda"), "{err}");
        }
    }
}
