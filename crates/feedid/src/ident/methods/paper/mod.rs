//! The paper's short-time identification (Nassef et al., sections III–V).
//!
//! The closed loop `X_a/X_s = N(s)/D(s)` with `N = N2·s² + N1·s + N0` and
//! `D = D7·s⁷ + … + D0` is divided by `s⁸` and read as a pair of Laplace
//! transforms (eq. 4–6). Their inverse transforms are polynomials in the time
//! `τ` since the time origin:
//!
//! ```text
//!     X_a(τ) = P5·τ⁵ + P6·τ⁶ + P7·τ⁷,      P5 = N2/120, P6 = N1/720, P7 = N0/5040
//!     X_s(τ) = Σ_{i=0..7} Q_i·τⁱ,           Q_i = D_{7−i}/i!
//! ```
//!
//! Per window of `W` samples the output model is fitted to the measured
//! position and the input model to the command, each by least squares
//! (eq. 8), and mapped to `N2, N1, N0, D7 … D0`
//! ([`coefficients_from_polynomials`]).
//!
//! **Time origin** ([`TimeOrigin`]): `τ = t − motion_start` (the paper's
//! reading, default) or `τ = t − t_first` of each window.
//!
//! **Scaled coordinates.** In seconds the basis `τ⁵, τ⁶, τ⁷` is tiny and nearly
//! collinear, and `1 … τ⁷` far from the origin is numerically degenerate
//! (column-scaled monomials have condition numbers of 1e7 … 1e13 for
//! windows 4 … 50 ms after the motion start). Both solvers therefore work on
//! the *same* well-conditioned basis of the *same* model families, with the
//! window mapped to `s = (τ − τ_c)/h ∈ [−1, 1]` (`τ_c`, `h`: centre and
//! half-width of the window in `τ`) and `T = max |τ|` over the window:
//!
//! ```text
//!     output:  φ_k(τ) = (τ/T)⁵·L_k(s),  k = 0, 1, 2   (span = {τ⁵, τ⁶, τ⁷})
//!     input:   ψ_k(τ) = L_k(s),          k = 0 … 7     (span = {1, …, τ⁷})
//! ```
//!
//! with `L_k` the Legendre polynomials, each column normalised to unit
//! 2-norm over the window. The fitted functions are identical to the fits on
//! the raw monomials (same least-squares problem, eq. 8); only the
//! coordinates differ. The coefficients `P`, `Q` are then obtained by an
//! exact change of basis (Legendre → powers of `s` → Taylor shift to powers of
//! `τ`). That last step is intrinsically ill-conditioned far from the origin
//! (the monomial coefficients of a window 25 s after the origin cancel over
//! ~30 decades); its growth factor is reported as
//! [`PaperDiagnostics::shift_amplification`]. Predictions in
//! [`PredictionMode::Polynomial`] are evaluated in the fitted basis and stay
//! accurate regardless.
//!
//! **One projection per sample grid.** The basis `L_0(s) … L_7(s)` depends
//! only on the window's grid `s_i`, which a uniformly sampled recording
//! repeats in every window, with either time origin; its thin QR
//! `V = Q·R` is computed once and reused while the grid repeats (to the
//! rounding of `s_i` itself), and a window costs the projections `Qᵀb`
//! (`8·W` multiply-adds each). The output basis is an exact polynomial
//! transform `V·C` of the local one (`C` from `(τ_c/T + (h/T)·s)⁵·L_k(s)`),
//! so the output fit is an 8×3 problem. Jittered grids rebuild the QR per
//! window. See `projection.rs`.
//!
//! **Solvers** ([`Solver`]): `Qr` is the exact linear least-squares solution
//! (Householder QR with column pivoting, [`crate::solve::lstsq_in_place`]'s
//! algorithm, on the projected problems); `Simplex` is the
//! paper's Nelder–Mead minimisation of the same sums of squares, evaluated in
//! the projected form `‖M·z − Qᵀb‖² + ‖b⊥‖²` (the same function, `8·n`
//! instead of `W·n` multiply-adds): once for the 3 output coefficients and
//! once for the 8 input coefficients. The paper is silent on the start and
//! the tolerances; by default ([`SimplexStart::Zeros`]) every window starts
//! from **zero coefficients** (each window is then independent of the
//! previous ones, so results do not depend on the hop, on the order of
//! processing or on batch vs streaming use) with start steps `step_rel·‖b‖`;
//! [`SimplexStart::Previous`] starts from the previous window's polynomials
//! projected on this window's basis, with start steps scaled to that start's
//! distance from the best degree-7 polynomial (about 2.5× fewer iterations).
//! Tolerances are relative to the window's data norm `‖b‖` (see
//! [`SimplexSettings`]). With
//! the defaults the simplex resolves exactly representable data to
//! `‖G·Δz‖ ≈ 1e-13·‖b‖` and otherwise to the rounding level of the sum of
//! squares, so that simplex and QR coefficients agree to 1e-6 relative where
//! the change of basis is benign, and predictions agree to 1e-6 of the data
//! scale everywhere. This costs about 150 iterations for the 3-parameter
//! output fit and 600–1000 for the 8-parameter input fit per window from
//! zeros: the simplex is two orders of magnitude slower than QR, which is
//! the default.
//!
//! **Prediction** ([`PredictionMode`]): `Polynomial` (default) continues the
//! fitted output polynomial over the horizon — the response of the identified
//! `Tf` to the fitted input polynomial is `N(s)/s⁸`, exactly that polynomial.
//! `TransferFunction` drives the identified `Tf` with the actual next command:
//! by superposition,
//!
//! ```text
//!     ŷ(t) = P(τ) + [Tf ∗ Δu](t − t_h),   Δu = u_actual − Q(τ) over the horizon,
//! ```
//!
//! with `t_h` the first horizon time, the convolution simulated from the zero
//! state with the exact zero-order-hold discretisation of the identified
//! `N(s)/D(s)` at the nominal sample interval (balanced realisation,
//! [`crate::lti`]). If the fitted command continues exactly, `Δu = 0` and
//! both modes coincide. If the identified `Tf` cannot be built, is unstable
//! or gives a non-finite response, the window falls back to the polynomial
//! prediction; this is counted ([`PaperMethod::tf_fallbacks`]) and flagged in
//! [`PaperDiagnostics::tf_fallback`]. Building and discretising a model per
//! window allocates (inside [`crate::lti`]); the polynomial mode does not.
//!
//! **Rest and reference** (with [`TimeOrigin::Motion`]): the output model
//! passes through zero at `τ = 0`, so positions are measured from the rest
//! position at the motion start (the measured position of the last sample at
//! or before the motion start, fixed by the first window that reaches past
//! it; predictions add it back). A window whose last sample is at or before the
//! motion start (or when the motion start is not known yet, `+∞` while
//! streaming) holds only rest data: there is nothing to identify, so it
//! predicts the last measured position held, writes zero coefficients and
//! reports [`FitStatus::Fallback`](crate::ident::FitStatus::Fallback). The command is fitted as given: its
//! model has a constant term (`Q0 = D7`).
//!
//! Reference: M.G.A. Nassef, L. Li, C. Schenck, B. Kuhfuss, "Short Time
//! Identification of Feed Drive Systems using Nonlinear Least Squares Method",
//! eq. (3)–(8); docs/METHODS.md §4.

mod basis;
mod config;
mod estimator;
mod polynomials;
mod projection;
mod simplex;
#[cfg(test)]
mod tests;

pub use config::{
    PaperConfig, PredictionMode, SimplexSettings, SimplexStart, Solver, TimeOrigin,
    SHIFT_AMPLIFICATION_WARNING,
};
pub use estimator::{PaperDiagnostics, PaperMethod};
pub use polynomials::{coefficients_from_polynomials, polynomials_from_coefficients};
