//! Fuzz target: the vtu reader must return a mesh or an error for any bytes, never panic.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    let _ = cylvol::io::vtu::read(data);
});
