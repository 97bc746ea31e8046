//! bumpbake: prepares 3D assets for bump and normal mapping.
//!
//! The library does all the work; the `bumpbake` binary only parses arguments and reports.
//! Every subcommand follows `docs/conventions.md` (copied from the project's shared contract).
//!
//! - [`scene`]: the one in-memory model every stage shares: the glTF JSON as read (its shape
//!   checked once, [`scene::shape`]), buffers, a renderer's view of each primitive, materials,
//!   node placement.
//! - [`format`](mod@format): every file format read or written into that model: OBJ, PLY, glTF/GLB (meshopt
//!   and Draco decoded on reading), images and KTX2.
//! - [`bake`], [`inspect`]: the `bake` and `inspect` commands.
//! - [`tangent`]: MikkTSpace tangent frames, fallback frames, vertex split and merge.
//! - [`normalmap`]: height maps to tangent-space normal maps.
//! - [`validate`]: tangent-frame, handedness and normal-map checks.
//! - [`preview`]: a CPU renderer of the reference shading model (`shaders/` in GLSL).
//! - [`transfer`]: high-poly to low-poly normal-map baking (`bake --from`).
//! - [`output`]: atomic writes, so that no failed run leaves a partial file.
//! - [`progress`]: how long work reports its progress; the caller draws it (or not).
//! - [`analytic`]: test meshes with exact answers, for `bumpbake bench` and the tests (feature
//!   `analytic`).

#[cfg(feature = "analytic")]
pub mod analytic;
pub mod bake;
pub mod batch;
pub mod error;
pub mod format;
pub mod inspect;
pub mod normalmap;
pub mod output;
pub mod preview;
pub mod progress;
pub mod scene;
pub mod tangent;
pub mod textures;
pub mod timings;
pub mod transfer;
pub mod validate;

pub use error::{Error, Result};
