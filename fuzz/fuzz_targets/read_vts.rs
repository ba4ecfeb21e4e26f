//! Fuzz target: the VTS reader must return a mesh or an error for any bytes, never panic.
//! Seeds: `fuzz/seeds/read_vts/` (small grids VTK wrote: blanked, in three encodings, and in
//! two pieces with a ghost level).
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    let _ = cylvol::io::vts::read(data);
});
