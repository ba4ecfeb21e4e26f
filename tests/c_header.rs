//! `include/cylvol.h` is what cbindgen makes of `src/ffi/` with `cbindgen.toml`: this test
//! regenerates it and fails when the committed header differs. `CYLVOL_BLESS=1 cargo test
//! --test c_header` writes the fresh header instead.

use std::path::Path;

fn generate() -> String {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let config =
        cbindgen::Config::from_file(root.join("cbindgen.toml")).expect("cbindgen.toml is readable");
    let bindings = cbindgen::Builder::new()
        .with_config(config)
        .with_src(root.join("src/ffi/mod.rs"))
        .generate()
        .expect("cbindgen generates the header");
    let mut out = Vec::new();
    bindings.write(&mut out);
    String::from_utf8(out).expect("the header is UTF-8")
}

#[test]
fn the_committed_header_is_up_to_date() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("include/cylvol.h");
    let fresh = generate();
    if std::env::var_os("CYLVOL_BLESS").is_some() {
        std::fs::write(&path, &fresh).expect("include/cylvol.h is writable");
        return;
    }
    let committed = std::fs::read_to_string(&path).unwrap_or_default();
    if committed != fresh {
        let line = committed
            .lines()
            .zip(fresh.lines())
            .position(|(a, b)| a != b)
            .map_or(committed.lines().count().min(fresh.lines().count()), |l| l)
            + 1;
        panic!(
            "include/cylvol.h is stale (first difference at line {line}); regenerate it with \
             `CYLVOL_BLESS=1 cargo test --test c_header` and commit it"
        );
    }
}

#[test]
fn the_header_has_every_name_of_the_contract() {
    let h = generate();
    for name in [
        "CYLVOL_STATUS_OK = 0",
        "CYLVOL_STATUS_PANIC = 8",
        "CYLVOL_VALUE_F64 = 1",
        "CYLVOL_INDEX_I64 = 1",
        "CYLVOL_POINT_DATA = 0",
        "CYLVOL_CELL_DATA = 1",
        "CYLVOL_STRUCTURE_CYLINDRICAL_BVH = 4",
        "CYLVOL_PATH_PAPER = 1",
        "CYLVOL_INTERPOLATION_NEAREST = 1",
        "CYLVOL_BLEND_COMPOSITE = 0",
        "CYLVOL_BLEND_MAXIMUM = 1",
        "CYLVOL_BLEND_MINIMUM = 2",
        "CYLVOL_PIXELS_RGBA_F32 = 1",
        "CYLVOL_CAMERA_MATRICES = 1",
        "typedef struct CylvolMesh CylvolMesh;",
        "typedef enum CylvolStatus {",
        "typedef struct CylvolCamera {",
        "typedef struct CylvolVolume CylvolVolume;",
        "const char *cylvol_version(void);",
        "const char *cylvol_status_message(CylvolStatus status);",
        "const char *cylvol_last_error(void);",
        "enum CylvolStatus cylvol_mesh_bounds(const struct CylvolMesh *mesh, double bounds[6]);",
        "void cylvol_volume_free(struct CylvolVolume *volume);",
        "size_t pixels_len",
    ] {
        assert!(h.contains(name), "the header lacks `{name}`");
    }
    // Every function is documented: a doc comment closes right before each declaration.
    let lines: Vec<&str> = h.lines().collect();
    for (i, l) in lines.iter().enumerate() {
        if l.contains(" cylvol_") && l.contains('(') && !l.starts_with(' ') {
            assert_eq!(lines[i - 1].trim(), "*/", "undocumented: {l}");
        }
    }
}
