//! The MikkTSpace engine boundary. Everything above this file sees per-corner frames
//! ([`Frames`]); only this file knows which implementation produced them, so a faster one can
//! replace it.

use super::frames::Frames;
use super::TriMesh;

/// Which implementation computes the reference frames.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Engine {
    /// `bevy_mikktspace`: a safe, byte-identical port of the C reference.
    Bevy,
    /// [`super::fast`]: the same frames bit for bit, in linear time and on all cores.
    #[default]
    Fast,
}

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
    let bevy = |mesh: &TriMesh| {
        Frames::from_flat(mesh.indices, generate_bevy(mesh).into_iter().map(|t| t.unwrap_or([0.0; 4])).collect())
    };
    match engine {
        Engine::Bevy => bevy(mesh),
        Engine::Fast => match super::fast::generate(mesh) {
            Ok(out) => out,
            // Beyond 32-bit corner ids: the reference has no such limit.
            Err(super::fast::Unsupported::TooLarge) => bevy(mesh),
            // An index past an attribute array: no frame is defined (the reference panics).
            Err(super::fast::Unsupported::IndexOutOfRange) => Frames::none(mesh.indices),
        },
    }
}

struct BevyGeometry<'a> {
    mesh: &'a TriMesh<'a>,
    out: Vec<Option<[f32; 4]>>,
}

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

fn generate_bevy(mesh: &TriMesh) -> Vec<Option<[f32; 4]>> {
    let mut g = BevyGeometry { mesh, out: vec![None; mesh.indices.len()] };
    // The error type has no variants: generation cannot fail, it can only leave corners unset.
    let _ = bevy_mikktspace::generate_tangents(&mut g);
    g.out
}
