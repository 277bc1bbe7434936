//! Linear time-invariant systems: continuous transfer functions and state-space
//! models, exact zero-order-hold discretisation, simulation, poles, zeros and
//! frequency response.
//!
//! Coefficients of feed-drive models span 1e-8 … 1e16, so every conversion goes
//! through a balanced state-space realisation; nothing is simulated from raw
//! polynomial coefficients.
//!
//! * Realisation: [`TransferFunction::to_state_space`] builds the controllable
//!   companion form of the monic denominator and balances it with
//!   [`StateSpace::balance`]: a diagonal similarity x = T·x̃, T = diag of powers
//!   of 2, from the Parlett–Reinsch / LAPACK `dgebal` iteration run to
//!   convergence on `[[A, B], [C, 0]]` (MATLAB `ssbal`). Powers of 2 make the
//!   similarity exact; equal row and column norms bound the rounding errors
//!   of everything downstream by ε·(pole magnitudes) instead of ε·1e23.
//! * Poles and roots: eigenvalues of balanced (companion) matrices by
//!   Hessenberg reduction and the double-shift QR iteration (EISPACK `hqr`).
//! * Discretisation: exact ZOH from the matrix exponential of the augmented
//!   matrix `[[A, B], [0, 0]]·Δt` (balanced scaling and squaring, Padé 13);
//!   ramps through an extra integrator state so sampled ramp responses are exact.
//! * [`StateSpace::to_tf`]: characteristic polynomial from real linear and
//!   quadratic eigenvalue factors; numerator from the first Markov parameter
//!   and the invariant zeros.
//!
//! ```
//! use feedid::lti::TransferFunction;
//! // Feed-drive closed loop of docs/METHODS.md §2.5 (coefficients rounded to 6 digits).
//! let g = TransferFunction::new(
//!     vec![4.10814e9, 1.60209e13, 6.63693e15],
//!     vec![1.68e-8, 2.69316e-4, 1.57906, 6.30146e3, 1.77277e7, 2.71640e10, 2.55023e13, 6.63693e15],
//! ).unwrap();
//! assert!((g.dc_gain() - 1.0).abs() < 1e-12);
//! assert!(g.is_stable().unwrap());
//! let y = g.step_response(2e-4, 100).unwrap(); // 20 ms at 5 kHz
//! assert!((y[99] - 1.0).abs() < 1e-3);
//! ```

mod balance;
mod butterworth;
mod discrete;
mod eig;
mod expm;
mod poly;
mod ss;
mod tf;

pub use butterworth::{butterworth_lowpass, filtfilt, Biquad};
pub use discrete::DiscreteStateSpace;
pub use nalgebra::Complex;
pub use poly::{poly_eval, poly_from_roots, poly_roots};
pub use ss::StateSpace;
pub use tf::{FrequencyPoint, TransferFunction};
