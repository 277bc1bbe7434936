//! Row operations of the small structured QR kernels (the sliding ARX
//! factor, [`lstsq_hessenberg`](super::lstsq_hessenberg)): `y += a·x`,
//! `x −= f·w`, `w = a·x` on rows of a fixed, compile-time length `W`
//! (fully unrolled and vectorised, no bounds checks inside), or with
//! `W = 0` on whole groups of 4 of the given slices (any length that is a
//! multiple of 4).
//!
//! The same operations in the same order either way and no FMA
//! contraction in Rust: results are bit-identical whatever the length
//! policy and whether the caller was compiled for AVX2 ([`avx2`]).

/// Whether the CPU has AVX2 (kernels compiled with `#[target_feature(enable = "avx2")]`),
/// detected at run time: a build runs on any x86-64 CPU and selects the
/// portable kernels where AVX2 is missing (and on other architectures).
/// Workspaces read this once, at construction.
pub(crate) fn avx2() -> bool {
    #[cfg(test)]
    if PORTABLE.with(|p| p.get()) {
        return false;
    }
    #[cfg(target_arch = "x86_64")]
    {
        std::arch::is_x86_feature_detected!("avx2")
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        false
    }
}

#[cfg(test)]
thread_local! {
    /// Tests: make [`avx2`] report `false` on this thread ([`portable`]).
    static PORTABLE: std::cell::Cell<bool> = const { std::cell::Cell::new(false) };
}

/// Tests: run `f` with [`avx2`] reporting `false`, so that the workspaces it
/// builds use the portable kernels (compared with the AVX2 ones).
#[cfg(test)]
pub(crate) fn portable<T>(f: impl FnOnce() -> T) -> T {
    PORTABLE.with(|p| p.set(true));
    let out = f();
    PORTABLE.with(|p| p.set(false));
    out
}

/// `y += a·x`.
#[inline(always)]
pub(crate) fn axpy<const W: usize>(y: &mut [f64], a: f64, x: &[f64]) {
    if W > 0 {
        let (y, x) = (&mut y[..W], &x[..W]);
        for j in 0..W {
            y[j] += a * x[j];
        }
    } else {
        for (yg, xg) in y.chunks_exact_mut(4).zip(x.chunks_exact(4)) {
            for (yj, &xj) in yg.iter_mut().zip(xg) {
                *yj += a * xj;
            }
        }
    }
}

/// `x −= f·w`.
#[inline(always)]
pub(crate) fn sub_scaled<const W: usize>(x: &mut [f64], f: f64, w: &[f64]) {
    if W > 0 {
        let (x, w) = (&mut x[..W], &w[..W]);
        for j in 0..W {
            x[j] -= f * w[j];
        }
    } else {
        for (xg, wg) in x.chunks_exact_mut(4).zip(w.chunks_exact(4)) {
            for (xj, &wj) in xg.iter_mut().zip(wg) {
                *xj -= f * wj;
            }
        }
    }
}

/// `w = a·x`.
#[inline(always)]
pub(crate) fn scaled<const W: usize>(w: &mut [f64], a: f64, x: &[f64]) {
    if W > 0 {
        let (w, x) = (&mut w[..W], &x[..W]);
        for j in 0..W {
            w[j] = a * x[j];
        }
    } else {
        for (wj, &xj) in w.iter_mut().zip(x) {
            *wj = a * xj;
        }
    }
}

/// The reflection that maps `(a, c)` (`σ = ‖c‖²`, `norm = √(a² + σ)`) to
/// `(norm, 0)`: `H = I − τ·v·vᵀ`, `v = (v0, c)`; returns `(norm, v0, τ)`.
/// `v0 = a − norm` is computed without cancellation (`−σ/(a + norm)` for
/// `a > 0`), so the new pivot `norm` is positive.
#[inline(always)]
pub(crate) fn reflection(a: f64, sigma: f64, c: &[f64]) -> (f64, f64, f64) {
    let norm = {
        let s = a * a + sigma;
        if (1e-290..=1e290).contains(&s) {
            s.sqrt()
        } else {
            // rescaled against over- and underflow of the squares
            let m = c.iter().fold(a.abs(), |m, v| m.max(v.abs()));
            if m > 0.0 && m.is_finite() {
                let t: f64 = c.iter().map(|v| (v / m) * (v / m)).sum::<f64>() + (a / m) * (a / m);
                m * t.sqrt()
            } else {
                s.sqrt()
            }
        }
    };
    let v0 = if a <= 0.0 {
        a - norm
    } else {
        -sigma / (a + norm)
    };
    let tau = 2.0 / (v0 * v0 + sigma);
    (norm, v0, tau)
}
