//! Fuzz target: the PLOT3D reader must return a mesh or an error for any grid and Q bytes,
//! never panic. The first two input bytes (little-endian, modulo the rest's length + 1) say
//! where the rest splits into a grid part and a Q part; the whole rest is also read as a grid
//! alone. Seeds: `fuzz/seeds/read_plot3d/` (tiny 2×2×2 grids with Q files in several layouts).
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    if let [a, b, rest @ ..] = data {
        let at = usize::from(u16::from_le_bytes([*a, *b])) % (rest.len() + 1);
        let (xyz, q) = rest.split_at(at);
        let _ = cylvol::io::plot3d::read(xyz, Some(q));
        let _ = cylvol::io::plot3d::read(rest, None);
    }
});
