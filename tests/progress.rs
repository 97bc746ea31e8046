//! Progress reaches the caller through `bumpbake::progress`, with totals that add up: a recording
//! `Progress` on an OBJ read, a batch of files, a `bake --from` and a `normalmap` conversion. The
//! library never draws.

use bumpbake::bake::{BakeJob, MapSource};
use bumpbake::batch::{self, BatchOptions};
use bumpbake::progress::{Progress, Reporter};
use bumpbake::scene::ReadOptions;
use bumpbake::transfer::Settings;
use std::path::PathBuf;
use std::sync::{Arc, Mutex};

#[derive(Debug, Clone, PartialEq)]
enum Call {
    Start(String, u64, String),
    Tick(u64),
    Message(String),
    Finish,
}

/// Every call, in order (ticks from worker threads interleave, their sum does not change).
#[derive(Clone, Default)]
struct Recording(Arc<Mutex<Vec<Call>>>);

impl Progress for Recording {
    fn start(&self, stage: &str, total: u64, unit: &str) {
        self.0.lock().unwrap().push(Call::Start(stage.into(), total, unit.into()));
    }
    fn tick(&self, n: u64) {
        self.0.lock().unwrap().push(Call::Tick(n));
    }
    fn message(&self, msg: &str) {
        self.0.lock().unwrap().push(Call::Message(msg.into()));
    }
    fn finish(&self) {
        self.0.lock().unwrap().push(Call::Finish);
    }
}

impl Recording {
    fn calls(&self) -> Vec<Call> {
        self.0.lock().unwrap().clone()
    }

    /// Each stage with its total and the sum of its ticks, checking every stage is finished.
    fn stages(&self) -> Vec<(String, u64, String, u64)> {
        let mut out: Vec<(String, u64, String, u64)> = Vec::new();
        let mut open = false;
        for c in self.calls() {
            match c {
                Call::Start(s, t, u) => {
                    assert!(!open, "a stage starts before the last one finished");
                    out.push((s, t, u, 0));
                    open = true;
                }
                Call::Tick(n) => {
                    assert!(open, "a tick outside a stage");
                    out.last_mut().unwrap().3 += n;
                }
                Call::Message(_) => assert!(open, "a message outside a stage"),
                Call::Finish => {
                    assert!(open, "a finish without a start");
                    open = false;
                }
            }
        }
        assert!(!open, "the last stage is finished");
        out
    }
}

fn fixture(p: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("fixtures").join(p)
}

#[test]
fn obj_read_ticks_every_byte_once() {
    let rec = Recording::default();
    let path = fixture("spot/spot.obj");
    let opts = ReadOptions { progress: Reporter::new(rec.clone()), ..Default::default() };
    bumpbake::format::read(&path, &opts).unwrap();
    let bytes = std::fs::metadata(&path).unwrap().len();
    assert_eq!(rec.stages(), vec![("read spot.obj".to_string(), bytes, "bytes".to_string(), bytes)]);
    assert!(rec.calls().iter().filter(|c| matches!(c, Call::Tick(_))).count() > 1, "ticks as it parses");
}

#[test]
fn glb_read_reports_nothing() {
    // Fast to read whatever its size: nothing to wait for.
    let rec = Recording::default();
    let opts = ReadOptions { progress: Reporter::new(rec.clone()), ..Default::default() };
    bumpbake::format::read(&fixture("khronos/NormalTangentTest.glb"), &opts).unwrap();
    assert_eq!(rec.calls(), vec![]);
}

#[test]
fn batch_ticks_one_file_at_a_time_and_names_it() {
    let rec = Recording::default();
    let inputs: Vec<PathBuf> = ["a", "b", "c"].iter().map(PathBuf::from).collect();
    let opts = BatchOptions { jobs: 2, progress: Reporter::new(rec.clone()) };
    let out = batch::run(&inputs, &opts, |p| Ok(p.to_path_buf())).unwrap();
    assert_eq!(out.len(), 3);
    assert_eq!(rec.stages(), vec![("files".to_string(), 3, "files".to_string(), 3)]);
    let mut named: Vec<String> =
        rec.calls().into_iter().filter_map(|c| if let Call::Message(m) = c { Some(m) } else { None }).collect();
    named.sort();
    assert_eq!(named, ["a", "b", "c"]);
}

#[test]
fn bake_from_reports_both_reads_and_every_row() {
    let rec = Recording::default();
    let progress = Reporter::new(rec.clone());
    let dir = std::env::temp_dir().join(format!("bumpbake-progress-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let low = fixture("bake/torus.obj");
    let read = ReadOptions { progress: progress.clone(), ..Default::default() };
    let settings = Settings {
        highs: vec![low.clone()],
        width: 48,
        height: 40,
        padding: 2,
        read: read.clone(),
        progress,
        ..Default::default()
    };
    let job = BakeJob {
        mesh: low.clone(),
        output: dir.join("torus.glb"),
        map: MapSource::Transfer(Box::new(settings)),
        read,
        ..Default::default()
    };
    let r = bumpbake::bake::run(&job);
    std::fs::remove_dir_all(&dir).ok();
    r.unwrap();
    let bytes = std::fs::metadata(&low).unwrap().len();
    let read_stage = ("read torus.obj".to_string(), bytes, "bytes".to_string(), bytes);
    let rows = (bumpbake::transfer::STAGE.to_string(), 40, "rows".to_string(), 40);
    // LOW, then HIGH, then the rays.
    assert_eq!(rec.stages(), vec![read_stage.clone(), read_stage, rows]);
}

#[test]
fn normalmap_reports_its_rows() {
    use bumpbake::normalmap::{self as nm, Convert, EncodeOptions};
    let dir = std::env::temp_dir().join(format!("bumpbake-progress-normalmap-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let input = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("fixtures/bake/bumps.png");
    let rows = image::image_dimensions(&input).unwrap().1 as u64;
    let rec = Recording::default();
    let progress = Reporter::new(rec.clone());
    for output in ["n.png", "n.exr"] {
        let output = dir.join(output);
        let c = Convert {
            input: input.clone(),
            output: output.clone(),
            channel: Default::default(),
            max_pixels: nm::DEFAULT_MAX_PIXELS,
            options: Default::default(),
            encode: EncodeOptions {
                depth: nm::OutputFormat::from_path(&output).unwrap().depth(&output, None).unwrap(),
                ..Default::default()
            },
            png: Default::default(),
            ktx2: bumpbake::format::image::ktx2::Codec::Uastc { level: nm::DEFAULT_UASTC_LEVEL, rdo: None },
        };
        nm::convert_file(&c, &progress).unwrap();
    }
    std::fs::remove_dir_all(&dir).ok();
    // The streamed PNG and the whole-image EXR count the same rows.
    let stage = (format!("normalmap {}", input.display()), rows, "rows".to_string(), rows);
    assert_eq!(rec.stages(), vec![stage.clone(), stage]);
}

#[test]
fn only_the_command_line_draws() {
    fn walk(dir: &std::path::Path, out: &mut Vec<PathBuf>) {
        for e in std::fs::read_dir(dir).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                walk(&p, out);
            } else if p.extension().is_some_and(|x| x == "rs") {
                out.push(p);
            }
        }
    }
    let src = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut files = Vec::new();
    walk(&src, &mut files);
    let drawing: Vec<String> = files
        .iter()
        .filter(|f| std::fs::read_to_string(f).unwrap().contains("indicatif"))
        .map(|f| f.strip_prefix(&src).unwrap().display().to_string())
        .collect();
    assert_eq!(drawing, ["cli/progress_bars.rs"], "indicatif is used only in src/cli/progress_bars.rs");
}
