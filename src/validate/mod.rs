//! Tangent-space and handedness checks (issue: validate). Not built yet.
