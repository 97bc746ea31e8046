//! Decoded images to heights `h` in [0,1] (floats taken as they are), per the conventions:
//! 8-bit samples over 255, 16-bit over 65535, colour through Rec. 709 luma unless a channel is
//! chosen. Luma is taken on the stored values, not linearised: a height map's values are
//! heights, not light, whatever colour space tag the file carries.

use crate::error::{Setting, Words};
use image::DynamicImage;
use rayon::prelude::*;
use serde::Serialize;

/// Which channel of the input carries the height.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Channel {
    /// Rec. 709 luma (0.2126 R + 0.7152 G + 0.0722 B) for colour, the gray value for gray.
    #[default]
    Luma,
    R,
    G,
    B,
    A,
}

/// Heights, row-major from the top row of the image.
#[derive(Clone, Debug, PartialEq)]
pub struct HeightPlane {
    pub width: usize,
    pub height: usize,
    pub data: Vec<f32>,
}

impl HeightPlane {
    pub fn new(width: usize, height: usize, data: Vec<f32>) -> HeightPlane {
        assert_eq!(data.len(), width * height, "height plane size");
        HeightPlane { width, height, data }
    }
    /// `f(x, row)` for every texel, row 0 at the top.
    pub fn from_fn(width: usize, height: usize, f: impl Fn(usize, usize) -> f32) -> HeightPlane {
        let data = (0..width * height).map(|i| f(i % width, i / width)).collect();
        HeightPlane { width, height, data }
    }
    pub fn get(&self, x: usize, y: usize) -> f32 {
        self.data[y * self.width + x]
    }
}

const LUMA: [f32; 3] = [0.2126, 0.7152, 0.0722];

#[derive(Clone, Copy)]
pub(crate) enum Pick {
    Index(usize),
    Luma,
}

/// Which sample of a `channels`-sample pixel holds the height, or why none does.
pub(crate) fn pick(channel: Channel, channels: usize, has_alpha: bool, is_colour: bool) -> crate::error::Faulty<Pick> {
    Ok(match channel {
        Channel::A if !has_alpha => {
            return Err(Words::new().given(Setting::Channel, "a").text(", but the image has no alpha channel").into())
        }
        Channel::A => Pick::Index(channels - 1),
        _ if !is_colour => Pick::Index(0),
        Channel::Luma => Pick::Luma,
        Channel::R => Pick::Index(0),
        Channel::G => Pick::Index(1),
        Channel::B => Pick::Index(2),
    })
}

/// One row of raw samples to heights.
#[inline]
pub(crate) fn convert_row<T: Copy>(raw: &[T], ch: usize, pick: Pick, f: impl Fn(T) -> f32, out: &mut [f32]) {
    match pick {
        Pick::Index(i) => out.iter_mut().zip(raw.chunks_exact(ch)).for_each(|(o, p)| *o = f(p[i])),
        Pick::Luma => out.iter_mut().zip(raw.chunks_exact(ch)).for_each(|(o, p)| {
            *o = LUMA[0] * f(p[0]) + LUMA[1] * f(p[1]) + LUMA[2] * f(p[2]);
        }),
    }
}

/// One row of big-endian 16-bit samples (as PNG stores them) to heights.
#[inline]
pub(crate) fn convert_row_be16(raw: &[u8], ch: usize, pick: Pick, out: &mut [f32]) {
    let s = |p: &[u8], i: usize| u16::from_be_bytes([p[2 * i], p[2 * i + 1]]) as f32 / 65535.0;
    match pick {
        Pick::Index(i) => out.iter_mut().zip(raw.chunks_exact(2 * ch)).for_each(|(o, p)| *o = s(p, i)),
        Pick::Luma => out.iter_mut().zip(raw.chunks_exact(2 * ch)).for_each(|(o, p)| {
            *o = LUMA[0] * s(p, 0) + LUMA[1] * s(p, 1) + LUMA[2] * s(p, 2);
        }),
    }
}

/// Turns a decoded image into heights. The error says what is wrong, without the file name.
pub fn height_from_image(img: &DynamicImage, channel: Channel) -> crate::error::Faulty<HeightPlane> {
    let (w, h) = (img.width() as usize, img.height() as usize);
    let has_alpha = img.color().has_alpha();
    let channels = img.color().channel_count() as usize;
    let pick = pick(channel, channels, has_alpha, img.color().has_color())?;
    let data = match img {
        DynamicImage::ImageLuma8(b) => convert(b.as_raw(), w, 1, pick, |v| v as f32 / 255.0),
        DynamicImage::ImageLumaA8(b) => convert(b.as_raw(), w, 2, pick, |v| v as f32 / 255.0),
        DynamicImage::ImageRgb8(b) => convert(b.as_raw(), w, 3, pick, |v| v as f32 / 255.0),
        DynamicImage::ImageRgba8(b) => convert(b.as_raw(), w, 4, pick, |v| v as f32 / 255.0),
        DynamicImage::ImageLuma16(b) => convert(b.as_raw(), w, 1, pick, |v| v as f32 / 65535.0),
        DynamicImage::ImageLumaA16(b) => convert(b.as_raw(), w, 2, pick, |v| v as f32 / 65535.0),
        DynamicImage::ImageRgb16(b) => convert(b.as_raw(), w, 3, pick, |v| v as f32 / 65535.0),
        DynamicImage::ImageRgba16(b) => convert(b.as_raw(), w, 4, pick, |v| v as f32 / 65535.0),
        DynamicImage::ImageRgb32F(b) => convert(b.as_raw(), w, 3, pick, |v| v),
        DynamicImage::ImageRgba32F(b) => convert(b.as_raw(), w, 4, pick, |v| v),
        other => {
            // Any layout added to `image` later: go through RGBA float, which loses nothing.
            let rgba = other.to_rgba32f();
            let pick = match pick {
                Pick::Index(i) if i == channels - 1 && has_alpha => Pick::Index(3),
                p => p,
            };
            convert(rgba.as_raw(), w, 4, pick, |v| v)
        }
    };
    check_finite(&data, w)?;
    Ok(HeightPlane { width: w, height: h, data })
}

/// Float inputs may hold NaN or infinities, which no filter can differentiate.
pub(crate) fn check_finite(data: &[f32], w: usize) -> crate::error::Faulty<()> {
    match data.iter().position(|v| !v.is_finite()) {
        Some(i) => Err(format!("height sample at column {}, row {} is {}", i % w, i / w, data[i]).into()),
        None => Ok(()),
    }
}

fn convert<T: Copy + Sync>(raw: &[T], w: usize, ch: usize, pick: Pick, f: impl Fn(T) -> f32 + Sync) -> Vec<f32> {
    let mut out = vec![0.0f32; raw.len() / ch];
    if w == 0 {
        return out;
    }
    out.par_chunks_mut(w).zip(raw.par_chunks(w * ch)).for_each(|(o, r)| convert_row(r, ch, pick, &f, o));
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use image::{GrayImage, ImageBuffer, Luma, Rgba, RgbaImage};

    #[test]
    fn bit_depths_scale_to_unit_range() {
        let g8 = DynamicImage::ImageLuma8(GrayImage::from_raw(2, 1, vec![0, 255]).unwrap());
        assert_eq!(height_from_image(&g8, Channel::Luma).unwrap().data, vec![0.0, 1.0]);
        let g16: ImageBuffer<Luma<u16>, Vec<u16>> = ImageBuffer::from_raw(2, 1, vec![1, 65535]).unwrap();
        let p = height_from_image(&DynamicImage::ImageLuma16(g16), Channel::R).unwrap();
        assert_eq!(p.data, vec![1.0 / 65535.0, 1.0]);
    }

    #[test]
    fn channels_and_luma() {
        let img = RgbaImage::from_pixel(1, 1, Rgba([255, 0, 0, 51]));
        let img = DynamicImage::ImageRgba8(img);
        assert!((height_from_image(&img, Channel::Luma).unwrap().data[0] - 0.2126).abs() < 1e-6);
        assert_eq!(height_from_image(&img, Channel::R).unwrap().data[0], 1.0);
        assert_eq!(height_from_image(&img, Channel::G).unwrap().data[0], 0.0);
        assert_eq!(height_from_image(&img, Channel::A).unwrap().data[0], 0.2);
        let gray = DynamicImage::ImageLuma8(GrayImage::new(1, 1));
        assert!(height_from_image(&gray, Channel::A).unwrap_err().to_string().contains("no alpha"));
    }

    #[test]
    fn non_finite_floats_are_refused() {
        let img = image::Rgb32FImage::from_raw(2, 1, vec![0.0, 0.0, 0.0, f32::NAN, 0.0, 0.0]).unwrap();
        let e = height_from_image(&DynamicImage::ImageRgb32F(img), Channel::R).unwrap_err().to_string();
        assert!(e.contains("column 1, row 0"), "{e}");
    }
}
