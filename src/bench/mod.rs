//! Benchmarks that measure error against run time (`bumpbake bench ...`).

pub mod normalmap;
pub mod plot;
pub mod surfaces;
