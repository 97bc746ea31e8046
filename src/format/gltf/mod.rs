//! glTF 2.0, `.gltf` and `.glb`: the reader (with meshopt and Draco decoded right after parsing,
//! into plain accessors), the writer, and the URIs both resolve inside the input's folder.

pub mod draco;
mod meshopt;
pub(super) mod read;
pub mod uri;
mod write;

pub use write::{write, WriteOptions, WriteStats};
