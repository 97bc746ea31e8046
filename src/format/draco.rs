//! KHR_draco_mesh_compression: bumpbake has no Draco decoder (see docs/dependencies.md for why).
//! A Draco primitive's accessors hold no data of their own, so reading one is an error that says
//! how to get an uncompressed file; primitives nothing reads pass through the writer untouched.

use crate::scene::{PrimRef, Scene};

pub const EXT: &str = "KHR_draco_mesh_compression";

/// What to run to get a file bumpbake can read. glTF-Transform decodes Draco on reading and its
/// `copy` writes the result uncompressed (checked with `@gltf-transform/cli` 4.5.1; gltfpack 1.3
/// cannot read Draco at all).
pub const WAY_OUT: &str =
    "decode it first with `npx @gltf-transform/cli copy IN.glb OUT.glb`, which writes it uncompressed";

/// Why the primitive's geometry cannot be read, if it is Draco-compressed.
pub fn why_unreadable(scene: &Scene, r: PrimRef) -> Option<String> {
    scene.prim_json(r).pointer("/extensions/KHR_draco_mesh_compression")?;
    Some(format!(
        "mesh {} primitive {} is compressed with {EXT}, which bumpbake cannot decode; {WAY_OUT}",
        r.mesh, r.primitive
    ))
}
