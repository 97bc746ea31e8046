//! Benchmarks that measure error against run time (`bumpbake bench ...`): library code so that
//! tests and the binary share it.

pub mod batch;
pub mod command;
pub mod normalmap;
pub mod plot;
pub mod surfaces;
pub mod tangents;
pub mod tangents_plot;
pub mod transfer;
