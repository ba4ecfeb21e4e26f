//! VTK XML image data (`.vti`) for 2-D images of one value per pixel, such as a render's
//! depth image: written by [`write_point_scalars`]
//! ([`crate::render::Image::write_depth_vti`]), which VTK's `vtkXMLImageDataReader` and
//! ParaView open as a one-slice image, and read by [`read_point_scalars`] (what the writer
//! writes, and what VTK's `vtkXMLImageDataWriter` writes for a one-slice image), which
//! `cylvol render --depth-in` takes.
//!
//! The writer's file holds one point array over a `width × height × 1` grid of unit spacing
//! with its origin at `(0, 0, 0)`, rows **bottom to top** as VTK stores images (point `(i, j)`
//! is pixel column `i` of row `j` counted from the bottom), in raw appended binary, little
//! endian, with a 64-bit size header.

use std::io::{self, Write};
use std::path::Path;

use super::vtu::{read_image_points, xml_escape};
use crate::error::Error;

/// A 2-D image of one value per pixel ([`read_point_scalars`]).
#[derive(Clone, Debug, PartialEq)]
pub struct ImageScalars {
    /// Pixels per row.
    pub width: u32,
    /// Rows.
    pub height: u32,
    /// The point array's name.
    pub name: String,
    /// `width × height` values, rows **bottom to top** as VTK stores them (pixel `(i, j)`,
    /// row `j` from the bottom, at `j · width + i`).
    pub values: Vec<f64>,
}

impl ImageScalars {
    /// The values as `f32`, rows **top to bottom** (the renderer's order, as
    /// [`crate::render::Renderer::render`] takes a depth image).
    pub fn top_down_f32(&self) -> Vec<f32> {
        rows_flipped(&self.values, self.width as usize, |v| v as f32)
    }
}

/// `values` in rows of `width`, the last row first, each value mapped by `f`: between VTK's
/// bottom-to-top image rows and the renderer's top-to-bottom ones (empty for a zero width).
pub(crate) fn rows_flipped<T: Copy, U>(values: &[T], width: usize, f: impl Fn(T) -> U) -> Vec<U> {
    if width == 0 {
        return Vec::new();
    }
    values
        .chunks_exact(width)
        .rev()
        .flatten()
        .map(|&v| f(v))
        .collect()
}

/// Reads the one-component point array of a VTK image one slice thick along z (`.vti`):
/// the array its piece names as active scalars, else its only one-component point array.
/// Any of VTK's XML encodings reads (ascii, base64, raw appended; compressed or not; either
/// header width and byte order), and any numeric type (converted to `f64`); the image must be
/// one piece covering its whole extent, as VTK's image writer writes it. Anything else is an
/// error saying what.
///
/// ```
/// use cylvol::io::vti;
/// let mut bytes = Vec::new();
/// vti::write_point_scalars(&mut bytes, 3, 2, "depth", &[1.0, 2.0, 3.0, 4.0, 5.0, f32::NAN]).unwrap();
/// let image = vti::read_point_scalars(&bytes).unwrap();
/// assert_eq!((image.width, image.height, image.name.as_str()), (3, 2, "depth"));
/// assert_eq!(image.values[..5], [1.0, 2.0, 3.0, 4.0, 5.0]);
/// assert!(image.values[5].is_nan());
/// // Rows top to bottom, for the renderer.
/// let top = image.top_down_f32();
/// assert_eq!(top[..2], [4.0, 5.0]);
/// assert!(top[2].is_nan());
/// assert_eq!(top[3..], [1.0, 2.0, 3.0]);
/// ```
pub fn read_point_scalars(bytes: &[u8]) -> Result<ImageScalars, Error> {
    let mut image = read_image_points(bytes).map_err(|mut e| {
        e.format = FORMAT;
        e
    })?;
    let invalid = |message: String| Error::Invalid(format!("{FORMAT}: {message}"));
    let e = image.extent;
    if e[4] != e[5] {
        return Err(invalid(format!(
            "the image is {} slices thick along z (extent {e:?}); a 2-D image is one",
            e[5] - e[4] + 1
        )));
    }
    let side = |lo: i64, hi: i64| u32::try_from(hi - lo + 1).ok();
    let (Some(width), Some(height)) = (side(e[0], e[1]), side(e[2], e[3])) else {
        return Err(invalid(format!("the image's extent {e:?} is too large")));
    };
    let singles: Vec<usize> = (0..image.arrays.len())
        .filter(|&i| image.arrays[i].components == 1)
        .collect();
    let chosen = match &image.active {
        Some(name) => image.arrays.iter().position(|a| &a.name == name),
        None => singles.first().copied().filter(|_| singles.len() == 1),
    };
    let Some(chosen) = chosen else {
        let names: Vec<String> = image
            .arrays
            .iter()
            .map(|a| format!("{} ({} components)", a.name, a.components))
            .collect();
        return Err(invalid(match &image.active {
            Some(name) => format!("the active scalars \"{name}\" are not a numeric point array"),
            None if singles.is_empty() => format!(
                "the image has no numeric point array of one component (it has: {})",
                if names.is_empty() {
                    "none".to_string()
                } else {
                    names.join(", ")
                }
            ),
            None => format!(
                "the image has {} point arrays of one component and names none as its \
                 scalars: {}",
                singles.len(),
                names.join(", ")
            ),
        }));
    };
    let array = image.arrays.swap_remove(chosen);
    if array.components != 1 {
        return Err(invalid(format!(
            "the active scalars \"{}\" have {} components, not one",
            array.name, array.components
        )));
    }
    Ok(ImageScalars {
        width,
        height,
        name: array.name,
        values: array.values,
    })
}

/// [`read_point_scalars`] of a file; errors name it.
pub fn read_point_scalars_file(path: &Path) -> Result<ImageScalars, Error> {
    let bytes = super::read_bytes(path)?;
    read_point_scalars(&bytes).map_err(|e| e.in_file(path))
}

/// The format name in read errors.
const FORMAT: &str = "VTI";

/// Writes `values` (`width × height` of them, rows bottom to top) as a `.vti` file with one
/// point array called `name`, the active scalars.
///
/// Errors are those of `out`, or `InvalidInput` when `values` does not hold `width × height`
/// values or the image is empty.
///
/// ```
/// use cylvol::io::vti;
/// let mut bytes = Vec::new();
/// vti::write_point_scalars(&mut bytes, 3, 2, "depth", &[1.0, 2.0, 3.0, 4.0, 5.0, f32::NAN]).unwrap();
/// let text = String::from_utf8_lossy(&bytes);
/// assert!(text.contains(r#"WholeExtent="0 2 0 1 0 0""#));
/// assert!(text.contains(r#"Name="depth""#));
/// // After the appended block's `_` marker: the byte count (24), then the six floats.
/// let block = &bytes[text.find("<AppendedData").unwrap()..];
/// let data = &block[block.iter().position(|&b| b == b'_').unwrap() + 1..];
/// assert_eq!(u64::from_le_bytes(data[..8].try_into().unwrap()), 24);
/// assert_eq!(f32::from_le_bytes(data[8..12].try_into().unwrap()), 1.0);
/// ```
pub fn write_point_scalars(
    out: &mut dyn Write,
    width: u32,
    height: u32,
    name: &str,
    values: &[f32],
) -> io::Result<()> {
    let count = width as u64 * height as u64;
    if count == 0 || values.len() as u64 != count {
        return Err(io::Error::new(
            io::ErrorKind::InvalidInput,
            format!(
                "a {width}x{height} image needs {count} values, not {}",
                values.len()
            ),
        ));
    }
    let extent = format!("0 {} 0 {} 0 0", width - 1, height - 1);
    let name = xml_escape(name);
    write!(
        out,
        "<?xml version=\"1.0\"?>\n\
         <VTKFile type=\"ImageData\" version=\"1.0\" byte_order=\"LittleEndian\" header_type=\"UInt64\">\n\
         \x20 <ImageData WholeExtent=\"{extent}\" Origin=\"0 0 0\" Spacing=\"1 1 1\">\n\
         \x20   <Piece Extent=\"{extent}\">\n\
         \x20     <PointData Scalars=\"{name}\">\n\
         \x20       <DataArray type=\"Float32\" Name=\"{name}\" NumberOfComponents=\"1\" format=\"appended\" offset=\"0\"/>\n\
         \x20     </PointData>\n\
         \x20     <CellData/>\n\
         \x20   </Piece>\n\
         \x20 </ImageData>\n\
         \x20 <AppendedData encoding=\"raw\">\n   _"
    )?;
    out.write_all(&(count * 4).to_le_bytes())?;
    let mut bytes = Vec::with_capacity(values.len() * 4);
    for v in values {
        bytes.extend_from_slice(&v.to_le_bytes());
    }
    out.write_all(&bytes)?;
    write!(out, "\n  </AppendedData>\n</VTKFile>\n")
}

#[cfg(test)]
mod tests {
    use super::*;

    fn values_of(bytes: &[u8]) -> Vec<u32> {
        let at = bytes
            .windows(13)
            .position(|w| w == b"<AppendedData")
            .unwrap();
        let data = &bytes[at + bytes[at..].iter().position(|&b| b == b'_').unwrap() + 1..];
        let n = u64::from_le_bytes(data[..8].try_into().unwrap()) as usize;
        data[8..8 + n]
            .chunks_exact(4)
            .map(|c| u32::from_le_bytes(c.try_into().unwrap()))
            .collect()
    }

    #[test]
    fn values_are_written_bit_for_bit_after_an_escaped_header() {
        let values = [0.0, -0.0, f32::NAN, f32::INFINITY, 1e-45, 3.5];
        let mut bytes = Vec::new();
        write_point_scalars(&mut bytes, 2, 3, "a\"b<c", &values).unwrap();
        let text = String::from_utf8_lossy(&bytes);
        assert!(text.contains(r#"Name="a&quot;b&lt;c""#), "{text}");
        assert!(text.contains(r#"WholeExtent="0 1 0 2 0 0""#), "{text}");
        assert_eq!(values_of(&bytes), values.map(f32::to_bits));
        assert!(text.ends_with("</AppendedData>\n</VTKFile>\n"));
    }

    /// What the writer writes reads back: the size, the name and every value bit for bit
    /// (through `f64`), rows bottom to top, and top to bottom for the renderer.
    #[test]
    fn written_images_read_back_bit_for_bit() {
        for (w, h) in [(1, 1), (3, 2), (1, 7), (17, 5)] {
            let values: Vec<f32> = (0..w * h)
                .map(|k| match k % 5 {
                    0 => f32::NAN,
                    1 => -0.0,
                    2 => f32::INFINITY,
                    _ => k as f32 * 1.25 - 3.0,
                })
                .collect();
            let mut bytes = Vec::new();
            write_point_scalars(&mut bytes, w, h, "depth", &values).unwrap();
            let image = read_point_scalars(&bytes).unwrap();
            assert_eq!((image.width, image.height), (w, h));
            assert_eq!(image.name, "depth");
            let bits = |v: &[f32]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
            let read: Vec<f32> = image.values.iter().map(|&v| v as f32).collect();
            assert_eq!(bits(&read), bits(&values), "{w}x{h}");
            let top_down: Vec<f32> = values
                .chunks_exact(w as usize)
                .rev()
                .flatten()
                .copied()
                .collect();
            assert_eq!(bits(&image.top_down_f32()), bits(&top_down), "{w}x{h}");
        }
    }

    /// A small image by hand: `extent`, then point arrays (`Name`, components, ascii values)
    /// under `<PointData attrs>`.
    fn image(extent: &str, point_data: &str, arrays: &[(&str, usize, &str)]) -> Vec<u8> {
        let arrays: String = arrays
            .iter()
            .map(|(name, k, values)| {
                format!(
                    r#"<DataArray type="Float64" Name="{name}" NumberOfComponents="{k}" format="ascii">{values}</DataArray>"#
                )
            })
            .collect();
        format!(
            r#"<VTKFile type="ImageData" version="1.0" byte_order="LittleEndian">
<ImageData WholeExtent="{extent}" Origin="0 0 0" Spacing="1 1 1"><Piece Extent="{extent}">
<PointData {point_data}>{arrays}</PointData></Piece></ImageData></VTKFile>"#
        )
        .into_bytes()
    }

    fn message(bytes: &[u8]) -> String {
        read_point_scalars(bytes).unwrap_err().to_string()
    }

    #[test]
    fn the_active_or_only_array_is_read_and_anything_else_is_refused() {
        let two = [("a", 1, "1 2 3 4"), ("b", 1, "5 6 7 8")];
        let active = read_point_scalars(&image("0 1 0 1 0 0", r#"Scalars="b""#, &two)).unwrap();
        assert_eq!(
            (active.name.as_str(), &active.values[..]),
            ("b", &[5.0, 6.0, 7.0, 8.0][..])
        );
        let vector_too = [("v", 3, "0 0 0 1 1 1 2 2 2 3 3 3"), ("d", 1, "9 8 7 6")];
        let only = read_point_scalars(&image("0 1 0 1 0 0", "", &vector_too)).unwrap();
        assert_eq!(only.name, "d");
        // An image placed anywhere: its extent's sizes count, not its origin.
        let moved =
            read_point_scalars(&image("-3 -1 10 10 5 5", "", &[("d", 1, "1 2 3")])).unwrap();
        assert_eq!((moved.width, moved.height), (3, 1));
        for (bytes, expected) in [
            (
                image("0 1 0 1 0 0", "", &two),
                "2 point arrays of one component and names none",
            ),
            (
                image("0 1 0 1 0 0", r#"Scalars="c""#, &two),
                "active scalars \"c\"",
            ),
            (
                image("0 1 0 1 0 0", r#"Scalars="v""#, &vector_too),
                "have 3 components",
            ),
            (
                image("0 1 0 1 0 0", "", &[("v", 3, "0 0 0 1 1 1 2 2 2 3 3 3")]),
                "no numeric point array of one component (it has: v (3 components))",
            ),
            (image("0 1 0 1 0 0", "", &[]), "(it has: none)"),
            (
                image("0 1 0 1 0 1", "", &[("d", 1, "1 2 3 4 5 6 7 8")]),
                "2 slices thick",
            ),
            (
                image("0 1 0 1", "", &[("d", 1, "1 2 3 4")]),
                "not six integers",
            ),
            (
                image("1 0 0 1 0 0", "", &[("d", 1, "1 2 3 4")]),
                "not six integers, low ≤ high",
            ),
            (image("0 1 0 1 0 0", "", &[("d", 1, "1 2 3")]), "VTI: "),
        ] {
            let got = message(&bytes);
            assert!(got.contains(expected), "'{expected}' not in '{got}'");
        }
        // Two pieces, or a piece short of the whole extent.
        let text = String::from_utf8(image("0 1 0 1 0 0", "", &[("d", 1, "1 2 3 4")])).unwrap();
        let piece = &text[text.find("<Piece").unwrap()..text.find("</ImageData>").unwrap()];
        let twice = text.replacen(piece, &format!("{piece}{piece}"), 1);
        assert!(
            message(twice.as_bytes()).contains("2 pieces"),
            "{}",
            message(twice.as_bytes())
        );
        let short = text.replacen(
            r#"Piece Extent="0 1 0 1 0 0""#,
            r#"Piece Extent="0 1 0 0 0 0""#,
            1,
        );
        assert!(message(short.as_bytes()).contains("not the <ImageData> WholeExtent"));
        // Another dataset type, named.
        let grid = text.replace("ImageData", "UnstructuredGrid");
        assert!(message(grid.as_bytes()).contains("only ImageData (.vti)"));
    }

    /// A written image cut anywhere before its closing `</VTKFile>` ends is an error, never a
    /// panic (only the final line break may go).
    #[test]
    fn a_cut_file_is_an_error() {
        let mut bytes = Vec::new();
        write_point_scalars(&mut bytes, 4, 3, "depth", &[1.5; 12]).unwrap();
        assert!(bytes.ends_with(b"</VTKFile>\n"));
        assert!(read_point_scalars(&bytes[..bytes.len() - 1]).is_ok());
        for len in 0..bytes.len() - 1 {
            assert!(read_point_scalars(&bytes[..len]).is_err(), "cut at {len}");
        }
    }

    #[test]
    fn a_wrong_count_or_an_empty_image_is_refused() {
        let mut bytes = Vec::new();
        for (w, h, n) in [(2, 2, 3), (2, 2, 5), (0, 3, 0), (3, 0, 0)] {
            let e = write_point_scalars(&mut bytes, w, h, "d", &vec![0.0; n]).unwrap_err();
            assert_eq!(e.kind(), io::ErrorKind::InvalidInput, "{w}x{h} with {n}");
        }
        assert!(bytes.is_empty(), "nothing written before the check");
    }
}
