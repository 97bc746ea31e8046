//! `validate --format sarif`: SARIF 2.1.0, the format GitHub code scanning and most CI dashboards ingest: one result per
//! finding, its rule the check code, located by the file (physical location) and the glTF element
//! inside it (logical location, e.g. `meshes/0/primitives/1`, `images/2`, `nodes/3`).

use bumpbake::validate::{Code, FileReport, Finding, Report, Severity, Subject};
use serde_json::{json, Value};
use std::path::{Component, Path};

/// The schema the log declares (the OASIS errata 01 schema, the one GitHub documents).
pub const SARIF_SCHEMA: &str =
    "https://docs.oasis-open.org/sarif/sarif/v2.1.0/errata01/os/schemas/sarif-schema-2.1.0.json";

/// What each check means, for `tool.driver.rules` (the long form is in docs/validate.md).
fn description(code: Code) -> &'static str {
    use Code::*;
    match code {
        TANGENT_MISSING => "A material's normalTexture needs a tangent space and the primitive has no TANGENT.",
        TEXCOORD_MISSING => "A material texture reads a UV set (texCoord) the primitive does not have.",
        TANGENT_UNUSED => "TANGENT is present but no normal texture reads it.",
        TANGENT_WITHOUT_NORMAL => "TANGENT without NORMAL: clients compute flat normals and must ignore the tangents.",
        TANGENT_NOT_FINITE => "A tangent holds NaN or infinity.",
        TANGENT_NOT_UNIT => "Tangent xyz length differs from 1 by more than the Khronos tolerance (0.00674).",
        TANGENT_W_INVALID => "Tangent w is not exactly +1.0 or -1.0.",
        TANGENT_W_MIXED => "The three corners of a triangle carry different w: the bitangent flips inside it.",
        TANGENT_NOT_ORTHOGONAL => "A tangent is more than 1 degree off the plane orthogonal to its normal.",
        TANGENT_PARALLEL_NORMAL => "A tangent lies within about 8 degrees of its normal: the frame collapses.",
        TANGENT_W_MISMATCH_UV => {
            "Tangent w disagrees with the triangle's orientation in the normal texture's UV space."
        }
        TANGENT_SEAM_SHARED => "One vertex serves triangles of both UV orientations: an unsplit mirror seam.",
        TANGENT_MIKK_ANGLE => "Stored tangents are further from the regenerated MikkTSpace frames than the threshold.",
        TANGENT_MIKK_UNCHECKED => "The comparison with regenerated MikkTSpace frames could not run on this primitive.",
        TANGENT_MIKK_SIGN => "Stored w differs from MikkTSpace's sign on a corner no other check explains.",
        TRIANGLE_DEGENERATE => "A zero-area triangle: no tangent frame exists.",
        TRIANGLE_UV_DEGENERATE => "A triangle with zero area in the normal texture's UV space.",
        TRIANGLE_SLIVER => "A needle triangle (quality below 1e-3) with unstable tangents.",
        NODE_MIRRORED => "A node shows a mesh through a negative-determinant transform (a mirrored instance).",
        NORMAL_NOT_UNIT => "NORMAL values that are zero, not finite, or not unit length.",
        PRIMITIVE_UNREADABLE => "A primitive whose data cannot be read (missing buffer data, index out of range).",
        PRIMITIVE_COMPRESSED => "No longer raised: Draco-compressed primitives are decoded and checked like any other.",
        PRIMITIVE_NOT_CHECKED => "A primitive the checks cannot read (not triangles, no POSITION).",
        NORMALMAP_UNREADABLE => "A material's normal-texture image could not be read or decoded.",
        NORMALMAP_NOT_DECODED => {
            "A normal-map image in a format bumpbake does not decode (AVIF, block-compressed KTX2): not checked."
        }
        NORMALMAP_Z_NEGATIVE => "Normal-map texels decode to z < 0: they point into the surface.",
        NORMALMAP_NOT_UNIT => "Normal-map texels decode to vectors more than 10% off unit length.",
        NORMALMAP_FLAT => "Every texel of the normal map is the flat normal (0, 0, 1), to within 8-bit rounding.",
        NORMALMAP_NEARLY_FLAT => "The largest tilt of any normal-map texel is below 2 degrees: the map barely shows.",
        NORMALMAP_CODEC_NOISE => {
            "Scattered texels of a lossy-coded normal map off unit length, within the codec's error."
        }
        NORMALMAP_GREEN_FLIPPED => "The normal map's green channel follows the other convention than the one expected.",
        NORMALMAP_MIPS_MISSING => {
            "A KTX2 normal map over 256 texels on a side without the mip levels below 256: it aliases when minified."
        }
        NORMALMAP_MIPS_NOT_UNIT => {
            "KTX2 normal-map mip levels whose mean texel length is off 1: filtered without renormalising."
        }
        NORMALMAP_MIPS_DIRECTION => "KTX2 normal-map mip levels whose directions do not follow the level above.",
        ROUGHNESS_MIPS_NOT_WIDENED => {
            "The material's roughness does not carry the normal variance its KTX2 normal map's mips average away."
        }
    }
}

/// SARIF's levels: a finding keeps the severity the JSON report gives it (after `--deny` and
/// `--allow`); whether the run fails is the invocation's exit code.
fn level(sev: Severity) -> &'static str {
    match sev {
        Severity::Error => "error",
        Severity::Warning => "warning",
        Severity::Info => "note",
    }
}

/// A relative path becomes a relative URI reference (so code scanning maps it onto the
/// repository), an absolute one a `file:` URI; bytes outside the unreserved set are escaped.
pub fn uri(path: &Path) -> String {
    let mut parts = Vec::new();
    let mut absolute = false;
    for c in path.components() {
        match c {
            Component::Prefix(p) => parts.push(p.as_os_str().to_string_lossy().into_owned()),
            Component::RootDir => absolute = true,
            Component::CurDir => {}
            Component::ParentDir => parts.push("..".into()),
            Component::Normal(s) => parts.push(s.to_string_lossy().into_owned()),
        }
    }
    let enc: Vec<String> = parts.iter().map(|p| escape(p)).collect();
    let joined = enc.join("/");
    if absolute {
        format!("file:///{joined}")
    } else {
        joined
    }
}

fn escape(s: &str) -> String {
    let mut o = String::with_capacity(s.len());
    for b in s.bytes() {
        if b.is_ascii_alphanumeric() || b"-._~".contains(&b) {
            o.push(b as char);
        } else {
            o += &format!("%{b:02X}");
        }
    }
    o
}

/// Where inside the file a subject is, as glTF JSON paths.
fn logical(sub: &Subject, f: &Finding) -> Vec<String> {
    match (sub.mesh, sub.primitive, sub.image) {
        (Some(m), Some(p), _) => vec![format!("meshes/{m}/primitives/{p}")],
        (_, _, Some(i)) => vec![format!("images/{i}")],
        // The node-transform subject covers the file; its findings name the nodes.
        _ => f.examples.iter().filter(|e| e.kind == "node").map(|e| format!("nodes/{}", e.index)).collect(),
    }
}

fn result(r: &Report, file_index: usize, file: &FileReport, sub: &Subject, f: &Finding) -> Value {
    let rule_index = Code::ALL.iter().position(|c| *c == f.code).unwrap_or(0);
    let paths = logical(sub, f);
    let mut location = json!({
        "physicalLocation": {
            "artifactLocation": { "uri": uri(&file.path), "index": file_index },
            // Code scanning places a result only on a line; the findings are about binary data or
            // the file as a whole, so they point at its first line and the logical location says
            // where inside.
            "region": { "startLine": 1 },
        },
    });
    if !paths.is_empty() {
        let logical =
            paths.iter().map(|p| json!({ "name": sub.name, "fullyQualifiedName": p, "kind": "object" })).collect();
        bumpbake::scene::set_key(&mut location, "logicalLocations", logical);
    }
    let mut text = format!("{}: {}", sub.name, f.message);
    if let Some(e) = f.examples.first() {
        text += &format!(" (e.g. {} {}: {})", e.kind, e.index, e.detail);
    }
    text += &format!(". Fix: {}", f.hint);
    json!({
        "ruleId": f.code.as_str(),
        "ruleIndex": rule_index,
        "level": level(f.severity),
        "message": { "text": text },
        "locations": [location],
        // Stable across runs and independent of line numbers, which the files do not have.
        "partialFingerprints": {
            "bumpbakeSubject/v1": format!("{}|{}", f.code.as_str(), paths.first().map_or(sub.name.as_str(), |p| p)),
        },
        "properties": {
            "subject": sub.name,
            "fails": r.fails(f.severity),
            "count": f.count,
            "total": f.total,
            "unit": f.unit,
            "examples": f.examples,
            "metrics": f.metrics,
        },
    })
}

/// The SARIF log (for stdout). `unusable` holds the message of every input that could not be
/// read; they become error notifications and mark the invocation unsuccessful.
pub fn sarif(r: &Report, unusable: &[String]) -> String {
    let rules: Vec<Value> = Code::ALL
        .iter()
        .map(|&c| {
            json!({
                "id": c.as_str(),
                "shortDescription": { "text": description(c) },
                "help": { "text": c.hint() },
                "defaultConfiguration": { "level": level(c.severity()) },
            })
        })
        .collect();
    let artifacts: Vec<Value> = r.files.iter().map(|f| json!({ "location": { "uri": uri(&f.path) } })).collect();
    let results: Vec<Value> = r
        .files
        .iter()
        .enumerate()
        .flat_map(|(i, file)| file.subjects.iter().flat_map(move |s| s.findings.iter().map(move |f| (i, file, s, f))))
        .map(|(i, file, s, f)| result(r, i, file, s, f))
        .collect();
    let notifications: Vec<Value> =
        unusable.iter().map(|m| json!({ "level": "error", "message": { "text": m } })).collect();
    let exit_code = if unusable.is_empty() { r.exit_code() } else { 2 };
    let v = json!({
        "$schema": SARIF_SCHEMA,
        "version": "2.1.0",
        "runs": [{
            "tool": { "driver": {
                "name": "bumpbake",
                "version": env!("CARGO_PKG_VERSION"),
                "semanticVersion": env!("CARGO_PKG_VERSION"),
                "rules": rules,
            }},
            "invocations": [{
                "executionSuccessful": unusable.is_empty(),
                "exitCode": exit_code,
                "toolExecutionNotifications": notifications,
            }],
            "artifacts": artifacts,
            "results": results,
            "columnKind": "unicodeCodePoints",
        }],
    });
    serde_json::to_string_pretty(&v).unwrap_or_else(|_| "{}".to_string())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn uris_are_escaped_relative_or_file() {
        assert_eq!(uri(Path::new("assets/a b/x#1.glb")), "assets/a%20b/x%231.glb");
        assert_eq!(uri(Path::new("./a.gltf")), "a.gltf");
        assert_eq!(uri(Path::new("../up/é.glb")), "../up/%C3%A9.glb");
        #[cfg(unix)]
        assert_eq!(uri(Path::new("/tmp/m.glb")), "file:///tmp/m.glb");
    }
}
