//! Benchmarks behind `bumpbake bench ...`: library code so that tests and the binary share it.

pub mod tangents;
