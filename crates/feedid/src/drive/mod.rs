//! The physical feed-drive model: rig parameters (paper eq. 1–2), the
//! closed-loop transfer function Xa/Xs (2nd over 7th order), the same cascade
//! as a 7-state state-space model, and the nonlinear virtual rig.

mod params;
mod rig;

pub use params::{
    equivalent_stiffness, screw_inertia, screw_stiffness, total_inertia, Control, Damping,
    Geometry, Inertia, Material, Motor, RigParams, Stiffness, Table,
};
pub use rig::{Friction, PositionLoop, RigEffects, RigOutput, VirtualRig, DEFAULT_MAX_STEP};
