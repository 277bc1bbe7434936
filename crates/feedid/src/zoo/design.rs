//! The zoo's design: which member gets which kind of axis, command and
//! feed-forward (stratified by index), and where in each parameter's range it
//! lies (a low-discrepancy sequence), so ~200 members span every range evenly
//! and any member can be made alone from its index.
//!
//! Categorical choices cycle with coprime periods, so every combination of
//! plant × command × feed-forward occurs in the first 168 members:
//!
//! ```text
//! plant         = i mod 8   (0 heavy, 1 conventional, 2 stiff, 3 heavy, 4 conventional,
//!                            5 stiff rig; 6 first-order, 7 second-order servo)
//! command       = i mod 7   (ramp, step, S-curve, sine sweep, square wave,
//!                            point-to-point, contour axis)
//! feed-forward  = ⌊i/7⌋ mod 3   (none, velocity, velocity + acceleration)
//! glitches      = i mod 12 = 5
//! ```
//!
//! A continuous parameter `d` of member `i` is placed at the quantile
//! `u_d(i) = frac(β_d + i·α_d)` of its range (an additive-recurrence / Weyl
//! sequence), `α_d = frac(√p_d)` for the d-th prime `p_d` and offsets `β_d`
//! from the zoo seed, stretched so that the outer 3 % of quantiles at each
//! end sit exactly on the range's bounds. Rationally independent `α_d` make the points
//! equidistributed in the unit cube (Kronecker), also on every residue class
//! of `i`, so each axis class spans its ranges too. Minor choices (the
//! direction of a move, the sweep law, targets of point-to-point moves, noise,
//! glitch positions) come from a ChaCha8 generator seeded with the zoo seed
//! on stream `i`.

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// Dimensions of the quasi-random design (one per continuous parameter).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[repr(usize)]
pub(crate) enum Dim {
    /// Position-loop gain within its range.
    Kv,
    /// Moving mass.
    Mass,
    /// Recording rate.
    Rate,
    /// Length of the recording.
    Duration,
    /// Command amplitude.
    Amplitude,
    /// Encoder resolution.
    Resolution,
    /// Noise relative to the resolution.
    Noise,
    /// Friction share of the peak force.
    Friction,
    /// Backlash present.
    Backlash,
    /// Backlash width.
    BacklashWidth,
    /// Resonance placed.
    Resonance,
    /// Frequency of a placed resonance.
    ResonanceFrequency,
    /// Screw lead.
    Lead,
    /// Velocity-loop bandwidth over Kv.
    VelocityRatio,
    /// Velocity-loop bandwidth over its reset rate.
    ResetRatio,
    /// Peak acceleration of the axis.
    Acceleration,
    /// Top speed of the axis.
    Velocity,
    /// Velocity feed-forward gain.
    Kvff,
    /// Acceleration feed-forward gain.
    Kaff,
    /// Dead time.
    DeadTime,
    /// Variable (nut-position dependent) stiffness on.
    VariableStiffness,
    /// Load-to-motor inertia ratio.
    InertiaRatio,
    /// Current limit of the drive.
    CurrentLimit,
    /// Electrical time constant.
    ElectricalTime,
    /// Damping of the guides.
    Damping,
    /// Second-order servo damping ratio.
    ServoDamping,
    /// Share of the axis's speed a command uses.
    CommandSpeed,
    /// Share of the axis's acceleration a command uses.
    CommandAcceleration,
}

/// Number of design dimensions.
const DIMS: usize = Dim::CommandAcceleration as usize + 1;

/// The first primes, one per dimension (α_d = frac(√p_d)).
const PRIMES: [u64; DIMS] = [
    2, 3, 5, 7, 11, 13, 17, 19, 23, 29, 31, 37, 41, 43, 47, 53, 59, 61, 67, 71, 73, 79, 83, 89, 97,
    101, 103, 107,
];

/// The quantiles of one member and its own random stream.
pub(crate) struct Draws {
    index: usize,
    offsets: [f64; DIMS],
    /// The member's generator (ChaCha8, zoo seed, stream = index).
    pub rng: ChaCha8Rng,
}

impl Draws {
    /// Draws of member `index` of the zoo with `seed`.
    pub fn new(seed: u64, index: usize) -> Self {
        let mut offsets_rng = ChaCha8Rng::seed_from_u64(seed);
        let offsets = std::array::from_fn(|_| offsets_rng.random::<f64>());
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        rng.set_stream(index as u64 + 1);
        Self {
            index,
            offsets,
            rng,
        }
    }

    /// Quantile `u_d(i) ∈ [0, 1)` of dimension `d`.
    pub fn u(&self, d: Dim) -> f64 {
        let k = d as usize;
        let alpha = (PRIMES[k] as f64).sqrt().fract();
        // i·α mod 1 computed without losing digits for large i
        let step = (self.index as f64 * alpha).fract();
        (self.offsets[k] + step).fract()
    }

    /// Log-uniform value in `[lo, hi]` at the stretched quantile of `d`.
    pub fn log_in(&self, d: Dim, (lo, hi): (f64, f64)) -> f64 {
        log_lerp(lo, hi, stretch(self.u(d)))
    }

    /// Uniform value in `[lo, hi]` at the stretched quantile of `d`.
    pub fn lin_in(&self, d: Dim, (lo, hi): (f64, f64)) -> f64 {
        lo + (hi - lo) * stretch(self.u(d))
    }

    /// A uniform draw in `[lo, hi)` from the member's stream.
    pub fn uniform(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.rng.random::<f64>()
    }

    /// A log-uniform draw in `[lo, hi)` from the member's stream.
    pub fn log_uniform(&mut self, lo: f64, hi: f64) -> f64 {
        let u = self.rng.random::<f64>();
        log_lerp(lo, hi, u)
    }

    /// +1 or −1 from the member's stream.
    pub fn sign(&mut self) -> f64 {
        if self.rng_bool() {
            1.0
        } else {
            -1.0
        }
    }

    /// A fair coin from the member's stream.
    pub fn rng_bool(&mut self) -> bool {
        self.rng.random::<bool>()
    }

    /// A seed for a sub-generator (noise, point-to-point targets).
    pub fn seed(&mut self) -> u64 {
        self.rng.random::<u64>()
    }
}

/// Share of the members placed exactly at each end of a range: 3 %.
const END_SHARE: f64 = 0.03;

/// `(u − ε)/(1 − 2ε)` clamped to `[0, 1]`: the extreme 3 % of the quantiles
/// at each end sit on the bounds, so even a class of ~50 members reaches both
/// ends of its ranges.
fn stretch(u: f64) -> f64 {
    ((u - END_SHARE) / (1.0 - 2.0 * END_SHARE)).clamp(0.0, 1.0)
}

/// `lo·(hi/lo)^u`.
pub(crate) fn log_lerp(lo: f64, hi: f64, u: f64) -> f64 {
    lo * (hi / lo).powf(u)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_dimension_spreads_evenly_over_two_hundred_members() {
        // an equidistributed sequence: every tenth of [0, 1) gets 21 ± 4 of 210
        for k in 0..DIMS {
            let d: Dim = dim_at(k);
            let mut bins = [0usize; 10];
            for i in 0..210 {
                let u = Draws::new(13, i).u(d);
                assert!((0.0..1.0).contains(&u));
                bins[(u * 10.0) as usize] += 1;
            }
            assert!(
                bins.iter().all(|&b| (17..=25).contains(&b)),
                "{d:?} {bins:?}"
            );
        }
    }

    #[test]
    fn the_same_seed_and_index_give_the_same_draws() {
        let mut a = Draws::new(13, 42);
        let mut b = Draws::new(13, 42);
        assert_eq!(a.u(Dim::Kv), b.u(Dim::Kv));
        assert_eq!(a.seed(), b.seed());
        let mut c = Draws::new(13, 43);
        assert_ne!(Draws::new(13, 42).seed(), c.seed());
    }

    fn dim_at(k: usize) -> Dim {
        const ALL: [Dim; DIMS] = [
            Dim::Kv,
            Dim::Mass,
            Dim::Rate,
            Dim::Duration,
            Dim::Amplitude,
            Dim::Resolution,
            Dim::Noise,
            Dim::Friction,
            Dim::Backlash,
            Dim::BacklashWidth,
            Dim::Resonance,
            Dim::ResonanceFrequency,
            Dim::Lead,
            Dim::VelocityRatio,
            Dim::ResetRatio,
            Dim::Acceleration,
            Dim::Velocity,
            Dim::Kvff,
            Dim::Kaff,
            Dim::DeadTime,
            Dim::VariableStiffness,
            Dim::InertiaRatio,
            Dim::CurrentLimit,
            Dim::ElectricalTime,
            Dim::Damping,
            Dim::ServoDamping,
            Dim::CommandSpeed,
            Dim::CommandAcceleration,
        ];
        ALL[k]
    }
}
