//! The linear model type every method and global fit produces: a discrete
//! transfer function with its sample time (the global fits are in
//! `ident/global.rs`, a layer above the methods).

mod linear;
mod reduce;

pub use linear::LinearModel;
pub use reduce::NEGLIGIBLE_PAIR;
