//! Windowed ARX identification with an exact sliding least-squares update,
//! and a batch (global) ARX fit.
//!
//! # Model
//!
//! ```text
//! A(q)·ỹ[k] = B(q)·ũ[k] + e[k]
//! A = 1 + a1·q⁻¹ + … + a_na·q⁻ⁿᵃ,   B = q⁻ⁿᵏ·(b_nk + b_(nk+1)·q⁻¹ + … + b_(nk+nb−1)·q⁻⁽ⁿᵇ⁻¹⁾)
//! ```
//!
//! in **deviation coordinates** `ỹ = y − r`, `ũ = u − r` from a reference
//! position `r`: positions are far from zero (EMPS up to 0.25 m), the
//! dynamics live in micrometres. For a window `[s, e)` the reference is the
//! last measured position of the window, `r = y[e−1]`, for fitting and for
//! predicting, so the prediction starts from the last measurement. (The
//! model has no offset term; with a unit DC gain, as for a position servo,
//! the result is independent of `r`; [`ArxConfig::offset`] adds an offset
//! term `c` for other systems.) The batch fit [`fit_arx`] uses
//! `r = y[0]`, the same convention as [`LinearModel::simulate`] (start at
//! rest at the first sample).
//!
//! Regression row `k` (one per sample of the window):
//! `ψ_k = [−ỹ[k−1] … −ỹ[k−na], ũ[k−nk] … ũ[k−nk−nb+1]]`, target `ỹ[k]`,
//! coefficients `θ = [a1 … a_na, b_nk … b_(nk+nb−1)]` (coefficient names
//! `"a1"…`, `"b<lag>"`). `nk = 0` is allowed: the command is the set-point,
//! known ahead of the prediction horizon.
//!
//! # Least squares
//!
//! `θ = argmin ‖Ψθ − ỹ‖² + ρ·Σ d_j²·θ_j²` with `d_j` the 2-norm of column `j`
//! of `Ψ` (a *relative* ridge `ρ`, [`ArxConfig::ridge`]). No normal
//! equations: the rows `[1, ψ_k, y_k]` (columns scaled by fixed factors) are
//! kept as an upper-triangular QR factor `R` of the window in the window's
//! frame `r` (see the sliding factor). Its columns `ψ` and `y` are then the
//! window's problem already reduced to upper-Hessenberg form (the ones
//! column's row 0 on top of a triangle), and the ridge problem is solved
//! from them in `n³/3 + O(n²)` operations ([`lstsq_hessenberg`](crate::solve::lstsq_hessenberg):
//! Householder reflections on the stacked `[R; √ρ·diag(c_j)]`).
//! Without ridge, or with a finite [`ArxConfig::max_condition`], the same
//! small matrix goes through the pivoted Householder QR
//! ([`lstsq_in_place`](crate::solve::lstsq_in_place)) instead, which reveals the rank and estimates the
//! condition for the decision.
//!
//! **Sliding update without downdating.** When the window is the previous
//! one shifted by the hop `h < W`, its factor is the merge of two factors
//! kept from earlier windows: the factor of its rows up to the last
//! *rebuild* (suffix factors computed then, every `⌈W/h⌉` windows, by block
//! Householder updates) and the factor of the rows since (the new `h` rows of
//! each window added by one block update). Each window's factor comes from
//! its exact rows by orthogonal transformations only — no downdate, no
//! drift; per window `O(h·p²)` for the new rows, `p³/3` for the merge and
//! the share of the rebuild. The result equals a fresh fit to rounding
//! (tested to `1e-9 + 1e-11·κ` relative). An earlier LINPACK `dchdd`
//! downdate failed on about a third of the windows of smooth data (the
//! lagged commands of a chirp at 5 kHz are collinear to machine precision)
//! and fell back to refactoring.
//!
//! # Per-window checks and fallback
//!
//! A window is **not informative** when the command is standing still in it
//! (standard deviation of `u[k−nk]` over the rows below
//! [`ArxConfig::min_excitation`]), or the scaled regression is numerically
//! rank deficient (condition estimate above [`ArxConfig::max_condition`], or
//! numerical rank below the parameter count without ridge).
//! An identified model is **rejected** when a coefficient is not finite, a
//! pole lies outside the radius [`ArxConfig::max_pole_radius`] (Schur–Cohn
//! step-down test on `A`, allocation-free), or the DC gain `B(1)/A(1)` is
//! outside [`ArxConfig::dc_gain_bounds`]. In both cases the last good model
//! is kept and the window reports [`FitStatus::Fallback`](crate::ident::FitStatus::Fallback); without any
//! good model yet the fit is an error ([`Error::Singular`]) and the engine
//! records the window as failed.
//!
//! # Prediction (k-step ahead)
//!
//! For the horizon `[e, e+H)`: the past outputs are the measured `ỹ[k]`
//! for `k < e`, the command is known over the horizon, and the model runs
//! forward feeding back its own predictions:
//! `ŷ[t] = r − Σ a_i·ỹ*[t−i] + Σ b_j·ũ[t−j]`, `ỹ*` measured before `e`,
//! predicted after.
//!
//! References: L. Ljung, *System Identification*, 2nd ed., §4.2, §7.3, §10.1;
//! Golub & Van Loan, *Matrix Computations*, 4th ed., §6.5 (updating QR);
//! L. Eldén, BIT 17 (1977) 134–145 (regularised triangular problems);
//! E.I. Jury, *Theory and Application of the z-Transform Method* (Schur–Cohn).
//!
//! ```
//! use feedid::ident::{engine, ArxConfig, ArxOrders, EngineConfig, Signals};
//! // y[k] = 0.6·y[k−1] + 0.4·u[k−1] driven by a sine command
//! let n = 400;
//! let dt = 1e-3;
//! let u: Vec<f64> = (0..n).map(|k| 1e-3 * (0.05 * k as f64).sin()).collect();
//! let mut y = vec![0.0; n];
//! for k in 1..n {
//!     y[k] = 0.6 * y[k - 1] + 0.4 * u[k - 1];
//! }
//! let t: Vec<f64> = (0..n).map(|k| k as f64 * dt).collect();
//! let mut arx = ArxConfig { orders: ArxOrders::new(1, 1, 1), ridge: 0.0, ..ArxConfig::default() }
//!     .build()
//!     .unwrap();
//! let cfg = EngineConfig { window: 50, horizon: 10, hop: Some(1), warm_up: 0 };
//! let res = engine::run(&mut arx, &Signals::new(&t, &u, &y, dt, 0.0), &cfg).unwrap();
//! assert!(res.stats.rms < 1e-12);
//! ```

mod config;
mod estimator;
mod factor;
mod fit;
#[cfg(test)]
mod tests;

pub use config::ArxConfig;
pub use estimator::{ArxDiagnostics, ArxEstimator};
pub(crate) use fit::fit_arx_rows;
pub use fit::{fit_arx, fit_arx_segments, ArxFit};
