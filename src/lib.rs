//! bumpbake: prepares 3D assets for bump and normal mapping.
//!
//! The library does all the work; the `bumpbake` binary only parses arguments and reports.
//! Every subcommand follows `docs/conventions.md` (copied from the project's shared contract).
//!
//! Layers, from the bottom (`docs/architecture.md`; `tests/layering.rs` holds them):
//!
//! - base: [`error`] (the one error type), [`output`] (atomic writes, so that no failed run
//!   leaves a partial file), [`progress`] (how long work reports its progress; the caller draws
//!   it, or not), [`batch`] (one job over many inputs, in parallel, results in input order),
//!   [`timings`] (stage timings every report carries, and memory marks when asked).
//! - model: [`scene`], the one in-memory model every stage shares: the glTF JSON as read (its
//!   shape checked once, [`scene::shape`]), buffers, a renderer's view of each primitive,
//!   materials, node placement.
//! - formats: [`format`](mod@format), every file format read or written into that model, a folder
//!   each: glTF/GLB (meshopt and Draco decoded on reading), OBJ, PLY, images and KTX2;
//!   [`format::read`] and [`format::write`].
//! - engines: [`tangent`] (MikkTSpace tangent frames, fallback frames, vertex split and merge),
//!   [`normalmap`] (height maps to tangent-space normal maps).
//! - pipelines, one per command, each a library call returning a report: [`tangent::command`]
//!   (`tangents`), [`bake`], [`transfer`] (high-poly to low-poly baking, `bake --from`),
//!   [`validate`] (tangent-frame, handedness and normal-map checks), [`preview`] (a CPU renderer
//!   of the reference shading model, `shaders/` in GLSL), [`textures`] (normal textures as KTX2,
//!   with specular antialiasing), [`inspect`]; and [`analytic`], test meshes with exact answers
//!   for `bumpbake bench` and the tests (feature `analytic`).

#[cfg(feature = "analytic")]
pub mod analytic;
pub mod bake;
pub mod batch;
pub mod error;
pub mod format;
pub mod inspect;
pub mod normalmap;
pub mod output;
pub(crate) mod pages;
pub mod preview;
pub mod progress;
pub(crate) mod scan;
pub mod scene;
pub mod tangent;
pub mod textures;
pub mod timings;
pub mod transfer;
pub mod validate;

#[cfg(test)]
mod test_rng;

pub use error::{Error, Result};
