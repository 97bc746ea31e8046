//! The shared in-memory model (not built yet).
