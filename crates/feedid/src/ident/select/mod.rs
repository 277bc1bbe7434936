//! Choosing the model order and the window: information criteria and FROLS
//! over ARX orders, and sweeps of method × order × window × horizon.

mod order;
mod sweep;

pub use order::{
    frols, order_table, select_order, Criterion, FrolsConfig, FrolsResult, FrolsTerm, OrderRow,
    OrderSearch, OrderSelection, OrderTable, TermKind,
};
pub use sweep::{sweep, SweepConfig, SweepResult, SweepRow, PAPER_WINDOW};
