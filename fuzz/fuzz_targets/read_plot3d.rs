//! Fuzz target: the PLOT3D reader must return a mesh or an error for any grid and Q bytes,
//! never panic. The first input byte splits the data into a grid part and a Q part.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    if let Some((&split, rest)) = data.split_first() {
        let at = (split as usize * rest.len()) / 256;
        let (xyz, q) = rest.split_at(at);
        let _ = cylvol::io::plot3d::read(xyz, Some(q));
        let _ = cylvol::io::plot3d::read(rest, None);
    }
});
