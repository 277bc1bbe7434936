//! The drive zoo: a deterministic family of generated recordings of feed
//! drives unlike the paper's rig, to choose defaults on and to benchmark
//! every method against.
//!
//! [`Zoo::standard`] holds 250 members: 210 regular recordings (every one a
//! file `feedid identify` reads), 10 with dropped rows and 30 disturbed
//! ([`Zoo::disturbed`]: force pulses, strong friction, coarse encoders at
//! low rates; readable like the regular ones). Member `i` depends
//! only on the zoo seed, `i` and the zoo's size, so a test or a task can make member `i`
//! alone ([`Zoo::member`]); [`Zoo::members`] makes many in parallel.
//! [`Zoo::small`] is the first 20 (every plant, command and feed-forward kind,
//! two with glitches) for fast tests. Each [`ZooMember`] carries its
//! [`MemberSpec`] (every parameter drawn, a label), the recording (time,
//! command, measured position) and the truth (the noise-free position);
//! [`MemberSpec::run_plant`] runs the same axis on any other command (an
//! identification excitation, a compensated command).
//!
//! # What the zoo spans
//!
//! | quantity | range |
//! |---|---|
//! | plant | the nonlinear virtual rig in three axis classes (heavy, conventional, stiff: 3/4 of the members); first- and second-order servo plants (1/4) |
//! | recording rate | 100 Hz … 20 kHz (log-uniform); the loop runs at up to 20× the recording rate, ≤ 20 kHz, with Kv·Δt ≤ 0.15 |
//! | position-loop gain Kv | 10 … 3000 1/s (rig 10 … 1000: above, no ball-screw axis has the velocity-loop bandwidth; servo plants 10 … 3000) |
//! | feed-forward | none / velocity (kvff 0.8 … 1) / velocity and acceleration (kaff 0.5 … 1, rig), a third each |
//! | moving mass | 0.5 … 500 kg (rig) |
//! | friction | Coulomb + Stribeck, 0 … 10 % of the drive's peak force (rig) |
//! | backlash | 1 … 20 µm on 35 % of the rig members (stiff loops then hunt in a small limit cycle, as real ones do) |
//! | resonance | the axial two-mass mode of each rig member; placed at 20 … 300 Hz on ~30 % |
//! | dead time | 0 … 3 recorded samples (set-point to drive) |
//! | encoder | resolution 1 nm … 20 µm; noise 0 (10 %) or 0.05 … 3 counts |
//! | amplitude | 0.1 mm … 1 m (heavy rig and servos up to 1 m, conventional 0.5 m, stiff 0.2 m; steps and square waves ≤ 2 mm, sweeps ≤ 10 mm) |
//! | commands | ramp, step, S-curve, sine sweep, square wave, random point-to-point moves with dwells, contour axis (circle) |
//! | defects | 1–3 glitches (wild samples, 0.1 … 1000 × the amplitude) on every 12th member; dropped rows on the 10 gapped members |
//! | length | 1000 … 20 000 rows (1–5 s asked; ≤ 60 000 loop samples) |
//! | disturbances (the 30 disturbed members) | force pulses and impacts on the table, 10 … 50 % of the peak force, 1 … 50 ms; Coulomb friction 10 … 25 % of the peak force on reversing commands; encoders of 30 … 1000 counts over the amplitude at 100 Hz … 1 kHz (`disturbance.rs`) |
//!
//! The design (which member gets what) is in `design.rs`, the rig recipe
//! (mechanics, motor, loop tuning, stability checks) in `axis.rs`, the servo
//! plants in `servo.rs`, the commands in `command.rs`, glitches and dropped
//! rows in `defects.rs`, the disturbed members in `disturbance.rs`; a
//! family of drive structures with known physical parameters, for the
//! structure fit, in `structures.rs` ([`StructureAxis`]). No
//! member is chosen or tuned for any identification method: parameters come
//! from the design and the physical recipe only.
//!
//! # Dropped rows
//!
//! The reader refuses a recording whose time column jumps, so members with
//! dropped rows are kept apart (indices [`Zoo::gapped`], after the regular
//! ones), each a copy of a regular member (`gap_source`) with 1–6 rows
//! removed (`dropped_rows`): [`ZooMember::recording`] fails for them as
//! `feedid identify` does, and the regular source shows what the gap costs a
//! method that accepts it.

mod axis;
mod command;
mod defects;
mod design;
mod disturbance;
mod excitation;
mod family;
mod member;
mod plant;
mod servo;
mod spec;
mod structures;

pub use disturbance::{Disturbance, Disturbed};
pub use family::{
    Zoo, MAX_LOOP_RATE, MAX_LOOP_SAMPLES, MAX_ROWS, MIN_ROWS, SMALL_MEMBERS, STANDARD_DISTURBED,
    STANDARD_GAPPED, STANDARD_REGULAR, ZOO_SEED,
};
pub use member::ZooMember;
pub use plant::{PlantRun, PlantStepper};
pub use spec::{
    AxisClass, CommandSpec, Glitch, MemberSpec, PlantKind, RigSetup, ServoSetup, Stability,
};
pub use structures::StructureAxis;
