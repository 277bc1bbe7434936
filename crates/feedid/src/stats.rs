//! Error statistics and information criteria.
