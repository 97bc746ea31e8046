//! The human printer: the text people read, one [`Human`] impl per record. Reports of work
//! done go to stderr, `inspect`'s text (the command's output) to stdout; `super` decides which.
//! `validate`'s text is in `validate.rs`, beside its other formats.

use super::Human;
use bumpbake::bake::BakeReport;
use bumpbake::inspect::Inspection;
use bumpbake::normalmap::Converted;
use bumpbake::preview::{Compared, Rendered};
use bumpbake::scene::Slot;
use bumpbake::tangent::command::TangentsReport;
use bumpbake::textures::{TexturesReport, TexturesRun};
use bumpbake::transfer::TransferReport;

/// What `tangents` did to one file.
impl Human for TangentsReport {
    fn human(&self) -> String {
        let mut s = format!(
            "{} -> {}: {} primitives got tangents, {} kept theirs, {} skipped\n",
            self.input.display(),
            self.output.display(),
            self.generated,
            self.kept,
            self.skipped
        );
        for p in &self.primitives {
            let at = format!("  mesh {} primitive {}", p.mesh, p.primitive);
            match (&p.stats, &p.reason) {
                (Some(st), _) => {
                    s += &format!(
                        "{at}: TEXCOORD_{} {} tris, vertices {} -> {}",
                        p.uv_set.unwrap_or(0),
                        st.triangles,
                        st.vertices_in,
                        st.vertices_out
                    );
                    if st.fallback.total() > 0 {
                        s += &format!(
                            ", {} fallback frames ({} undefined, {} invalid)",
                            st.fallback.total(),
                            st.fallback.undefined,
                            st.fallback.invalid
                        );
                    }
                    if st.generated_normals {
                        s += ", flat normals generated (NORMAL was missing)";
                    }
                    if let Some(r) = &p.reason {
                        s += &format!("; {r}");
                    }
                    s += "\n";
                }
                (None, Some(r)) => s += &format!("{at}: {}: {r}\n", p.action),
                (None, None) => s += &format!("{at}: {}\n", p.action),
            }
        }
        for n in &self.notes {
            s += &format!("  note: {n}\n");
        }
        if self.written.accessors_dropped > 0 {
            s += &format!(
                "  dropped {} unreferenced accessors, {} buffer views ({} -> {} buffer bytes)\n",
                self.written.accessors_dropped,
                self.written.buffer_views_dropped,
                self.written.buffer_bytes_in,
                self.written.buffer_bytes_out
            );
        }
        let times: Vec<String> = self.timings_ms.stages.iter().map(|(n, ms)| format!("{n} {ms:.1} ms")).collect();
        s += &format!("  time: {}\n", times.join(", "));
        s
    }
}

/// What `bake` did to one file (and `--from`'s transfer).
impl Human for BakeReport {
    fn human(&self) -> String {
        let mut s = format!("{} -> {}\n", self.input.display(), self.output.display());
        for m in &self.maps {
            let from = m.file.as_ref().map(|f| format!(" from {}", f.display())).unwrap_or_default();
            let what = match (&m.name, m.created) {
                (_, true) => "(new: the file had none)".to_string(),
                (Some(n), false) => n.clone(),
                (None, false) => String::new(),
            };
            s += &format!("  material {} {what}: {} map{from}", m.material, m.source);
            if let Some(c) = &m.convention {
                s += &format!(
                    " (looks {} at {:.2}{})",
                    c.detected,
                    c.confidence,
                    if c.converted { ", converted to OpenGL +Y" } else { "" }
                );
            }
            s += "\n";
        }
        let gen = self.primitives.iter().filter(|p| p.action == "generated").count();
        let fb: usize = self.primitives.iter().filter_map(|p| p.stats.as_ref()).map(|s| s.fallback.total()).sum();
        s += &format!("  tangents: {gen} primitives, {fb} fallback frames\n");
        for removal in &self.removed {
            s += &format!("  left out {} ({} bytes)\n", removal.what, removal.bytes);
        }
        if !self.removed.is_empty() {
            s += &format!("  left out {} bytes in all\n", self.removed_bytes);
        }
        for n in &self.notes {
            s += &format!("  note: {n}\n");
        }
        for w in &self.warnings {
            s += &format!("  warning: {w}\n");
        }
        if let Some(tr) = &self.transfer {
            s += &transfer(tr);
        }
        if let Some(t) = &self.textures {
            s += &textures(t);
        }
        let times: Vec<String> = self.timings_ms.stages.iter().map(|(n, ms)| format!("{n} {ms:.1} ms")).collect();
        s += &format!("  time: {}\n", times.join(", "));
        s
    }
}

/// What `bumpbake textures` did to one file.
impl Human for TexturesRun {
    fn human(&self) -> String {
        let mut s = format!("{} -> {}\n", self.input.display(), self.output.display());
        s += &textures(&self.textures);
        let times: Vec<String> = self.timings_ms.stages.iter().map(|(n, ms)| format!("{n} {ms:.1} ms")).collect();
        s += &format!("  time: {}\n", times.join(", "));
        s
    }
}

/// The textures shipped as KTX2, inside bake's and `textures`' text.
fn textures(r: &TexturesReport) -> String {
    let aa = if r.specular_aa { format!(", specular AA (threshold {})", r.threshold) } else { String::new() };
    let fallback = if r.fallback { ", PNG/JPEG fallback kept" } else { "" };
    let mut s = format!("  KTX2 {}{aa}{fallback}: {} normal map(s), {} bytes\n", r.codec, r.normal_maps, r.ktx2_bytes);
    for m in &r.materials {
        let name = m.name.as_deref().map(|n| format!(" '{n}'")).unwrap_or_default();
        s += &format!(
            "  material {}{name}: normal map {}x{}, {} levels, {} bytes\n",
            m.material,
            m.width,
            m.height,
            m.levels.len(),
            m.bytes
        );
        for l in &m.levels {
            let added = m.roughness.as_ref().and_then(|r| r.added.get(l.level));
            let added =
                added.map(|a| format!("  roughness +{:.3} mean, +{:.3} max", a.mean, a.max)).unwrap_or_default();
            s += &format!(
                "    level {:>2} {:>5}x{:<5} mean {:.2}°  p99 {:.2}°  mean length {:.4}{added}\n",
                l.level, l.width, l.height, l.mean_deg, l.p99_deg, l.mean_length
            );
        }
        if let Some(rr) = &m.roughness {
            let from = if rr.from_texture { "its metallicRoughness texture" } else { "its factors" };
            s += &format!(
                "    roughness texture from {from} x roughnessFactor {} (now 1): {} bytes\n",
                rr.roughness_factor, rr.bytes
            );
        }
    }
    for removal in &r.removed {
        s += &format!("  left out {} ({} bytes)\n", removal.what, removal.bytes);
    }
    for n in &r.notes {
        s += &format!("  note: {n}\n");
    }
    s
}

/// What `bake --from` did, inside bake's text.
fn transfer(r: &TransferReport) -> String {
    let c = &r.counts;
    let tris: usize = r.high.iter().map(|h| h.triangles).sum();
    let mut s = format!(
        "  from {} HIGH file(s), {tris} triangles, onto {} LOW triangles: {}x{}, {} sample(s) per texel, rays {:.4} out / {:.4} in\n",
        r.high.len(),
        r.low_triangles,
        r.width,
        r.height,
        r.samples_per_texel,
        r.ray_front,
        r.ray_back
    );
    s += &format!(
        "  texels: {} covered, {} at island borders, {} padded, {} left flat\n",
        c.covered, c.extended, c.padded, c.uncovered
    );
    s += &format!(
        "  rays: {}, {} missed HIGH ({} texels; flat there{})\n",
        c.rays,
        c.missed_rays,
        c.texels_with_misses,
        if c.missed_rays > 0 { ", see --miss-mask" } else { "" }
    );
    if c.overlapping_samples > 0 || c.zero_uv_triangles > 0 {
        s += &format!(
            "  UVs: {} samples in overlapping triangles (first triangle baked), {} triangles without UV area\n",
            c.overlapping_samples, c.zero_uv_triangles
        );
    }
    if c.clamped_below > 0 || c.degenerate_frames > 0 {
        s += &format!(
            "  {} hit normals facing away from LOW (clamped), {} degenerate LOW frames (flat)\n",
            c.clamped_below, c.degenerate_frames
        );
    }
    if let Some([lo, hi]) = r.height_range {
        s += &format!("  HIGH lies {lo:.5} to {hi:.5} from LOW along the rays (world units)\n");
    }
    for p in &r.pairs {
        s += &format!("  parts: {} bake from {} only\n", p.low.join(", "), p.high.join(", "));
    }
    if !r.pairs.is_empty() && (!r.unmatched_low.is_empty() || !r.unmatched_high.is_empty()) {
        s += &format!("  unmatched: LOW {} see HIGH {}\n", list(&r.unmatched_low), list(&r.unmatched_high));
    }
    if r.materials.len() > 1 || r.materials.iter().any(|m| m.parts.len() > 1) {
        for m in &r.materials {
            s += &format!(
                "  material {} {}: {} texels, {} rays, {} missed, HIGH {}\n",
                m.material,
                m.name.as_deref().unwrap_or(""),
                m.counts.covered + m.counts.extended,
                m.counts.rays,
                m.counts.missed_rays,
                range(m.height_range)
            );
            for p in &m.parts {
                s += &format!(
                    "    part {}: {} texels, {} rays, {} missed, HIGH {}\n",
                    p.name,
                    p.texels,
                    p.rays,
                    p.missed_rays,
                    range(p.distance_range)
                );
            }
        }
    }
    s
}

fn range(r: Option<[f32; 2]>) -> String {
    r.map_or_else(|| "no hits".to_string(), |[lo, hi]| format!("{lo:.5} to {hi:.5}"))
}

fn list(v: &[String]) -> String {
    if v.is_empty() {
        "(none)".to_string()
    } else {
        v.join(", ")
    }
}

/// What one file holds (`inspect`: the command's output, on stdout).
impl Human for Inspection {
    fn human(&self) -> String {
        let mut s = format!(
            "{} ({}): {} nodes, {} meshes, {} animations, {} skins\n",
            self.file.display(),
            self.format,
            self.nodes,
            self.meshes,
            self.animations,
            self.skins
        );
        if !self.extensions_used.is_empty() {
            s += &format!("  extensions: {}\n", self.extensions_used.join(", "));
        }
        for p in &self.primitives {
            let attrs: Vec<String> = p.attributes.iter().map(|a| format!("{} {}", a.name, a.r#type)).collect();
            s += &format!(
                "  mesh {} primitive {}: {} vertices, {} {}, material {}\n    attributes: {}\n",
                p.mesh,
                p.primitive,
                p.vertices,
                p.elements,
                p.element,
                p.material.map(|m| m.to_string()).unwrap_or("-".into()),
                attrs.join(", ")
            );
            let by = |uv: &str| p.tangents_needed_by.clone().unwrap_or_else(|| format!("--all reads {uv}"));
            let t = match (&p.tangents_needed_from, p.has_tangents) {
                (Some(uv), true) => format!("present; needed ({})", by(uv)),
                (Some(uv), false) => format!("MISSING; needed ({})", by(uv)),
                (None, true) => format!("present but unused ({})", p.tangents_not_needed.as_deref().unwrap_or("")),
                (None, false) => format!("none; not needed ({})", p.tangents_not_needed.as_deref().unwrap_or("")),
            };
            s += &format!("    tangents: {t}\n");
            for c in &p.tangent_conflicts {
                s += &format!("    note: {c}\n");
            }
            if let Some(e) = &p.error {
                s += &format!("    UNREADABLE: {e}\n");
            }
        }
        for m in &self.materials {
            s += &format!("  material {} {}: ", m.index, m.name.as_deref().unwrap_or(""));
            let mut parts = Vec::new();
            if let Some(i) = m.base_color_image {
                parts.push(format!("base colour image {i}"));
            }
            if let Some(i) = m.normal_image {
                parts.push(format!(
                    "normal image {i} (TEXCOORD_{}, scale {})",
                    m.normal_tex_coord.unwrap_or(0),
                    m.normal_scale.unwrap_or(1.0)
                ));
            }
            if let Some(h) = &m.height_map {
                parts.push(format!("height map {}", h.display()));
            }
            for t in m.textures.iter().filter(|t| !matches!(t.slot, Slot::BaseColor | Slot::Normal)) {
                let img = t.image().map(|i| format!("image {i}")).unwrap_or_else(|| "no image".into());
                parts.push(format!("{:?} {img} (TEXCOORD_{})", t.slot, t.tex_coord));
            }
            if !m.tangents_needed_by.is_empty() {
                parts.push(format!("needs tangents: {}", m.tangents_needed_by.join(", ")));
            }
            s += &(if parts.is_empty() { "no textures".to_string() } else { parts.join(", ") } + "\n");
        }
        for i in &self.images {
            match (&i.error, i.width) {
                (None, Some(w)) => {
                    s += &format!(
                        "  image {}: {}x{} {}{} {}-bit {} ({} bytes, {})\n",
                        i.index,
                        w,
                        i.height.unwrap_or(0),
                        i.format.as_deref().unwrap_or("?"),
                        i.variant.as_ref().map(|v| format!(" ({v})")).unwrap_or_default(),
                        i.bits_per_channel.unwrap_or(0),
                        i.color.as_deref().unwrap_or(""),
                        i.bytes,
                        i.stored
                    )
                }
                (Some(e), _) => s += &format!("  image {}: unreadable: {e}\n", i.index),
                _ => s += &format!("  image {}: {} bytes\n", i.index, i.bytes),
            }
        }
        s
    }
}

/// One height map converted: named only in a batch (one map converted says nothing), any
/// warning, and for KTX2 each level's error.
impl Human for Converted {
    fn human(&self) -> String {
        let mut s =
            if self.batch { format!("{} -> {}\n", self.input.display(), self.output.display()) } else { String::new() };
        for w in &self.warnings {
            s += &format!("bumpbake: warning: {}: {w}\n", self.input.display());
        }
        if let Some(levels) = &self.levels {
            s += &format!(
                "{}: {} mip levels; angle of the stored texels to the averaged full-resolution normals:\n",
                self.output.display(),
                levels.len()
            );
            for l in levels {
                s += &format!(
                    "  level {:>2} {:>5}x{:<5} mean {:.2}°  p99 {:.2}°  mean length {:.4}\n",
                    l.level, l.width, l.height, l.mean_deg, l.p99_deg, l.mean_length
                );
            }
        }
        s
    }
}

/// One picture rendered by `preview`.
impl Human for Rendered {
    fn human(&self) -> String {
        let mut s = format!(
            "preview: {} -> {} ({}x{}, {} view, {} triangles, {:.0} ms)\n",
            self.input.display(),
            self.output.display(),
            self.width,
            self.height,
            self.view,
            self.triangles,
            self.time_ms
        );
        if let Some(why) = &self.camera.flat {
            s += &format!("  camera: {why}\n");
        }
        let t = &self.stages;
        s += &format!(
            "  read {:.0} ms, prepare {:.0} ms, render {:.0} ms, write {:.0} ms\n",
            t.read_ms, t.prepare_ms, t.render_ms, t.write_ms
        );
        for n in &self.notes {
            s += &format!("  note: {n}\n");
        }
        s
    }
}

/// `preview --compare`: how far the candidate's shading is from the reference's.
impl Human for Compared {
    fn human(&self) -> String {
        let c = &self.comparison;
        let mut s = format!(
            "preview: {} vs {} -> {} ({}x{}, {:.0} ms)\n",
            self.reference.display(),
            self.compare.display(),
            self.output.display(),
            c.width,
            c.height,
            self.time_ms
        );
        s += &format!("  pixels compared {}, excluded near silhouettes {}\n", c.pixels_compared, c.pixels_excluded);
        match c.normal_angle_deg {
            Some(a) => {
                s += &format!("  shading-normal angle: mean {:.3}°, p95 {:.3}°, max {:.3}°\n", a.mean, a.p95, a.max)
            }
            None => s += "  shading-normal angle: no pixels to compare\n",
        }
        match c.psnr_db {
            Some(p) => s += &format!("  shaded PSNR {p:.2} dB\n"),
            None => s += "  shaded PSNR: identical\n",
        }
        s
    }
}
