//! The closed-loop transfer function `Xa/Xs = N(s)/D(s)` of the cascade
//! (2nd-order numerator over 7th-order denominator, paper appendix eq. A1–A12)
//! and the same cascade as a 7-state state-space model.
//!
//! State equations (SI, `r = lead/2π`, the paper's `K1`):
//!
//! ```text
//! e_v   = Kv·(x_s − x_a) − r·ω                velocity error (table units)
//! i_ref = Kp·(e_v + Ki·z_v),   ż_v = e_v       series PI, Ki a reset rate
//! u     = Kpi·(i_ref − i + Kii·z_i), ż_i = i_ref − i
//! L·di/dt = u − R·i − Ke·ω
//! J·dω/dt = Kt·i − C1·ω − r·K·(r·θ − x_a)
//! M·d²x_a/dt² = K·(r·θ − x_a) − C2·dx_a/dt
//! ```
//!
//! with states `[z_v, z_i, i, θ, ω, x_a, v_a]`, input `x_s`, output `x_a`.
//! Coefficients, normalised so that `D7 = J·L·M` (the paper's common factor
//! `K1` cancels):
//!
//! ```text
//! N2 = K·Kp·Kpi·Kt·Kv·r,  N1 = N2·(Ki + Kii),  N0 = N2·Ki·Kii
//! D7 = J·L·M
//! D6 = C1·L·M + C2·J·L + J·M·(R + Kpi)
//! D5 = C1·C2·L + C1·M·R + C2·J·R + J·K·L + K·L·M·r² + Ke·Kt·M
//!      + Kpi·(C1·M + C2·J + J·Kii·M + Kp·Kt·M·r)
//! D4 = C1·C2·R + C1·K·L + C2·K·L·r² + C2·Ke·Kt + J·K·R + K·M·R·r²
//!      + Kpi·(C1·C2 + C1·Kii·M + C2·J·Kii + C2·Kp·Kt·r + J·K + K·M·r²
//!             + (Ki + Kii)·Kp·Kt·M·r)
//! D3 = K·(C1·R + C2·R·r² + Ke·Kt)
//!      + Kpi·(C1·C2·Kii + C1·K + C2·K·r² + C2·(Ki + Kii)·Kp·Kt·r + J·K·Kii
//!             + K·Kii·M·r² + K·Kp·Kt·r + Ki·Kii·Kp·Kt·M·r)
//! D2 = Kpi·(C1·K·Kii + C2·K·Kii·r² + C2·Ki·Kii·Kp·Kt·r + K·Kp·Kt·r·(Ki + Kii + Kv))
//! D1 = K·Kp·Kpi·Kt·r·(Ki·Kii + Kv·(Ki + Kii))
//! D0 = N0                                        (unit DC gain)
//! ```
//!
//! # Feed-forward
//!
//! With velocity and acceleration feed-forward (`control.kvff`, `control.kaff`,
//! both 0 in the paper's cascade) the references become
//!
//! ```text
//! v_c   = Kv·(x_s − x_a) + kvff·ẋ_s                          [m/s]
//! i_ref = Kp·(e_v + Ki·z_v) + c_a·ẍ_s,   c_a = kaff·(J + M·r²)/(r·Kt)   [A]
//! ```
//!
//! The poles stay those of `D(s)`; the numerator gains the feed-forward paths
//! (the velocity reference reaches `x_a` through `N(s)/(Kv·D(s))`, the current
//! reference through `K·Kpi·Kt·r·s·(s + Kii)/D(s)`):
//!
//! ```text
//! N(s) = G·(Kv + kvff·s)·(s + Ki)·(s + Kii) + H·s³·(s + Kii),
//! G = K·Kp·Kpi·Kt·r,   H = K·Kpi·kaff·(J + M·r²)
//! F4 = H,  F3 = H·Kii + G·kvff,  F2 = G·kvff·(Ki + Kii),  F1 = G·kvff·Ki·Kii
//! ```
//!
//! added to `[N4 … N0] = [0, 0, N2, N1, N0]`. The ramp following error
//! `(D1 − N1 − F1)/D0` becomes `(1 − kvff)/Kv`.
//!
//! The state-space model realises the same transfer function with the command
//! alone as input: with `ẋ = A·x + b₀·x_s + b₁·ẋ_s + b₂·ẍ_s` (b₁ = kvff·b_v,
//! b₂ = c_a·b_i, b_v and b_i the entries of the velocity and current references)
//! the state `z = x − b₂·ẋ_s − (A·b₂ + b₁)·x_s` obeys `ż = A·z + g·x_s` with
//! `g = b₀ + A·b₁ + A²·b₂`, and `x_a` is the same in both (`C·b₁ = C·b₂ = C·A·b₂ = 0`).
//! Without feed-forward `z = x` (the physical states).
//!
//! The paper prints `D1 = K1²·Kt·Kp·Kii·Ki·K·Kpi`, which lacks the term `+N1`.
//! With it the ramp following error `(D1 − N1)/D0` is `1/Kv − 1/Ki − 1/Kii`
//! (negative for real gains) instead of `1/Kv`; it is available as
//! [`D1Variant::PaperPrinted`] for comparison only.
//!
//! ```
//! use feedid::drive::{closed_loop_coefficients, D1Variant, RigParams};
//! let c = closed_loop_coefficients(&RigParams::default(), D1Variant::Corrected);
//! // ramp following error per m/s = (D1 − N1)/D0 = 1/Kv
//! assert!(((c.den[6] - c.num[1]) / c.den[7] - 1.0 / 700.0).abs() < 1e-12);
//! ```

use nalgebra::{DMatrix, DVector, RowDVector};

use crate::drive::RigParams;
use crate::error::Result;
use crate::lti::{StateSpace, TransferFunction};

/// Which `D1` coefficient to use.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum D1Variant {
    /// `D1 = K·Kp·Kpi·Kt·r·(Ki·Kii + Kv·(Ki + Kii))`, consistent with the state equations.
    #[default]
    Corrected,
    /// The paper's printed `D1 = K·Kp·Kpi·Kt·r·Ki·Kii` (lacks `+N1`); wrong ramp following error.
    PaperPrinted,
}

/// Coefficients of `Xa/Xs` in descending powers of s, normalised so `D7 = J·L·M`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ClosedLoopCoefficients {
    /// `[N2, N1, N0]` of the position-feedback path: the paper's numerator,
    /// the whole numerator without feed-forward.
    pub num: [f64; 3],
    /// `[D7, D6, …, D0]`.
    pub den: [f64; 8],
    /// Terms `[F4, F3, F2, F1]` the feed-forward adds to the numerator (see
    /// the module doc); all 0 without feed-forward.
    pub feed_forward: [f64; 4],
}

impl ClosedLoopCoefficients {
    /// The whole numerator `[N4, N3, N2, N1, N0]` (feedback plus feed-forward).
    pub fn numerator(&self) -> [f64; 5] {
        let f = &self.feed_forward;
        [
            f[0],
            f[1],
            self.num[0] + f[2],
            self.num[1] + f[3],
            self.num[2],
        ]
    }

    /// Steady ramp following error per unit command velocity,
    /// `(D1 − N1 − F1)/D0` \[s\] (= `(1 − kvff)/Kv`).
    pub fn following_error_per_velocity(&self) -> f64 {
        (self.den[6] - self.numerator()[3]) / self.den[7]
    }

    /// DC gain `N0/D0`.
    pub fn dc_gain(&self) -> f64 {
        self.num[2] / self.den[7]
    }

    /// The coefficients as a transfer function (leading zero coefficients
    /// dropped: 2nd over 7th order without feed-forward).
    pub fn transfer_function(&self) -> Result<TransferFunction> {
        TransferFunction::new(self.numerator().to_vec(), self.den.to_vec())
    }
}

/// Closed-loop coefficients at the default nut position (stiffness `params.stiffness_k()`).
pub fn closed_loop_coefficients(params: &RigParams, variant: D1Variant) -> ClosedLoopCoefficients {
    closed_loop_coefficients_with_stiffness(params, params.stiffness_k(), variant)
}

/// Closed-loop coefficients with an explicit equivalent stiffness `k` \[N/m\].
pub fn closed_loop_coefficients_with_stiffness(
    params: &RigParams,
    k: f64,
    variant: D1Variant,
) -> ClosedLoopCoefficients {
    let r = params.r();
    let j = params.inertia_j();
    let m = params.table.mass;
    let (c1, c2) = (params.damping.c1, params.damping.c2);
    let (kt, ke) = (params.motor.kt, params.motor.ke);
    let (res, l) = (params.motor.resistance, params.motor.inductance);
    let g = &params.control;
    let (kv, kp, ki, kpi, kii) = (g.kv, g.kp, g.ki, g.kpi, g.kii);
    let r2 = r * r;

    let n2 = k * kp * kpi * kt * kv * r;
    let n1 = n2 * (ki + kii);
    let n0 = n2 * ki * kii;

    let d7 = j * l * m;
    let d6 = c1 * l * m + c2 * j * l + j * m * (res + kpi);
    let d5 = c1 * c2 * l
        + c1 * m * res
        + c2 * j * res
        + j * k * l
        + k * l * m * r2
        + ke * kt * m
        + kpi * (c1 * m + c2 * j + j * kii * m + kp * kt * m * r);
    let d4 = c1 * c2 * res
        + c1 * k * l
        + c2 * k * l * r2
        + c2 * ke * kt
        + j * k * res
        + k * m * res * r2
        + kpi
            * (c1 * c2
                + c1 * kii * m
                + c2 * j * kii
                + c2 * kp * kt * r
                + j * k
                + k * m * r2
                + (ki + kii) * kp * kt * m * r);
    let d3 = k * (c1 * res + c2 * res * r2 + ke * kt)
        + kpi
            * (c1 * c2 * kii
                + c1 * k
                + c2 * k * r2
                + c2 * (ki + kii) * kp * kt * r
                + j * k * kii
                + k * kii * m * r2
                + k * kp * kt * r
                + ki * kii * kp * kt * m * r);
    let d2 = kpi
        * (c1 * k * kii
            + c2 * k * kii * r2
            + c2 * ki * kii * kp * kt * r
            + k * kp * kt * r * (ki + kii + kv));
    let d1 = match variant {
        D1Variant::Corrected => k * kp * kpi * kt * r * (ki * kii + kv * (ki + kii)),
        D1Variant::PaperPrinted => k * kp * kpi * kt * r * ki * kii,
    };
    let d0 = n0;
    let (kvff, kaff) = (g.kvff, g.kaff);
    let gain = k * kp * kpi * kt * r;
    let h = k * kpi * kaff * (j + m * r2);
    ClosedLoopCoefficients {
        num: [n2, n1, n0],
        den: [d7, d6, d5, d4, d3, d2, d1, d0],
        feed_forward: [
            h,
            h * kii + gain * kvff,
            gain * kvff * (ki + kii),
            gain * kvff * ki * kii,
        ],
    }
}

/// The cascade as a 7-state state-space model at stiffness `params.stiffness_k()`.
///
/// States `[z_v, z_i, i, θ, ω, x_a, v_a]` in SI units, input `x_s` \[m\],
/// output `x_a` \[m\]; with feed-forward the states are shifted by input
/// terms (`z` of the module doc), the output is unchanged.
pub fn closed_loop_state_space(params: &RigParams) -> Result<StateSpace> {
    closed_loop_state_space_with_stiffness(params, params.stiffness_k())
}

/// The cascade as a 7-state state-space model with an explicit stiffness `k` \[N/m\].
pub fn closed_loop_state_space_with_stiffness(params: &RigParams, k: f64) -> Result<StateSpace> {
    let r = params.r();
    let j = params.inertia_j();
    let m = params.table.mass;
    let (c1, c2) = (params.damping.c1, params.damping.c2);
    let (kt, ke) = (params.motor.kt, params.motor.ke);
    let (res, l) = (params.motor.resistance, params.motor.inductance);
    let g = &params.control;
    let (kv, kp, ki, kpi, kii) = (g.kv, g.kp, g.ki, g.kpi, g.kii);

    // Indices of the states.
    const ZV: usize = 0;
    const ZI: usize = 1;
    const I: usize = 2;
    const TH: usize = 3;
    const W: usize = 4;
    const XA: usize = 5;
    const VA: usize = 6;

    let mut a = DMatrix::<f64>::zeros(7, 7);
    let mut b = DVector::<f64>::zeros(7);
    // ż_v = e_v = −r·ω − Kv·x_a + Kv·x_s
    a[(ZV, W)] = -r;
    a[(ZV, XA)] = -kv;
    b[ZV] = kv;
    // ż_i = i_ref − i = Kp·Ki·z_v − i + Kp·e_v
    a[(ZI, ZV)] = kp * ki;
    a[(ZI, I)] = -1.0;
    a[(ZI, W)] = -kp * r;
    a[(ZI, XA)] = -kp * kv;
    b[ZI] = kp * kv;
    // L·di/dt = Kpi·(i_ref − i + Kii·z_i) − R·i − Ke·ω
    a[(I, ZV)] = kpi * kp * ki / l;
    a[(I, ZI)] = kpi * kii / l;
    a[(I, I)] = -(kpi + res) / l;
    a[(I, W)] = -(kpi * kp * r + ke) / l;
    a[(I, XA)] = -kpi * kp * kv / l;
    b[I] = kpi * kp * kv / l;
    // θ̇ = ω
    a[(TH, W)] = 1.0;
    // J·ω̇ = Kt·i − C1·ω − r·K·(r·θ − x_a)
    a[(W, I)] = kt / j;
    a[(W, TH)] = -r * r * k / j;
    a[(W, W)] = -c1 / j;
    a[(W, XA)] = r * k / j;
    // ẋ_a = v_a
    a[(XA, VA)] = 1.0;
    // M·v̇_a = K·(r·θ − x_a) − C2·v_a
    a[(VA, TH)] = k * r / m;
    a[(VA, XA)] = -k / m;
    a[(VA, VA)] = -c2 / m;

    if g.kvff != 0.0 || g.kaff != 0.0 {
        // g = b₀ + A·b₁ + A²·b₂ (module doc): b₁ = kvff·b_v, b₂ = c_a·b_i
        let (bv, bi) = reference_inputs(params);
        let b1 = bv * g.kvff;
        let b2 = bi * params.acceleration_feed_forward_gain();
        let ab2 = &a * &b2;
        b += &a * (b1 + ab2);
    }
    let mut c = RowDVector::<f64>::zeros(7);
    c[XA] = 1.0;
    StateSpace::new(a, b, c, 0.0)
}

/// Input vectors of the velocity reference `v_c` \[m/s\] and of a current
/// added to the current reference \[A\] in the physical state coordinates
/// `[z_v, z_i, i, θ, ω, x_a, v_a]` of [`closed_loop_state_space`]:
/// `b_v = [1, Kp, Kpi·Kp/L, 0, 0, 0, 0]`, `b_i = [0, 1, Kpi/L, 0, 0, 0, 0]`.
/// With the position loop opened (`Kv = 0`, no feed-forward) the cascade is
/// `ẋ = A₀·x + b_v·v_c + b_i·i_ff`; the feed-forward of the module doc is
/// `b₁ = kvff·b_v`, `b₂ = c_a·b_i`.
///
/// ```
/// use feedid::drive::{reference_inputs, RigParams};
/// let p = RigParams::default();
/// let (bv, bi) = reference_inputs(&p);
/// assert_eq!(bv[1], p.control.kp);
/// assert_eq!(bi[1], 1.0);
/// ```
pub fn reference_inputs(params: &RigParams) -> (DVector<f64>, DVector<f64>) {
    let g = &params.control;
    let l = params.motor.inductance;
    let mut bv = DVector::<f64>::zeros(7);
    bv[0] = 1.0;
    bv[1] = g.kp;
    bv[2] = g.kpi * g.kp / l;
    let mut bi = DVector::<f64>::zeros(7);
    bi[1] = 1.0;
    bi[2] = g.kpi / l;
    (bv, bi)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rel(a: f64, b: f64) -> f64 {
        ((a - b) / b).abs()
    }

    #[test]
    fn default_rig_reproduces_notes_coefficients() {
        let c = closed_loop_coefficients(&RigParams::default(), D1Variant::Corrected);
        let num = [4.10814e9, 1.60209e13, 6.63693e15];
        let den = [
            1.68000e-8, 2.69316e-4, 1.57906, 6.30146e3, 1.77277e7, 2.71640e10, 2.55023e13,
            6.63693e15,
        ];
        for (k, (&got, &want)) in c.num.iter().zip(num.iter()).enumerate() {
            assert!(rel(got, want) < 6e-6, "N{}: {got} vs {want}", 2 - k);
        }
        for (k, (&got, &want)) in c.den.iter().zip(den.iter()).enumerate() {
            assert!(rel(got, want) < 6e-6, "D{}: {got} vs {want}", 7 - k);
        }
    }

    #[test]
    fn dc_gain_is_one() {
        let c = closed_loop_coefficients(&RigParams::default(), D1Variant::Corrected);
        assert!((c.dc_gain() - 1.0).abs() < 1e-15);
    }

    #[test]
    fn ramp_following_error_is_one_over_kv() {
        let p = RigParams::default();
        let c = closed_loop_coefficients(&p, D1Variant::Corrected);
        let e = c.following_error_per_velocity();
        assert!(rel(e, 1.0 / p.control.kv) < 1e-12, "{e}");
        // 50 mm/s → 71.4 µm (docs/METHODS.md §2.5)
        assert!((0.05 * e - 71.4e-6).abs() < 0.05e-6);
    }

    #[test]
    fn printed_d1_gives_the_documented_wrong_following_error() {
        let p = RigParams::default();
        let c = closed_loop_coefficients(&p, D1Variant::PaperPrinted);
        let g = &p.control;
        let want = 1.0 / g.kv - 1.0 / g.ki - 1.0 / g.kii;
        assert!(rel(c.following_error_per_velocity(), want) < 1e-12);
        assert!(c.following_error_per_velocity() < 0.0);
    }

    #[test]
    fn printed_d1_differs_from_corrected_by_n1() {
        let p = RigParams::default();
        let a = closed_loop_coefficients(&p, D1Variant::Corrected);
        let b = closed_loop_coefficients(&p, D1Variant::PaperPrinted);
        assert!(rel(a.den[6] - b.den[6], a.num[1]) < 1e-12);
    }

    #[test]
    fn coefficients_equal_state_space_conversion() {
        // Random-ish but physical variations of the default rig, including a
        // different nut position, all to 1e-9 relative.
        let mut p = RigParams::default();
        for case in 0..4 {
            let tf = closed_loop_state_space(&p).unwrap().to_tf().unwrap();
            let c = closed_loop_coefficients(&p, D1Variant::Corrected);
            let scale = c.den[0] / tf.den()[0];
            assert_eq!(tf.den().len(), 8);
            for (k, (&got, &want)) in tf.den().iter().zip(c.den.iter()).enumerate() {
                assert!(
                    rel(got * scale, want) < 1e-9,
                    "case {case} D{}: {got} vs {want}",
                    7 - k
                );
            }
            let num = tf.num();
            assert_eq!(num.len(), 3, "relative degree 5: {num:?}");
            for (k, (&got, &want)) in num.iter().zip(c.num.iter()).enumerate() {
                assert!(
                    rel(got * scale, want) < 1e-9,
                    "case {case} N{}: {got} vs {want}",
                    2 - k
                );
            }
            p.control.kv *= 1.3;
            p.damping.c2 *= 2.0;
            p.table.mass *= 0.7;
            p.geometry.nut_position *= 0.5;
        }
    }

    #[test]
    fn feed_forward_coefficients_equal_state_space_conversion_and_keep_the_poles() {
        for (kvff, kaff, degree) in [(0.9, 0.0, 3), (0.0, 0.7, 4), (1.0, 1.0, 4)] {
            let mut p = RigParams::default();
            p.control.kvff = kvff;
            p.control.kaff = kaff;
            p.table.mass = 40.0;
            let c = closed_loop_coefficients(&p, D1Variant::Corrected);
            let plain = {
                let mut q = p;
                q.control.kvff = 0.0;
                q.control.kaff = 0.0;
                closed_loop_coefficients(&q, D1Variant::Corrected)
            };
            assert_eq!(c.den, plain.den, "feed-forward moves no pole");
            assert_eq!(c.num, plain.num);
            let tf = closed_loop_state_space(&p).unwrap().to_tf().unwrap();
            let scale = c.den[0] / tf.den()[0];
            for (&got, &want) in tf.den().iter().zip(c.den.iter()) {
                assert!(rel(got * scale, want) < 1e-9, "{got} vs {want}");
            }
            let full = c.numerator();
            let want = &full[4 - degree..];
            assert_eq!(tf.num().len(), degree + 1, "{:?}", tf.num());
            for (&got, &want) in tf.num().iter().zip(want) {
                assert!(rel(got * scale, want) < 1e-8, "{got} vs {want}");
            }
            assert!((c.dc_gain() - 1.0).abs() < 1e-15);
            let ss = closed_loop_state_space(&p).unwrap();
            assert!((ss.dc_gain().unwrap() - 1.0).abs() < 1e-9);
            assert!(
                rel(
                    c.following_error_per_velocity(),
                    (1.0 - kvff) / p.control.kv
                ) < 1e-9
                    || kvff == 1.0 && c.following_error_per_velocity().abs() < 1e-12
            );
        }
    }

    #[test]
    fn feed_forward_numerator_is_the_closed_form_product() {
        // N(s) = G·(Kv + kvff·s)·(s + Ki)·(s + Kii) + H·s³·(s + Kii)
        let mut p = RigParams::default();
        p.control.kvff = 0.8;
        p.control.kaff = 0.6;
        let c = closed_loop_coefficients(&p, D1Variant::Corrected);
        let g = &p.control;
        let r = p.r();
        let gain = p.stiffness_k() * g.kp * g.kpi * p.motor.kt * r;
        let h = p.stiffness_k() * g.kpi * g.kaff * (p.inertia_j() + p.table.mass * r * r);
        let n = c.numerator();
        for s in [-300.0, -17.0, 0.5, 40.0, 2000.0] {
            let direct =
                gain * (g.kv + g.kvff * s) * (s + g.ki) * (s + g.kii) + h * s * s * s * (s + g.kii);
            let poly = n.iter().fold(0.0, |acc, &a| acc * s + a);
            assert!(rel(poly, direct) < 1e-12, "s = {s}: {poly} vs {direct}");
        }
    }

    #[test]
    fn state_space_has_unit_dc_gain_and_notes_poles() {
        let ss = closed_loop_state_space(&RigParams::default()).unwrap();
        assert!((ss.dc_gain().unwrap() - 1.0).abs() < 1e-12);
        let mut f: Vec<f64> = ss
            .poles()
            .unwrap()
            .iter()
            .filter(|p| p.im >= 0.0)
            .map(|p| p.norm() / (2.0 * std::f64::consts::PI))
            .collect();
        f.sort_by(f64::total_cmp);
        let want = [60.7, 254.0, 561.0, 579.0, 1430.0];
        for (g, w) in f.iter().zip(want) {
            assert!((g - w).abs() / w < 3e-3, "{f:?}");
        }
    }

    #[test]
    fn ramp_response_of_transfer_function_settles_to_v_over_kv_lag() {
        let p = RigParams::default();
        let tf = closed_loop_coefficients(&p, D1Variant::Corrected)
            .transfer_function()
            .unwrap();
        let dt = 2e-4;
        let y = tf.ramp_response(0.05, dt, 1000).unwrap();
        let t_end = 999.0 * dt;
        let lag = 0.05 * t_end - y[999];
        assert!((lag - 0.05 / 700.0).abs() < 1e-9, "{lag}");
    }

    #[test]
    fn state_space_has_seven_states_and_structure() {
        let ss = closed_loop_state_space(&RigParams::default()).unwrap();
        assert_eq!(ss.order(), 7);
        assert_eq!(ss.c[5], 1.0);
        assert_eq!(ss.d, 0.0);
    }
}
