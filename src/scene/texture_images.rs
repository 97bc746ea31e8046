//! Which images a texture can show: the image extensions' sources (`KHR_texture_basisu`,
//! `EXT_texture_webp`, ...) before the core `source`, each image once. Whether bumpbake can
//! decode one is the image reader's question (`format::image::texture_image_to_decode`).

use super::refs::IMAGE_SOURCE_EXTENSIONS;
use super::{as_index, Scene};

/// A glTF image a texture may show, and the extension that names it (`None`: the texture's
/// core `source`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct TextureImage {
    pub image: usize,
    pub extension: Option<&'static str>,
}

impl Scene {
    /// Every image texture `texture` can show: the extensions' sources first (a client that
    /// supports one shows it), then the core `source` (the fallback). Each image once.
    pub fn texture_images(&self, texture: usize) -> Vec<TextureImage> {
        let Some(t) = self.json.pointer(&format!("/textures/{texture}")) else { return Vec::new() };
        let mut out: Vec<TextureImage> = Vec::new();
        let from_ext = IMAGE_SOURCE_EXTENSIONS.iter().filter_map(|&ext| {
            let i = t.pointer(&format!("/extensions/{ext}/source")).and_then(as_index)?;
            Some(TextureImage { image: i, extension: Some(ext) })
        });
        let core = t.get("source").and_then(as_index).map(|i| TextureImage { image: i, extension: None });
        for ti in from_ext.chain(core) {
            if !out.iter().any(|o| o.image == ti.image) {
                out.push(ti);
            }
        }
        out
    }
}
