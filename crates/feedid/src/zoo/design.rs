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
//! Each continuous parameter is drawn by Latin-hypercube sampling within
//! the member's plant group (heavy, conventional and stiff rig, first- and
//! second-order servo: 26–53 members each in the standard zoo): the `N_g`
//! members of group `g` take the quantiles `(π(j) + ½)/N_g` of the range,
//! `j` the member's place in its group and `π` a permutation seeded by the
//! zoo seed, the dimension and the group, independent between dimensions.
//! The quantiles are stretched so that the outer 3 % at each end sit exactly
//! on the bounds: every group reaches both ends of each of its ranges, and
//! member `i` depends only on the seed, `i` and the number of regular members.
//! Minor choices (the direction of a move, the sweep law, targets of
//! point-to-point moves, noise, glitch positions) come from a ChaCha8
//! generator seeded with the zoo seed on stream `i`.

use rand::seq::SliceRandom;
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

/// Plant group of member `i`: 0 heavy, 1 conventional, 2 stiff rig,
/// 3 first-order, 4 second-order servo (`i mod 8` as in the module doc).
pub(crate) fn plant_group(i: usize) -> usize {
    match i % 8 {
        0 | 3 => 0,
        1 | 4 => 1,
        2 | 5 => 2,
        6 => 3,
        _ => 4,
    }
}

/// The quantiles of one member and its own random stream.
#[derive(Clone)]
pub(crate) struct Draws {
    quantiles: [f64; DIMS],
    /// The member's generator (ChaCha8, zoo seed, stream = index + 1).
    pub rng: ChaCha8Rng,
}

impl Draws {
    /// Draws of member `index` of a zoo with `seed` and `regular` regular
    /// members (members past them only use the generator).
    pub fn new(seed: u64, index: usize, regular: usize) -> Self {
        let mut quantiles = [0.5; DIMS];
        if index < regular {
            let g = plant_group(index);
            let place = (0..index).filter(|&k| plant_group(k) == g).count();
            let size = (0..regular).filter(|&k| plant_group(k) == g).count();
            for (d, q) in quantiles.iter_mut().enumerate() {
                let mut perm: Vec<usize> = (0..size).collect();
                let mut shuffle = ChaCha8Rng::seed_from_u64(seed);
                shuffle.set_stream(1 << 32 | (d as u64) << 8 | g as u64);
                perm.shuffle(&mut shuffle);
                *q = (perm[place] as f64 + 0.5) / size as f64;
            }
        }
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        rng.set_stream(index as u64 + 1);
        Self { quantiles, rng }
    }

    /// Quantile `u_d ∈ (0, 1)` of dimension `d` (before stretching).
    pub fn u(&self, d: Dim) -> f64 {
        self.quantiles[d as usize]
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
    fn every_group_takes_every_quantile_stratum_once_per_dimension() {
        let regular = 210;
        for k in 0..DIMS {
            let d = dim_at(k);
            for g in 0..5 {
                let mut u: Vec<f64> = (0..regular)
                    .filter(|&i| plant_group(i) == g)
                    .map(|i| Draws::new(13, i, regular).u(d))
                    .collect();
                u.sort_by(f64::total_cmp);
                let n = u.len() as f64;
                for (j, v) in u.iter().enumerate() {
                    assert!((v - (j as f64 + 0.5) / n).abs() < 1e-12, "{d:?} group {g}");
                }
                // the stretch puts both ends on the bounds
                assert_eq!(stretch(u[0]), 0.0);
                assert_eq!(stretch(u[u.len() - 1]), 1.0);
            }
        }
    }

    #[test]
    fn the_same_seed_and_index_give_the_same_draws() {
        let mut a = Draws::new(13, 42, 210);
        let mut b = Draws::new(13, 42, 210);
        assert_eq!(a.u(Dim::Kv), b.u(Dim::Kv));
        assert_eq!(a.seed(), b.seed());
        let mut c = Draws::new(13, 43, 210);
        assert_ne!(Draws::new(13, 42, 210).seed(), c.seed());
        // dimensions are paired at random, not in lockstep
        let same = (0..210)
            .filter(|&i| {
                let d = Draws::new(13, i, 210);
                d.u(Dim::Kv) == d.u(Dim::Mass)
            })
            .count();
        assert!(same < 10, "{same}");
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
