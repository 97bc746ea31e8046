//! CPU reference renderer (issue: preview). Not built yet.
