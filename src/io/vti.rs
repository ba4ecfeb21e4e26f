//! VTK XML image data (`.vti`) output for 2-D images of one `Float32` value per pixel, such as
//! a render's depth image ([`crate::render::Image::write_depth_vti`]): VTK's
//! `vtkXMLImageDataReader` and ParaView open it as a one-slice image.
//!
//! The file holds one point array over a `width × height × 1` grid of unit spacing with its
//! origin at `(0, 0, 0)`, rows **bottom to top** as VTK stores images (point `(i, j)` is
//! pixel column `i` of row `j` counted from the bottom), in raw appended binary, little
//! endian, with a 64-bit size header.

use std::io::{self, Write};

use super::vtu::xml_escape;

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
