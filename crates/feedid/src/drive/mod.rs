//! The physical feed-drive model: rig parameters (paper eq. 1–2), the
//! closed-loop transfer function Xa/Xs (2nd over 7th order), the same cascade
//! as a 7-state state-space model, and the nonlinear virtual rig.

mod closed_loop;
mod nominal;
mod params;
mod rig;
mod stability;
mod structure;
mod summary;

pub use closed_loop::{
    closed_loop_coefficients, closed_loop_coefficients_with_stiffness, closed_loop_state_space,
    closed_loop_state_space_with_stiffness, reference_inputs, ClosedLoopCoefficients, D1Variant,
};
pub use nominal::{simulate_nominal, simulate_nominal_recording};
pub use params::{
    equivalent_stiffness, screw_inertia, screw_stiffness, total_inertia, Control, Damping,
    Geometry, Inertia, Material, Motor, RigParams, Stiffness, Table,
};
pub use rig::{
    ForcePulses, Friction, PositionLoop, RigEffects, RigOutput, RigStepper, VirtualRig,
    DEFAULT_MAX_STEP,
};
pub use stability::{check_model, require_stable, ModelCheck};
pub use structure::{
    check_restarts, inverse_dynamics, Controller, CurrentLoop, Drive, DriveStructure, FeedForward,
    FrictionLaw, IdimConfig, IdimFit, LoopGains, LoopKind, Measured, Mechanics, RunFigures,
    StructureEstimate, StructureFit, StructureParam, StructureRun, StructureSummary,
    StructureValidation, StructureVerdict, TuneTarget, Tuned, VelocityEstimate, EQUALLY_GOOD,
    MAX_RESTARTS, PINNED,
};
pub use summary::{bandwidth_hz, ModelSummary, PoleInfo};
