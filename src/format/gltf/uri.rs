//! Resolving the URIs a glTF or MTL file names: data URIs, and relative files that must stay
//! inside the asset's folder unless the user allows otherwise.

use crate::error::{Error, Result, Setting, Words};
use base64::Engine as _;
use std::path::{Component, Path, PathBuf};

/// What a URI names.
pub enum Target {
    /// Bytes carried in a `data:` URI, with its media type.
    Data { mime: String, bytes: Vec<u8> },
    /// A file on disk.
    File(PathBuf),
}

/// Resolves `uri` against `base_dir`. `source` is the file that names it, for messages.
pub fn resolve(uri: &str, base_dir: &Path, source: &Path, allow_outside: bool) -> Result<Target> {
    if let Some(rest) = uri.strip_prefix("data:") {
        let (meta, payload) = rest
            .split_once(',')
            .ok_or_else(|| Error::input(source, format!("data URI without a comma: {}", short(uri))))?;
        let (mime, is_b64) = match meta.strip_suffix(";base64") {
            Some(m) => (m, true),
            None => (meta, false),
        };
        // RFC 2397 allows the payload percent-encoded as well as in base64.
        let bytes = if is_b64 {
            base64::engine::general_purpose::STANDARD
                .decode(payload.trim())
                .map_err(|e| Error::input(source, format!("data URI is not valid base64 ({e})")))?
        } else {
            percent_decode_bytes(payload)
        };
        let mime = mime.split(';').next().unwrap_or("");
        return Ok(Target::Data { mime: mime.to_string(), bytes });
    }
    if uri.contains("://") {
        return Err(Error::input(
            source,
            format!("URI '{}' is not a local file; only relative paths and data URIs are read", short(uri)),
        ));
    }
    let decoded = percent_decode(uri);
    let rel = Path::new(&decoded);
    if !allow_outside && escapes(rel) {
        let msg = format!("URI '{}' reaches outside the asset's folder (pass ", short(uri));
        return Err(Error::input(source, Words::from(msg).on(Setting::AllowOutside).text(" to permit)")));
    }
    Ok(Target::File(base_dir.join(rel)))
}

/// Reads the bytes a URI names.
pub fn read(uri: &str, base_dir: &Path, source: &Path, allow_outside: bool) -> Result<Vec<u8>> {
    match resolve(uri, base_dir, source, allow_outside)? {
        Target::Data { bytes, .. } => Ok(bytes),
        Target::File(p) => {
            std::fs::read(&p).map_err(|e| Error::input(source, format!("cannot read '{}' ({}): {e}", uri, p.display())))
        }
    }
}

/// True when a relative path is absolute or climbs above its starting folder.
fn escapes(p: &Path) -> bool {
    let mut depth: i64 = 0;
    for c in p.components() {
        match c {
            Component::Prefix(_) | Component::RootDir => return true,
            Component::ParentDir => {
                depth -= 1;
                if depth < 0 {
                    return true;
                }
            }
            Component::Normal(_) => depth += 1,
            Component::CurDir => {}
        }
    }
    false
}

/// The relative path a (percent-encoded) URI names.
pub fn decoded_path(uri: &str) -> PathBuf {
    PathBuf::from(percent_decode(uri))
}

fn percent_decode(s: &str) -> String {
    String::from_utf8_lossy(&percent_decode_bytes(s)).into_owned()
}

fn percent_decode_bytes(s: &str) -> Vec<u8> {
    let b = s.as_bytes();
    let mut out = Vec::with_capacity(b.len());
    let mut i = 0;
    while i < b.len() {
        if b[i] == b'%' && i + 2 < b.len() {
            let hex = |c: u8| (c as char).to_digit(16);
            if let (Some(h), Some(l)) = (hex(b[i + 1]), hex(b[i + 2])) {
                out.push((h * 16 + l) as u8);
                i += 3;
                continue;
            }
        }
        out.push(b[i]);
        i += 1;
    }
    out
}

fn short(uri: &str) -> String {
    if uri.len() > 60 {
        format!("{}...", &uri[..uri.char_indices().nth(57).map(|(i, _)| i).unwrap_or(uri.len())])
    } else {
        uri.to_string()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn escaping_paths_are_caught() {
        assert!(escapes(Path::new("../x.bin")));
        assert!(escapes(Path::new("a/../../x.bin")));
        assert!(escapes(Path::new("/etc/passwd")));
        assert!(!escapes(Path::new("a/../x.bin")));
        assert!(!escapes(Path::new("tex/x.png")));
    }

    #[test]
    fn percent_decoding() {
        assert_eq!(percent_decode("a%20b.png"), "a b.png");
        assert_eq!(percent_decode("100%"), "100%");
        assert_eq!(percent_decode("x%2"), "x%2");
    }
}
