//! Tangent frames: MikkTSpace generation ([`mikk`]), the fallback for corners the reference
//! leaves undefined ([`fallback`]), and the split/merge of vertices that follows ([`split`]).

pub mod fast;
pub mod mikk;

/// An indexed triangle list as MikkTSpace sees it: one normal and one UV per vertex.
#[derive(Debug, Clone, Copy)]
pub struct TriMesh<'a> {
    pub positions: &'a [[f32; 3]],
    pub normals: &'a [[f32; 3]],
    pub uvs: &'a [[f32; 2]],
    /// Three indices per triangle, each `< positions.len()`.
    pub indices: &'a [u32],
}
