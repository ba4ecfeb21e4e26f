//! Fuzz target: the legacy reader must return a mesh or an error for any bytes, never panic;
//! and reading the bytes from a file (a BINARY file block by block as it is parsed) must give
//! the same mesh, or an error where the bytes give one.
#![no_main]

use std::path::PathBuf;
use std::sync::OnceLock;

fn scratch() -> &'static PathBuf {
    static PATH: OnceLock<PathBuf> = OnceLock::new();
    PATH.get_or_init(|| {
        std::env::temp_dir().join(format!("cylvol-fuzz-legacy-{}.vtk", std::process::id()))
    })
}

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    let from_bytes = cylvol::io::legacy::read(data);
    std::fs::write(scratch(), data).expect("scratch file");
    let from_file = cylvol::io::legacy::read_file(scratch());
    match (from_bytes, from_file) {
        (Ok(a), Ok(b)) => assert!(a == b, "the file read gives another mesh"),
        (Err(_), Err(_)) => {}
        (a, b) => panic!("bytes: {:?}, file: {:?}", a.map(|_| ()), b.map(|_| ())),
    }
});
