//! Height maps to tangent-space normal maps (issue: normalmap). Not built yet.
