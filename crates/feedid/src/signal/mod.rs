//! Command trajectories: ramp, step, jerk-limited move, chirp, PRBS, multisine.
