//! Fuzz target: the vtu reader must return a mesh or an error for any bytes, never panic; a
//! mesh it returns must survive a write (in a mode picked from the input) and read back equal.
//! The bytes are also read as a parallel index (`.pvtu`) whose every piece is those bytes.
#![no_main]

use cylvol::io::vtu::{self, ByteOrder, Encoding, HeaderType, VtuOptions};

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    let _ = vtu::read_parallel(data, |_| Ok(data.to_vec()));
    let Ok(mesh) = cylvol::io::vtu::read(data) else {
        return;
    };
    let pick = data.len();
    let options = VtuOptions {
        encoding: [
            Encoding::Ascii,
            Encoding::Base64,
            Encoding::AppendedRaw,
            Encoding::AppendedBase64,
        ][pick % 4],
        zlib: if pick & 4 != 0 { Some(1) } else { None },
        header: if pick & 8 != 0 {
            HeaderType::UInt32
        } else {
            HeaderType::UInt64
        },
        byte_order: if pick & 16 != 0 {
            ByteOrder::BigEndian
        } else {
            ByteOrder::LittleEndian
        },
        block_size: 64,
    };
    let mut bytes = Vec::new();
    vtu::write_with(&mesh, &mut bytes, &options).expect("write to a Vec");
    let back = vtu::read(&bytes).expect("our own file reads back");
    assert_eq!(back.points(), mesh.points());
    assert_eq!(back.cells(), mesh.cells());
    assert_eq!(back.kinds(), mesh.kinds());
    assert_eq!(back.point_data(), mesh.point_data());
    assert_eq!(back.cell_data(), mesh.cell_data());
});
