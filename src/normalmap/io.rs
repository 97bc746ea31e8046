//! Files in and out. Inputs are refused on their header's size before any pixel buffer is
//! allocated; outputs are written whole or not at all ([`crate::output::write_atomic`]).

use super::ktx2::LevelError;
use super::{encode_normals, height_from_image, Channel, Depth, EncodeOptions, HeightPlane, NormalData, NormalImage};
use super::{Convention, NormalPlane, Options};
use crate::error::{Error, Result, Setting, Words};
use crate::progress::Reporter;
use crate::timings::Timings;
use image::{DynamicImage, ExtendedColorType, ImageEncoder};
use std::io::Cursor;
use std::path::{Path, PathBuf};

/// 16384 x 16384: the largest texture most GPUs take.
pub const DEFAULT_MAX_PIXELS: u64 = 268_435_456;

/// One line, however the decoder formats its error.
fn one_line(e: impl std::fmt::Display) -> String {
    e.to_string().split_whitespace().collect::<Vec<_>>().join(" ")
}

/// Opens and decodes an image (any format [`crate::format::image`] reads), refusing it first if its
/// header claims more than `max_pixels`.
pub fn open_image(path: &Path, max_pixels: u64) -> Result<DynamicImage> {
    crate::format::image::read_file(path, max_pixels)
}

/// Reads a height map: PNG (8/16-bit gray, gray+alpha, RGB, RGBA, palette), JPEG, WebP, TIFF, or
/// EXR.
pub fn load_height(path: &Path, channel: Channel, max_pixels: u64) -> Result<HeightPlane> {
    if crate::format::image::file_is_png(path) {
        if let Some(plane) = load_png_height(path, channel, max_pixels)? {
            return Ok(plane);
        }
    }
    let img = open_image(path, max_pixels)?;
    height_from_image(&img, channel).map_err(|m| Error::in_file(path, m))
}

/// PNG rows straight into the height plane, as they are inflated: no decoded image in between
/// (a 16-bit 4096² map would be 32 MB more) and no separate conversion pass. `None` for
/// interlaced files, which the general path handles.
fn load_png_height(path: &Path, channel: Channel, max_pixels: u64) -> Result<Option<HeightPlane>> {
    let bad = |e: png::DecodingError| Error::input(path, format!("cannot decode as PNG: {}", one_line(e)));
    let file = std::fs::File::open(path).map_err(|e| Error::input(path, format!("cannot open: {}", one_line(e))))?;
    let mut decoder = png::Decoder::new(std::io::BufReader::with_capacity(1 << 16, file));
    decoder.set_transformations(png::Transformations::EXPAND);
    decoder.set_limits(png::Limits { bytes: usize::MAX });
    let mut reader = decoder.read_info().map_err(bad)?;
    check_png_complete(path)?;
    let (w, h) = (reader.info().width, reader.info().height);
    check_size(path, w, h, max_pixels)?;
    if reader.info().interlaced {
        return Ok(None);
    }
    let (color, depth) = reader.output_color_type();
    let ch = color.samples();
    let has_alpha = matches!(color, png::ColorType::GrayscaleAlpha | png::ColorType::Rgba);
    let is_colour = matches!(color, png::ColorType::Rgb | png::ColorType::Rgba);
    let pick = super::height::pick(channel, ch, has_alpha, is_colour).map_err(|m| Error::in_file(path, m))?;
    let (w, h) = (w as usize, h as usize);
    let mut data = vec![0.0f32; w * h];
    // Inflating is sequential; converting rows to heights is not. One thread inflates batches of
    // rows while this one converts the previous batch, so conversion costs no wall time.
    const BATCH: usize = 64;
    let convert = |raw: &[u8], out: &mut [f32]| match depth {
        png::BitDepth::Sixteen => super::height::convert_row_be16(raw, ch, pick, out),
        _ => super::height::convert_row(raw, ch, pick, |v| v as f32 / 255.0, out),
    };
    std::thread::scope(|scope| -> Result<()> {
        let (tx, rx) = std::sync::mpsc::sync_channel::<Result<(usize, Vec<u8>)>>(4);
        scope.spawn(move || {
            let mut row_len = 0;
            for y0 in (0..h).step_by(BATCH) {
                let mut buf = Vec::new();
                for _ in y0..(y0 + BATCH).min(h) {
                    match reader.next_row() {
                        Ok(Some(row)) => {
                            row_len = row.data().len();
                            buf.extend_from_slice(row.data());
                        }
                        Ok(None) => {
                            let _ = tx.send(Err(Error::input(path, "cannot decode as PNG: rows missing")));
                            return;
                        }
                        Err(e) => {
                            let _ = tx.send(Err(bad(e)));
                            return;
                        }
                    }
                }
                if tx.send(Ok((row_len, buf))).is_err() {
                    return;
                }
            }
            // The rows can all be there while the compressed stream's checksum is not.
            if let Err(e) = reader.finish() {
                let _ = tx.send(Err(bad(e)));
            }
        });
        for (rows, batch) in data.chunks_mut(w * BATCH).zip(rx.iter()) {
            let (row_len, raw) = batch?;
            for (out, r) in rows.chunks_exact_mut(w).zip(raw.chunks_exact(row_len.max(1))) {
                convert(r, out);
            }
        }
        match rx.recv() {
            Ok(Err(e)) => Err(e),
            _ => Ok(()),
        }
    })?;
    Ok(Some(HeightPlane { width: w, height: h, data }))
}

/// Refuses a PNG whose chunks stop before `IEND`: a truncated file (an unfinished copy, most
/// often) can still yield rows, and must not become a map. Only chunk headers are read.
fn check_png_complete(path: &Path) -> Result<()> {
    use std::io::{Read, Seek, SeekFrom};
    let truncated = || {
        Error::input(
            path,
            "cannot decode as PNG: the file is truncated (it ends before its IEND chunk); is the copy unfinished?",
        )
    };
    let mut f = std::fs::File::open(path).map_err(|e| Error::input(path, format!("cannot open: {}", one_line(e))))?;
    let size = f.metadata().map(|m| m.len()).unwrap_or(u64::MAX);
    let mut at = 8u64;
    let mut header = [0u8; 8];
    loop {
        if at.checked_add(12).is_none_or(|end| end > size) {
            return Err(truncated());
        }
        f.seek(SeekFrom::Start(at)).and_then(|_| f.read_exact(&mut header)).map_err(|_| truncated())?;
        let len = u32::from_be_bytes([header[0], header[1], header[2], header[3]]) as u64;
        if &header[4..8] == b"IEND" {
            return Ok(());
        }
        at = at + 12 + len;
    }
}

fn check_size(path: &Path, w: u32, h: u32, max_pixels: u64) -> Result<()> {
    crate::format::image::check_size_within(w, h, &crate::format::image::Limits::file(max_pixels))
        .map_err(|m| Error::in_file(path, m))
}

/// Reads an encoded normal map (RGB or RGBA; 8-bit, 16-bit or float) without decoding texels.
pub fn load_normal_image(path: &Path, max_pixels: u64) -> Result<NormalImage> {
    let img = open_image(path, max_pixels)?;
    let (width, height) = (img.width() as usize, img.height() as usize);
    let (channels, data) = match img {
        DynamicImage::ImageRgb8(b) => (3, NormalData::U8(b.into_raw())),
        DynamicImage::ImageRgba8(b) => (4, NormalData::U8(b.into_raw())),
        DynamicImage::ImageRgb16(b) => (3, NormalData::U16(b.into_raw())),
        DynamicImage::ImageRgba16(b) => (4, NormalData::U16(b.into_raw())),
        DynamicImage::ImageRgb32F(b) => (3, NormalData::F32(b.into_raw())),
        DynamicImage::ImageRgba32F(b) => (4, NormalData::F32(b.into_raw())),
        other => {
            return Err(Error::input(
                path,
                format!("a normal map must be RGB or RGBA, this is {}", colour_words(other.color())),
            ))
        }
    };
    Ok(NormalImage { width, height, channels, data })
}

/// A colour type in words: "grey 8-bit", "grey+alpha 16-bit", "RGB float".
pub fn colour_words(c: image::ColorType) -> String {
    let kind = match c.channel_count() {
        1 => "grey",
        2 => "grey+alpha",
        3 => "RGB",
        _ => "RGBA",
    };
    if matches!(c, image::ColorType::Rgb32F | image::ColorType::Rgba32F) {
        return format!("{kind} float");
    }
    format!("{kind} {}-bit", c.bits_per_pixel() / c.channel_count() as u16)
}

/// Reads a normal map and decodes it to vectors (`n = 2·texel - 1`, OpenGL convention,
/// not renormalised). `convention` is the one the file was written in.
pub fn decode_normal_image(path: &Path, convention: Convention, max_pixels: u64) -> Result<NormalPlane> {
    Ok(load_normal_image(path, max_pixels)?.decode(convention))
}

/// What an output file name asks for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum OutputFormat {
    Png,
    Tiff,
    Exr,
    /// Basis Universal in KTX2, with a full mip chain.
    Ktx2,
}

impl OutputFormat {
    pub fn from_path(path: &Path) -> Result<OutputFormat> {
        let ext = path.extension().map(|e| e.to_string_lossy().to_ascii_lowercase()).unwrap_or_default();
        match ext.as_str() {
            "png" => Ok(OutputFormat::Png),
            "tif" | "tiff" => Ok(OutputFormat::Tiff),
            "exr" => Ok(OutputFormat::Exr),
            "ktx2" => Ok(OutputFormat::Ktx2),
            _ => Err(Error::usage(format!(
                "{}: unsupported output format: name it .png, .tif, .exr or .ktx2",
                path.display()
            ))),
        }
    }
    /// The sample depth for `--bits` (None: the format's default).
    pub fn depth(self, path: &Path, bits: Option<u8>) -> Result<Depth> {
        match (self, bits) {
            (OutputFormat::Exr, None) => Ok(Depth::Float),
            (OutputFormat::Exr, Some(b)) => {
                let msg = Words::from(format!("{}: EXR output is 32-bit float; ", path.display())).name(Setting::Bits);
                Err(Error::setting(Setting::Bits, Some(b.to_string()), msg.text(" is for PNG and TIFF")))
            }
            (OutputFormat::Ktx2, Some(16)) => {
                let msg = format!("{}: KTX2 output is 8-bit Basis Universal; ", path.display());
                let msg = Words::from(msg).given(Setting::Bits, 16).text(" is for PNG and TIFF");
                Err(Error::setting(Setting::Bits, Some("16".into()), msg))
            }
            (_, None | Some(8)) => Ok(Depth::Bits8),
            (_, Some(16)) => Ok(Depth::Bits16),
            (_, Some(b)) => {
                let msg = Words::new().given(Setting::Bits, b).text(": use 8 or 16");
                Err(Error::setting(Setting::Bits, Some(b.to_string()), msg))
            }
        }
    }
}

/// PNG writer settings. Fast deflate with the `Up` filter was measured fastest for normal maps
/// at a size within a few percent of adaptive filtering (see `docs/normalmap.md`).
#[derive(Clone, Copy, Debug)]
pub struct PngSettings {
    pub compression: png::Compression,
    pub filter: png::Filter,
}

impl Default for PngSettings {
    fn default() -> Self {
        PngSettings { compression: png::Compression::Fast, filter: png::Filter::Up }
    }
}

/// PNG bytes of a normal map (8- or 16-bit RGB/RGBA). Float maps cannot be PNG.
pub fn png_bytes(img: &NormalImage, settings: PngSettings) -> crate::error::Faulty<Vec<u8>> {
    let mut out = Vec::new();
    let mut enc = png::Encoder::new(&mut out, img.width as u32, img.height as u32);
    enc.set_color(if img.channels == 4 { png::ColorType::Rgba } else { png::ColorType::Rgb });
    enc.set_compression(settings.compression);
    enc.set_filter(settings.filter);
    let result = match &img.data {
        NormalData::U8(d) => {
            enc.set_depth(png::BitDepth::Eight);
            enc.write_header().and_then(|mut w| {
                w.write_image_data(d)?;
                w.finish()
            })
        }
        NormalData::U16(d) => {
            enc.set_depth(png::BitDepth::Sixteen);
            let be: Vec<u8> = d.iter().flat_map(|v| v.to_be_bytes()).collect();
            enc.write_header().and_then(|mut w| {
                w.write_image_data(&be)?;
                w.finish()
            })
        }
        NormalData::F32(_) => return Err("a float normal map cannot be written as PNG: use .exr".into()),
    };
    result.map_err(one_line)?;
    Ok(out)
}

/// The bytes of a normal map in `format` (PNG, TIFF or EXR; EXR takes float maps only).
pub fn image_bytes(img: &NormalImage, format: OutputFormat, png: PngSettings) -> crate::error::Faulty<Vec<u8>> {
    let (w, h) = (img.width as u32, img.height as u32);
    let rgba = img.channels == 4;
    match (format, &img.data) {
        (OutputFormat::Png, _) => png_bytes(img, png),
        (OutputFormat::Tiff, NormalData::U8(d)) => {
            let mut c = Cursor::new(Vec::new());
            let ct = if rgba { ExtendedColorType::Rgba8 } else { ExtendedColorType::Rgb8 };
            image::codecs::tiff::TiffEncoder::new(&mut c).write_image(d, w, h, ct).map_err(one_line)?;
            Ok(c.into_inner())
        }
        (OutputFormat::Tiff, NormalData::U16(d)) => {
            let mut c = Cursor::new(Vec::new());
            let ct = if rgba { ExtendedColorType::Rgba16 } else { ExtendedColorType::Rgb16 };
            let bytes: Vec<u8> = d.iter().flat_map(|v| v.to_ne_bytes()).collect();
            image::codecs::tiff::TiffEncoder::new(&mut c).write_image(&bytes, w, h, ct).map_err(one_line)?;
            Ok(c.into_inner())
        }
        (OutputFormat::Exr, NormalData::F32(d)) => {
            let mut c = Cursor::new(Vec::new());
            let ct = if rgba { ExtendedColorType::Rgba32F } else { ExtendedColorType::Rgb32F };
            let bytes: Vec<u8> = d.iter().flat_map(|v| v.to_ne_bytes()).collect();
            image::codecs::openexr::OpenExrEncoder::new(&mut c).write_image(&bytes, w, h, ct).map_err(one_line)?;
            Ok(c.into_inner())
        }
        (OutputFormat::Exr, _) => Err("EXR output takes float normals".into()),
        (OutputFormat::Ktx2, _) => Err("KTX2 output is written with its mip chain by `convert_file`".into()),
        (OutputFormat::Tiff, NormalData::F32(_)) => Err("float TIFF output is not supported: use .exr".into()),
    }
}

/// Writes a normal map in the format its extension names, atomically.
pub fn write_normal_image(path: &Path, img: &NormalImage, png: PngSettings) -> Result<()> {
    let format = OutputFormat::from_path(path)?;
    let bytes = image_bytes(img, format, png).map_err(|m| Error::output(path, m))?;
    crate::output::write_atomic(path, &bytes)
}

/// The whole `bumpbake normalmap` command.
#[derive(Clone, Debug)]
pub struct Convert {
    pub input: PathBuf,
    pub output: PathBuf,
    pub channel: Channel,
    pub max_pixels: u64,
    pub options: Options,
    /// `depth` is taken from the output name and `--bits` by the caller.
    pub encode: EncodeOptions,
    pub png: PngSettings,
    /// The codec of KTX2 output.
    pub ktx2: crate::format::image::ktx2::Codec,
}

/// What one conversion did (`--json`: `docs/json.md`, normalmap).
#[derive(Debug, Clone, serde::Serialize)]
pub struct Converted {
    pub input: PathBuf,
    pub output: PathBuf,
    /// `decode`, `filter`, `encode`, `write`, in ms.
    pub timings_ms: Timings,
    /// A map that came out (nearly) flat.
    pub warnings: Vec<String>,
    /// KTX2 output: each mip level's angular error after the codec.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub levels: Option<Vec<LevelError>>,
    /// Whether this is one of several inputs (the text then names the files); the caller sets it.
    #[serde(skip)]
    pub batch: bool,
}

/// Runs [`Convert`]: decode, filter + encode, serialise, write (KTX2 adds the `mips` and `check`
/// stages and each level's error). Nothing is written unless all succeeds. The filter's rows are
/// a stage of `progress`, named after the input.
///
/// PNG output is streamed: strips of rows are filtered (in parallel) into one reused buffer and
/// handed to the compressor, so the encoded map never exists whole and memory stays at about
/// the height plane plus the compressed file.
pub fn convert_file(c: &Convert, progress: &Reporter) -> Result<Converted> {
    let format = OutputFormat::from_path(&c.output)?;
    if format == OutputFormat::Ktx2 {
        c.ktx2.check()?;
    }
    let mut t = Timings::default();
    let height = t.time("decode", || load_height(&c.input, c.channel, c.max_pixels))?;
    // Judged on the texels as written, as `validate` judges them.
    let mut flat = super::Flatness::default();
    progress.start(&format!("normalmap {}", c.input.display()), height.height as u64, "rows");
    let bytes = filtered_bytes(c, format, &height, progress, &mut t, &mut flat);
    progress.finish();
    let (bytes, levels) = bytes?;
    let warning = flat.warning(&height, c.options.strength, 1.0);
    drop(height);
    t.time("write", || crate::output::write_atomic(&c.output, &bytes))?;
    Ok(Converted {
        input: c.input.clone(),
        output: c.output.clone(),
        timings_ms: t,
        warnings: warning.into_iter().collect(),
        levels,
        batch: false,
    })
}

/// The encoded file's bytes: filtered and encoded, timed as `filter` and `encode` (KTX2: with
/// each level's error).
fn filtered_bytes(
    c: &Convert,
    format: OutputFormat,
    height: &HeightPlane,
    progress: &Reporter,
    t: &mut Timings,
    flat: &mut super::Flatness,
) -> Result<(Vec<u8>, Option<Vec<LevelError>>)> {
    if format == OutputFormat::Ktx2 {
        if c.encode.alpha_height || c.encode.depth != Depth::Bits8 {
            let msg = format!("{}: KTX2 output is an 8-bit RGB normal map (no ", c.output.display());
            let msg = Words::from(msg).name(Setting::Alpha).text(", no ").given(Setting::Bits, 16).text(")");
            let setting = if c.encode.alpha_height { Setting::Alpha } else { Setting::Bits };
            return Err(Error::setting(setting, None, msg));
        }
        let max = crate::format::image::ktx2::MAX_SIDE as usize;
        if height.width > max || height.height > max {
            return Err(Error::usage(format!(
                "{}: a {}x{} map is larger than Basis Universal encodes ({max} texels a side): write PNG",
                c.output.display(),
                height.width,
                height.height
            )));
        }
        let img = t.time("filter", || encode_normals(height, &c.options, &c.encode, progress));
        *flat = super::Flatness::of_image(&img);
        let NormalData::U8(rgb) = &img.data else {
            return Err(Error::output(&c.output, "KTX2 output takes 8-bit normals"));
        };
        let (bytes, report) =
            super::ktx2::ktx2_bytes(rgb, img.width, img.height, c.ktx2, t).map_err(|m| Error::output(&c.output, m))?;
        Ok((bytes, Some(report)))
    } else if format == OutputFormat::Png && c.encode.depth != Depth::Float {
        let (bytes, filter_ms, encode_ms) = png_streamed(height, &c.options, &c.encode, c.png, progress, flat)
            .map_err(|m| Error::output(&c.output, m))?;
        t.stages.push(("filter".into(), filter_ms));
        t.stages.push(("encode".into(), encode_ms));
        Ok((bytes, None))
    } else {
        let img = t.time("filter", || encode_normals(height, &c.options, &c.encode, progress));
        *flat = super::Flatness::of_image(&img);
        let bytes = t.time("encode", || image_bytes(&img, format, c.png)).map_err(|m| Error::output(&c.output, m))?;
        Ok((bytes, None))
    }
}

/// Strip-by-strip filtering and PNG compression; returns the bytes and the time spent in
/// each (ms).
fn png_streamed(
    height: &HeightPlane,
    opts: &Options,
    enc: &EncodeOptions,
    settings: PngSettings,
    progress: &Reporter,
    flat: &mut super::Flatness,
) -> crate::error::Faulty<(Vec<u8>, f64, f64)> {
    use std::io::Write;
    use std::time::Instant;
    let (w, h) = (height.width, height.height);
    let ch = if enc.alpha_height { 4 } else { 3 };
    let sample_bytes = if enc.depth == Depth::Bits16 { 2 } else { 1 };
    // About 2 MB a strip: large enough for every worker to get many bands, small enough to
    // stay in cache between the filter writing it and the compressor reading it.
    let strip = ((2 << 20) / (w * ch * sample_bytes)).clamp(8, 1024);
    let mut out = Vec::new();
    let (mut filter_ms, mut encode_ms) = (0.0, 0.0);
    {
        let mut e = png::Encoder::new(&mut out, w as u32, h as u32);
        e.set_color(if ch == 4 { png::ColorType::Rgba } else { png::ColorType::Rgb });
        e.set_depth(if sample_bytes == 2 { png::BitDepth::Sixteen } else { png::BitDepth::Eight });
        e.set_compression(settings.compression);
        e.set_filter(settings.filter);
        let mut writer = e.write_header().map_err(one_line)?;
        let mut stream = writer.stream_writer_with_size(1 << 20).map_err(one_line)?;
        let mut strips = super::encode::Strips::new(height, opts, enc);
        let mut be: Vec<u8> = Vec::new();
        // Strip k is compressed (one thread) while strip k + 1 is filtered (the others).
        let starts: Vec<usize> = (0..h).step_by(strip).collect();
        let (mut done_u8, mut done_u16): (Vec<u8>, Vec<u16>) = (Vec::new(), Vec::new());
        let t0 = Instant::now();
        strips.encode(0, strip.min(h), progress);
        filter_ms += t0.elapsed().as_secs_f64() * 1e3;
        for (k, _) in starts.iter().enumerate() {
            std::mem::swap(&mut strips.u8s, &mut done_u8);
            std::mem::swap(&mut strips.u16s, &mut done_u16);
            let mut write = || -> crate::error::Faulty<f64> {
                let t = Instant::now();
                if sample_bytes == 2 {
                    flat.push_u16(&done_u16, ch);
                    be.clear();
                    be.extend(done_u16.iter().flat_map(|v| v.to_be_bytes()));
                    stream.write_all(&be).map_err(one_line)?;
                } else {
                    flat.push_u8(&done_u8, ch);
                    stream.write_all(&done_u8).map_err(one_line)?;
                }
                Ok(t.elapsed().as_secs_f64() * 1e3)
            };
            let (wrote, filtered) = match starts.get(k + 1) {
                Some(&y) => rayon::join(write, || {
                    let t = Instant::now();
                    strips.encode(y, strip.min(h - y), progress);
                    t.elapsed().as_secs_f64() * 1e3
                }),
                None => (write(), 0.0),
            };
            encode_ms += wrote?;
            filter_ms += filtered;
        }
        let t1 = Instant::now();
        stream.finish().map_err(one_line)?;
        encode_ms += t1.elapsed().as_secs_f64() * 1e3;
    }
    Ok((out, filter_ms, encode_ms))
}
