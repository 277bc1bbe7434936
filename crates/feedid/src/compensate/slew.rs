//! A command within velocity and acceleration limits that follows a
//! compensated command as closely as the limits let it: where the
//! compensation asks for more than the limits allow (a slow axis whose
//! following error `τ·v` has to be built up at a ramp's corner), the
//! command slews there at the limits and is the compensated one again
//! as soon as it has caught up.
//!
//! The follower is a discrete bounded tracker: at each sample the command
//! moves onto its target when that needs at most the limits,
//!
//! ```text
//! v_k = (c_k − u_{k−1})/Δt,   |v_k| ≤ V,   |v_k − v_{k−1}| ≤ A·Δt,
//! ```
//!
//! else towards it no faster than it can still stop relative to the
//! target (`|v_k − ċ_k| ≤ √(A·|c_k − u_{k−1}|)`, half the acceleration
//! kept for the target's own) and clamped into the limits. Run forwards
//! it lags behind every change the limits cut; run backwards (the time
//! reversal keeps both limits) it leads them. Both runs meet the limits,
//! and so does their mean (the limits are bounds on first and second
//! differences, a convex set), which is centred on each change; a last
//! forward run from the command's own start makes the start exact. A
//! target that meets the limits is followed exactly.
//!
//! This is the offline counterpart of the online compensator's braking
//! ([`super::OnlineCompensator`]); unlike holding the correction back
//! (`super::step`), it keeps the whole correction wherever the limits
//! allow it and gives up only the time it needs to build it.

/// `target` followed within `|Δu|/Δt ≤ vmax` and `|Δ²u|/Δt² ≤ amax`,
/// starting at `target[0]` with velocity `v0` (module doc). Limits must be
/// > 0; the first sample is the target's.
pub(super) fn within_limits(target: &[f64], v0: f64, vmax: f64, amax: f64, dt: f64) -> Vec<f64> {
    let n = target.len();
    if n < 2 {
        return target.to_vec();
    }
    let forward = follow(target, v0, vmax, amax, dt);
    let reversed: Vec<f64> = target.iter().rev().copied().collect();
    let v_end = (target[n - 2] - target[n - 1]) / dt;
    let mut backward = follow(&reversed, v_end, vmax, amax, dt);
    backward.reverse();
    let mean: Vec<f64> = forward
        .iter()
        .zip(&backward)
        .map(|(f, b)| 0.5 * (f + b))
        .collect();
    follow(&mean, v0, vmax, amax, dt)
}

/// The forward tracker (module doc).
fn follow(target: &[f64], v0: f64, vmax: f64, amax: f64, dt: f64) -> Vec<f64> {
    let n = target.len();
    let mut out = Vec::with_capacity(n);
    let mut u = target[0];
    let mut v = v0.clamp(-vmax, vmax);
    out.push(u);
    let dv = amax * dt;
    for k in 1..n {
        let gap = target[k] - u;
        let vc = (target[k] - target[k - 1]) / dt;
        let land = gap / dt;
        let brake = vc + gap.signum() * (amax * gap.abs()).sqrt();
        let want = if gap >= 0.0 {
            land.min(brake.max(vc))
        } else {
            land.max(brake.min(vc))
        };
        // an acceleration step within the limit, then the velocity limit
        // (clamping towards the previous velocity keeps the step within it)
        v = want.clamp(v - dv, v + dv).clamp(-vmax, vmax);
        u += v * dt;
        out.push(u);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn peaks(u: &[f64], v0: f64, dt: f64) -> (f64, f64) {
        let mut vel = vec![v0];
        vel.extend(u.windows(2).map(|w| (w[1] - w[0]) / dt));
        let vmax = vel.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
        let amax = vel
            .windows(2)
            .map(|w| ((w[1] - w[0]) / dt).abs())
            .fold(0.0, f64::max);
        (vmax, amax)
    }

    #[test]
    fn a_target_within_the_limits_is_followed_exactly() {
        let dt = 1e-3;
        let target: Vec<f64> = (0..400)
            .map(|k| {
                let t = k as f64 * dt;
                1e-3 * (1.0 - (2.0 * std::f64::consts::PI * t).cos())
            })
            .collect();
        let u = within_limits(&target, 0.0, 1.0, 100.0, dt);
        let worst = u
            .iter()
            .zip(&target)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        assert!(worst < 1e-15, "{worst}");
    }

    #[test]
    fn a_step_is_slewed_within_both_limits_and_centred_on_it() {
        // a 10 mm step at sample 500 of 1000, limits 0.1 m/s and 2 m/s²
        let dt = 1e-3;
        let target: Vec<f64> = (0..1000)
            .map(|k| if k < 500 { 0.0 } else { 1e-2 })
            .collect();
        let (vmax, amax) = (0.1, 2.0);
        let u = within_limits(&target, 0.0, vmax, amax, dt);
        let (pv, pa) = peaks(&u, 0.0, dt);
        assert!(
            pv <= vmax * (1.0 + 1e-9) && pa <= amax * (1.0 + 1e-9),
            "{pv} {pa}"
        );
        // back on the target well before the end and at rest at the start
        assert_eq!(u[0], 0.0);
        assert!((u[999] - 1e-2).abs() < 1e-12, "{}", u[999]);
        assert!(u[..300].iter().all(|v| v.abs() < 1e-12));
        // centred: half way up around the step; a minimum-time move of
        // 10 mm at these limits takes 0.15 s (the braking keeps half the
        // acceleration in reserve: a little longer)
        let half = u.iter().position(|&v| v >= 5e-3).unwrap();
        assert!((half as i64 - 500).abs() <= 15, "half way at {half}");
        let start = u.iter().position(|&v| v > 1e-9).unwrap();
        assert!((300..425).contains(&start), "starts at {start}");
    }

    #[test]
    fn the_limits_hold_on_random_targets() {
        // seeded: random walks with jumps, any limits
        let mut state = 12345u64;
        let mut rnd = || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((state >> 11) as f64) / ((1u64 << 53) as f64) - 0.5
        };
        for _ in 0..50 {
            let dt = 1e-4 * (1.0 + 10.0 * (rnd() + 0.5));
            let (vmax, amax) = (0.01 + (rnd() + 0.5), 0.1 + 50.0 * (rnd() + 0.5));
            let mut x = 0.0;
            let target: Vec<f64> = (0..500)
                .map(|_| {
                    x += 1e-4 * rnd() + if rnd() > 0.45 { 1e-2 * rnd() } else { 0.0 };
                    x
                })
                .collect();
            let u = within_limits(&target, 0.0, vmax, amax, dt);
            let (pv, pa) = peaks(&u, 0.0, dt);
            assert!(pv <= vmax * (1.0 + 1e-9), "velocity {pv} > {vmax}");
            assert!(pa <= amax * (1.0 + 1e-9), "acceleration {pa} > {amax}");
            assert!(u.iter().all(|v| v.is_finite()));
        }
    }
}
