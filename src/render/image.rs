//! Rendered images: premultiplied floating-point RGBA with a depth per pixel, their 8-bit
//! conversion, and PNG output (through the `png` crate).

use std::fs::File;
use std::io::BufWriter;
use std::path::Path;

use crate::Error;

/// A rendered image, rows top to bottom.
#[derive(Clone, Debug, PartialEq)]
pub struct Image {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// Premultiplied `[r, g, b, a]` per pixel, `a = 1 − transmittance`, all in `[0, 1]`.
    pub rgba: Vec<[f32; 4]>,
    /// Per pixel, the ray distance of the depth sample (see [`crate::render::RenderOptions`]),
    /// `+∞` where there is none.
    pub depth: Vec<f32>,
}

fn to_u8(x: f64) -> u8 {
    (x.clamp(0.0, 1.0) * 255.0).round() as u8
}

impl Image {
    /// A transparent image with infinite depth.
    pub fn new(width: u32, height: u32) -> Image {
        let n = width as usize * height as usize;
        Image {
            width,
            height,
            rgba: vec![[0.0; 4]; n],
            depth: vec![f32::INFINITY; n],
        }
    }

    /// 8-bit RGBA, row after row. With a background colour the image is composited over it
    /// (alpha 255); without, the colour is un-premultiplied and alpha kept (straight alpha).
    pub fn to_rgba8(&self, background: Option<[f64; 3]>) -> Vec<u8> {
        let mut out = Vec::with_capacity(self.rgba.len() * 4);
        for p in &self.rgba {
            let a = p[3] as f64;
            match background {
                Some(bg) => {
                    for (c, b) in p.iter().zip(bg) {
                        out.push(to_u8(*c as f64 + (1.0 - a) * b));
                    }
                    out.push(255);
                }
                None => {
                    for c in &p[..3] {
                        out.push(to_u8(if a > 0.0 { *c as f64 / a } else { 0.0 }));
                    }
                    out.push(to_u8(a));
                }
            }
        }
        out
    }

    /// The largest difference of any channel of any pixel from `other` (premultiplied RGBA);
    /// infinite when the sizes differ.
    pub fn max_abs_difference(&self, other: &Image) -> f32 {
        if (self.width, self.height) != (other.width, other.height) {
            return f32::INFINITY;
        }
        self.rgba
            .iter()
            .zip(&other.rgba)
            .flat_map(|(p, q)| (0..4).map(move |k| (p[k] - q[k]).abs()))
            .fold(0.0, f32::max)
    }

    /// Writes the image as an 8-bit RGBA PNG (see [`Image::to_rgba8`] for `background`).
    pub fn write_png(&self, path: &Path, background: Option<[f64; 3]>) -> Result<(), Error> {
        let file = File::create(path).map_err(|source| Error::Io {
            path: path.to_path_buf(),
            source,
        })?;
        let mut encoder = png::Encoder::new(BufWriter::new(file), self.width, self.height);
        encoder.set_color(png::ColorType::Rgba);
        encoder.set_depth(png::BitDepth::Eight);
        let enc = |e: png::EncodingError| Error::Invalid(format!("{}: {e}", path.display()));
        let mut writer = encoder.write_header().map_err(enc)?;
        writer
            .write_image_data(&self.to_rgba8(background))
            .map_err(enc)?;
        writer.finish().map_err(enc)
    }

    /// The depth image as VTK stores images: rows bottom to top, NaN where a pixel has no
    /// depth sample (`+∞` in [`Image::depth`]), so that VTK's and ParaView's ranges and colour
    /// maps skip it.
    pub fn depth_bottom_up(&self) -> Vec<f32> {
        crate::io::vti::rows_flipped(&self.depth, self.width as usize, |d| {
            if d.is_infinite() {
                f32::NAN
            } else {
                d
            }
        })
    }

    /// Writes [`Image::depth_bottom_up`] as VTK image data (`.vti`), one point array `depth`
    /// over a `width × height` image ([`crate::io::vti::write_point_scalars`]).
    pub fn write_depth_vti(&self, path: &Path) -> Result<(), Error> {
        let io_error = |source| Error::Io {
            path: path.to_path_buf(),
            source,
        };
        let mut out = BufWriter::new(File::create(path).map_err(io_error)?);
        crate::io::vti::write_point_scalars(
            &mut out,
            self.width,
            self.height,
            "depth",
            &self.depth_bottom_up(),
        )
        .and_then(|()| std::io::Write::flush(&mut out))
        .map_err(io_error)
    }
}
