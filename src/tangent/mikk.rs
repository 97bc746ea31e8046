//! The MikkTSpace engine boundary. Everything above this file sees per-corner frames
//! ([`Frames`]); only this file knows which implementation produced them, so a faster one can
//! replace it.

use super::frames::Frames;
use super::TriMesh;

/// Which implementation computes the reference frames.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Engine {
    /// `bevy_mikktspace`: a safe, byte-identical port of the C reference. Only with the
    /// `reference` feature ([`REFERENCE_BUILT_IN`]).
    Bevy,
    /// [`super::fast`]: the same frames bit for bit, in linear time and on all cores.
    #[default]
    Fast,
}

/// Whether [`Engine::Bevy`] is built in (the `reference` feature).
pub const REFERENCE_BUILT_IN: bool = cfg!(feature = "reference");

/// Per-corner MikkTSpace frames `(t.x, t.y, t.z, sign)` in the reference's own sign convention
/// (`sign = +1` when the UV orientation is preserved), or `None` where the reference gives no
/// answer (a degenerate triangle with no neighbour to borrow from).
pub fn generate(mesh: &TriMesh, engine: Engine) -> Vec<Option<[f32; 4]>> {
    frames(mesh, engine).into_iter().map(|t| (t[3] != 0.0).then_some(t)).collect()
}

/// [`generate`] as flat frames, `[0.0; 4]` (`w == 0`) where it gives `None`.
pub fn frames(mesh: &TriMesh, engine: Engine) -> Vec<[f32; 4]> {
    compact(mesh, engine).to_flat(mesh.indices)
}

/// [`generate`] as [`Frames`]: each value once per group of corners the engine shares it among
/// (the fast engine), or once per corner (the reference), found through `mesh.indices`.
pub fn compact(mesh: &TriMesh, engine: Engine) -> Frames {
    match engine {
        Engine::Bevy => reference(mesh),
        Engine::Fast => match super::fast::generate(mesh) {
            Ok(out) => out,
            // An index past an attribute array: no frame is defined (the reference panics).
            // Beyond 32-bit corner ids (1.4 billion triangles, more than memory holds): no
            // frames, so every corner gets a substitute, counted in the report.
            Err(super::fast::Unsupported::IndexOutOfRange | super::fast::Unsupported::TooLarge) => {
                Frames::none(mesh.indices)
            }
        },
    }
}

#[cfg(feature = "reference")]
fn reference(mesh: &TriMesh) -> Frames {
    Frames::from_flat(mesh.indices, generate_bevy(mesh).into_iter().map(|t| t.unwrap_or([0.0; 4])).collect())
}

/// Callers check [`REFERENCE_BUILT_IN`] first (the command line refuses the engine without it).
#[cfg(not(feature = "reference"))]
fn reference(_mesh: &TriMesh) -> Frames {
    panic!("the reference engine (bevy_mikktspace) is not built in: build bumpbake with its `reference` feature")
}

#[cfg(feature = "reference")]
struct BevyGeometry<'a> {
    mesh: &'a TriMesh<'a>,
    out: Vec<Option<[f32; 4]>>,
}

#[cfg(feature = "reference")]
impl bevy_mikktspace::Geometry for BevyGeometry<'_> {
    fn num_faces(&self) -> usize {
        self.mesh.indices.len() / 3
    }
    fn num_vertices_of_face(&self, _face: usize) -> usize {
        3
    }
    fn position(&self, face: usize, vert: usize) -> [f32; 3] {
        self.mesh.positions[self.mesh.indices[face * 3 + vert] as usize]
    }
    fn normal(&self, face: usize, vert: usize) -> [f32; 3] {
        self.mesh.normals[self.mesh.indices[face * 3 + vert] as usize]
    }
    fn tex_coord(&self, face: usize, vert: usize) -> [f32; 2] {
        self.mesh.uvs[self.mesh.indices[face * 3 + vert] as usize]
    }
    fn set_tangent(&mut self, ts: Option<bevy_mikktspace::TangentSpace>, face: usize, vert: usize) {
        self.out[face * 3 + vert] = ts.map(|t| t.tangent_encoded());
    }
}

#[cfg(feature = "reference")]
fn generate_bevy(mesh: &TriMesh) -> Vec<Option<[f32; 4]>> {
    let mut g = BevyGeometry { mesh, out: vec![None; mesh.indices.len()] };
    // The error type has no variants: generation cannot fail, it can only leave corners unset.
    let _ = bevy_mikktspace::generate_tangents(&mut g);
    g.out
}
