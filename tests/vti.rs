//! Reading VTK image data (`.vti`, `cylvol::io::vti::read_point_scalars`): images VTK's own
//! `vtkXMLImageDataWriter` writes, in every encoding and compressor it offers, read to the
//! values it wrote.

use std::process::Command;

use cylvol::io::vti;

/// Writes a 7×5 one-slice image (extent starting at (2, −1)) with a `Float32` array `d`
/// (NaN and an infinity among its values) as the active scalars, an `Int16` array and a
/// vector, in each mode; prints each file's name and the values of `d` it wrote (as `f32`,
/// exactly). (VTK's own reader fails on its ASCII file, which spells NaN `nan`.)
const SCRIPT: &str = r#"
import math, sys, vtk
out = sys.argv[1]
img = vtk.vtkImageData(); img.SetExtent(2, 8, -1, 3, 4, 4)
n = img.GetNumberOfPoints()
d = vtk.vtkFloatArray(); d.SetName('d')
e = vtk.vtkShortArray(); e.SetName('e')
v = vtk.vtkDoubleArray(); v.SetName('v'); v.SetNumberOfComponents(3)
for k in range(n):
    d.InsertNextValue(float('nan') if k % 9 == 4 else float('inf') if k == 7 else k * 0.37 - 5.0)
    e.InsertNextValue(k - 17)
    v.InsertNextTuple3(k, -k, 0.5 * k)
img.GetPointData().AddArray(e); img.GetPointData().AddArray(v); img.GetPointData().SetScalars(d)
modes = [('ascii', 'ascii', None, 64), ('binary', 'binary', None, 64),
         ('raw', 'appended', None, 64), ('raw32', 'appended', None, 32),
         ('base64', 'appended-base64', None, 64),
         ('zlib', 'appended', 'zlib', 64), ('lz4', 'binary', 'lz4', 32), ('lzma', 'appended', 'lzma', 64)]
for name, mode, compressor, header in modes:
    w = vtk.vtkXMLImageDataWriter(); w.SetInputData(img)
    w.SetFileName(out + '/' + name + '.vti')
    if mode == 'ascii': w.SetDataModeToAscii()
    elif mode == 'binary': w.SetDataModeToBinary()
    else:
        w.SetDataModeToAppended()
        w.SetEncodeAppendedData(1 if mode == 'appended-base64' else 0)
    if compressor is None: w.SetCompressorTypeToNone()
    elif compressor == 'zlib': w.SetCompressorTypeToZLib()
    elif compressor == 'lz4': w.SetCompressorTypeToLZ4()
    else: w.SetCompressorTypeToLZMA()
    if header == 32: w.SetHeaderTypeToUInt32()
    else: w.SetHeaderTypeToUInt64()
    assert w.Write() == 1
    print(name, *[repr(d.GetValue(k)) for k in range(n)])
"#;

#[test]
fn images_vtk_writes_read_to_the_values_written() {
    let dir = tempfile::tempdir().unwrap();
    let Ok(out) = Command::new("/usr/bin/python3")
        .args(["-c", SCRIPT, dir.path().to_str().unwrap()])
        .output()
    else {
        eprintln!("NOTE: /usr/bin/python3 unavailable; skipping the comparison with VTK");
        return;
    };
    let stderr = String::from_utf8_lossy(&out.stderr);
    if !out.status.success() && stderr.contains("No module named 'vtk'") {
        eprintln!("NOTE: VTK's Python unavailable; skipping the comparison with VTK");
        return;
    }
    assert!(out.status.success(), "{stderr}");
    let stdout = String::from_utf8_lossy(&out.stdout);
    let lines: Vec<&str> = stdout.lines().collect();
    assert_eq!(lines.len(), 8, "{stdout}");
    for line in lines {
        let fields: Vec<&str> = line.split_whitespace().collect();
        let name = fields[0];
        let written: Vec<f64> = fields[1..].iter().map(|v| v.parse().unwrap()).collect();
        let path = dir.path().join(format!("{name}.vti"));
        let ours = vti::read_point_scalars_file(&path).unwrap_or_else(|e| panic!("{name}: {e}"));
        assert_eq!((ours.width, ours.height), (7, 5), "{name}");
        assert_eq!(ours.name, "d", "{name}");
        assert_eq!(ours.values.len(), written.len(), "{name}");
        for (k, (a, b)) in ours.values.iter().zip(&written).enumerate() {
            // Binary data is the `f32`s themselves; ASCII text VTK's printed digits.
            let same = if name == "ascii" {
                (*a as f32).to_bits() == (*b as f32).to_bits()
            } else {
                a.to_bits() == b.to_bits()
            };
            assert!(
                same || (a.is_nan() && b.is_nan()),
                "{name}: value {k}: ours {a}, written {b}"
            );
        }
        assert_eq!(
            ours.values.iter().filter(|v| v.is_nan()).count(),
            written.iter().filter(|v| v.is_nan()).count(),
            "{name}"
        );
        assert!(ours.values.contains(&f64::INFINITY), "{name}");
    }
}
