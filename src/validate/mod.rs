//! `bumpbake validate`: the checks the Khronos glTF-Validator does not make.
//!
//! The Khronos validator accepts any TANGENT that is unit length with `w = ±1`. Files with flipped
//! `w`, rotated or collapsed tangents, shared mirror seams, or normal maps in the wrong convention
//! pass it and still render visibly wrong. This module finds those, per primitive and per image,
//! and says how bad each is (counts, worst offenders, a fix hint) so CI can gate on it.
//!
//! Each check has a stable [`Code`]; `docs/validate.md` lists them with what causes each. A
//! [`Finding`] is reported once, at its root cause: corners already explained by an earlier check
//! (a NaN tangent, a shared mirror seam) are not counted again by the checks after it, so one
//! broken thing gives one finding.
//!
//! Entry points: [`validate_path`] (any input the command line takes), [`validate_scene`] (a
//! scene in memory, e.g. `bake`'s output before it is written), [`validate_normal_image`], and
//! [`normal_image::detect_convention`] for the OpenGL/DirectX green-channel detector.

mod codes;
pub mod conformance;
pub mod frames;
pub mod handedness;
pub mod lossy;
pub mod mip_levels;
pub mod normal_image;
pub mod roughness_levels;
mod scene_checks;

pub use crate::normalmap::Convention;
pub use codes::{Code, Severity};
pub use normal_image::{describe_convention, detect_convention, REPORT_CONFIDENCE};

use crate::error::{Error, Result};
use crate::scene::{ReadOptions, Scene};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// What the caller wants checked and how strictly.
#[derive(Debug, Clone)]
pub struct Options {
    /// Angle between stored and regenerated MikkTSpace tangents above which a corner does not
    /// conform (degrees).
    pub max_angle_deg: f64,
    /// Warnings fail too.
    pub strict: bool,
    /// Checks raised to error severity.
    pub deny: Vec<Code>,
    /// Checks lowered to info severity (still reported, never failing).
    pub allow: Vec<Code>,
    /// The convention normal-map images given directly are expected to follow (glTF materials
    /// always expect OpenGL).
    pub image_convention: Convention,
    pub read: ReadOptions,
}

impl Default for Options {
    fn default() -> Self {
        Options {
            max_angle_deg: 1.0,
            strict: false,
            deny: Vec::new(),
            allow: Vec::new(),
            image_convention: Convention::Opengl,
            read: ReadOptions::default(),
        }
    }
}

/// One offending element, so the user can find it in a DCC tool.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Example {
    /// `vertex`, `triangle`, `corner`, `texel`, `node` or `level` (a KTX2 mip level).
    pub kind: &'static str,
    pub index: u64,
    /// Texel column and row (row 0 at the top), for `texel`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub at: Option<[u32; 2]>,
    pub detail: String,
}

/// One check that did not pass on one subject.
#[derive(Debug, Clone, serde::Serialize)]
pub struct Finding {
    pub code: Code,
    pub severity: Severity,
    /// Offending elements.
    pub count: usize,
    /// Elements checked.
    pub total: usize,
    /// What `count` and `total` count (`vertices`, `corners`, `triangles`, `texels`, ...).
    pub unit: &'static str,
    pub message: String,
    pub hint: String,
    /// Up to [`MAX_EXAMPLES`] worst offenders, worst first.
    pub examples: Vec<Example>,
    /// Figures such as `max_angle_deg`, `p99_angle_deg`, `confidence`.
    pub metrics: BTreeMap<&'static str, f64>,
}

impl Finding {
    pub fn new(code: Code, count: usize, total: usize, unit: &'static str, message: impl Into<String>) -> Self {
        Finding {
            code,
            severity: code.severity(),
            count,
            total,
            unit,
            message: message.into(),
            hint: code.hint().to_string(),
            examples: Vec::new(),
            metrics: BTreeMap::new(),
        }
    }
    pub fn examples(mut self, e: Vec<Example>) -> Self {
        self.examples = e;
        self
    }
    pub fn metric(mut self, k: &'static str, v: f64) -> Self {
        self.metrics.insert(k, v);
        self
    }
    pub fn hint(mut self, h: impl Into<String>) -> Self {
        self.hint = h.into();
        self
    }
}

/// How many worst offenders a finding lists.
pub const MAX_EXAMPLES: usize = 5;

/// Keeps the `MAX_EXAMPLES` worst offenders seen so far, in linear time overall.
#[derive(Debug, Default)]
pub struct Worst {
    items: Vec<(f64, Example)>,
}

impl Worst {
    pub fn push(&mut self, badness: f64, make: impl FnOnce() -> Example) {
        let badness = if badness.is_nan() { f64::INFINITY } else { badness };
        if self.items.len() < MAX_EXAMPLES {
            self.items.push((badness, make()));
        } else if let Some((i, _)) = self.items.iter().enumerate().min_by(|a, b| a.1 .0.total_cmp(&b.1 .0)) {
            if badness > self.items[i].0 {
                self.items[i] = (badness, make());
            }
        }
    }
    pub fn into_examples(mut self) -> Vec<Example> {
        self.items.sort_by(|a, b| b.0.total_cmp(&a.0).then(a.1.index.cmp(&b.1.index)));
        self.items.into_iter().map(|(_, e)| e).collect()
    }
}

/// What was checked: a primitive, a node, an image or the file as a whole.
#[derive(Debug, Clone, serde::Serialize)]
pub struct Subject {
    /// `primitive`, `node`, `image` or `file`.
    pub kind: &'static str,
    /// Human name, e.g. `mesh 0 primitive 1`, `image 2 (normal.png)`.
    pub name: String,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub mesh: Option<usize>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub primitive: Option<usize>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub node: Option<usize>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub image: Option<usize>,
    /// Every check that ran on this subject, passed or not (JUnit lists one testcase each).
    pub checks: Vec<Code>,
    pub findings: Vec<Finding>,
    /// Agreement with regenerated MikkTSpace frames, when it was measured.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub conformance: Option<conformance::Conformance>,
    /// The green-channel detector's verdict, for images.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub convention: Option<normal_image::Detection>,
}

impl Subject {
    pub fn new(kind: &'static str, name: impl Into<String>) -> Self {
        Subject {
            kind,
            name: name.into(),
            mesh: None,
            primitive: None,
            node: None,
            image: None,
            checks: Vec::new(),
            findings: Vec::new(),
            conformance: None,
            convention: None,
        }
    }
    /// Records that `code` ran, and its finding if it failed.
    pub fn check(&mut self, code: Code, finding: Option<Finding>) {
        if !self.checks.contains(&code) {
            self.checks.push(code);
        }
        if let Some(f) = finding {
            self.findings.push(f);
        }
    }
}

/// Everything found in one input file.
#[derive(Debug, Clone, serde::Serialize)]
pub struct FileReport {
    pub path: PathBuf,
    /// `mesh` or `image`.
    pub kind: &'static str,
    pub subjects: Vec<Subject>,
}

/// Everything found in every input.
#[derive(Debug, Clone, serde::Serialize)]
pub struct Report {
    pub files: Vec<FileReport>,
    pub strict: bool,
    pub max_angle_deg: f64,
}

/// Counts of findings by severity.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, serde::Serialize)]
pub struct Summary {
    pub errors: usize,
    pub warnings: usize,
    pub infos: usize,
    pub checks: usize,
}

impl Report {
    pub fn findings(&self) -> impl Iterator<Item = (&FileReport, &Subject, &Finding)> {
        self.files.iter().flat_map(|f| f.subjects.iter().flat_map(move |s| s.findings.iter().map(move |x| (f, s, x))))
    }
    pub fn summary(&self) -> Summary {
        let mut s = Summary::default();
        for (_, _, f) in self.findings() {
            match f.severity {
                Severity::Error => s.errors += 1,
                Severity::Warning => s.warnings += 1,
                Severity::Info => s.infos += 1,
            }
        }
        s.checks = self.files.iter().flat_map(|f| &f.subjects).map(|s| s.checks.len()).sum();
        s
    }
    /// Whether a finding makes the run fail.
    pub fn fails(&self, sev: Severity) -> bool {
        sev == Severity::Error || (self.strict && sev == Severity::Warning)
    }
    /// The exit code the conventions give this outcome: 1 when anything fails, else 0.
    pub fn exit_code(&self) -> u8 {
        if self.findings().any(|(_, _, f)| self.fails(f.severity)) {
            1
        } else {
            0
        }
    }
}

/// Validates every input in order; the first unusable one stops the run (exit 2).
pub fn validate_paths(paths: &[PathBuf], opts: &Options) -> Result<Report> {
    let mut files = Vec::with_capacity(paths.len());
    for p in paths {
        files.push(validate_path(p, opts)?);
    }
    Ok(Report { files, strict: opts.strict, max_angle_deg: opts.max_angle_deg })
}

/// Validates many inputs, `jobs` at a time (0: one per core); an unusable file never stops the
/// others: it is returned with its error, and the report holds every file that could be read.
pub fn validate_many(paths: &[PathBuf], opts: &Options, jobs: usize) -> Result<(Report, Vec<Error>)> {
    let batch = crate::batch::BatchOptions { jobs, ..Default::default() };
    let results = crate::batch::run(paths, &batch, |p| validate_path(p, opts))?;
    let mut files = Vec::with_capacity(paths.len());
    let mut failed = Vec::new();
    for r in results {
        match r {
            Ok(f) => files.push(f),
            Err(e) => failed.push(e),
        }
    }
    Ok((Report { files, strict: opts.strict, max_angle_deg: opts.max_angle_deg }, failed))
}

/// Validates one `.gltf`, `.glb`, `.obj`, or a normal-map image.
pub fn validate_path(path: &Path, opts: &Options) -> Result<FileReport> {
    let ext = path.extension().and_then(|e| e.to_str()).unwrap_or("").to_ascii_lowercase();
    let bytes = std::fs::read(path).map_err(|e| Error::input(path, format!("cannot read: {e}")))?;
    // GLB is known by its magic whatever the name, as `format::read` does.
    let mesh = matches!(ext.as_str(), "gltf" | "glb" | "obj") || bytes.starts_with(b"glTF");
    let mut rep = if mesh {
        drop(bytes);
        let scene = crate::format::read(path, &opts.read)?;
        FileReport { path: path.to_path_buf(), kind: "mesh", subjects: validate_scene(&scene, opts)? }
    } else {
        use crate::format::image::{self as img, Kind};
        let limits = img::Limits::file(crate::normalmap::DEFAULT_MAX_PIXELS);
        // A KTX2 carries its own chain: decoded once, level 0 gets the image checks and the
        // levels get the checks a material's KTX2 gets.
        let chain = (Kind::sniff(&bytes) == Kind::Ktx2).then(|| img::ktx2::decode_levels_within(&bytes, &limits));
        let decoded;
        let level0 = match &chain {
            Some(Ok(imgs)) => &imgs[0],
            _ => {
                decoded = img::decode_within(&bytes, &limits).map_err(|e| match Kind::sniff(&bytes) {
                    Kind::Unknown => Error::input(
                        path,
                        format!("neither a mesh (.gltf, .glb, .obj) nor an image bumpbake reads ({})", img::DECODED),
                    ),
                    _ => Error::in_file(path, e),
                })?;
                &decoded
            }
        };
        let name = path.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
        let mut subject = Subject::new("image", name);
        let codec = lossy::Codec::sniff(&bytes);
        validate_normal_image(level0, codec, opts.image_convention, "the command line", &mut subject);
        match &chain {
            Some(Ok(imgs)) => mip_levels::check(&mip_levels::levels(imgs), codec, &mut subject),
            Some(Err(e)) => {
                let why = format!("mip levels not checked: {e}");
                let f = Finding::new(Code::NORMALMAP_UNREADABLE, 1, 1, "images", why);
                subject.check(Code::NORMALMAP_UNREADABLE, Some(f));
            }
            None => {}
        }
        FileReport { path: path.to_path_buf(), kind: "image", subjects: vec![subject] }
    };
    apply_policy(&mut rep, opts);
    Ok(rep)
}

/// Validates a scene in memory: every primitive, every node transform, every normal-map image.
/// Severities are the defaults; [`apply_policy`] applies `--deny`/`--allow`.
pub fn validate_scene(scene: &Scene, opts: &Options) -> Result<Vec<Subject>> {
    scene_checks::run(scene, opts)
}

/// Checks a decoded normal-map image: z < 0, non-unit texels (judged by how its bytes were
/// coded: `lossy::Codec::sniff`), (nearly) flat, and its green-channel convention against
/// `expected` (`wanted_by` names who expects it, for the message).
pub fn validate_normal_image(
    img: &image::DynamicImage,
    codec: lossy::Codec,
    expected: Convention,
    wanted_by: &str,
    subject: &mut Subject,
) {
    normal_image::check(img, codec, expected, wanted_by, subject)
}

/// Moves single checks up (`deny`) or down (`allow`) in severity.
pub fn apply_policy(rep: &mut FileReport, opts: &Options) {
    for f in rep.subjects.iter_mut().flat_map(|s| s.findings.iter_mut()) {
        if opts.deny.contains(&f.code) {
            f.severity = Severity::Error;
        } else if opts.allow.contains(&f.code) {
            f.severity = Severity::Info;
        }
    }
}
