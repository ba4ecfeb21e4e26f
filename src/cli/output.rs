//! The files the commands write: checked before any work, written whole or not at all.
//!
//! [`check`] runs before a command loads or computes anything: the file name must end in an
//! extension the command writes (any case), the path must not be a folder, and its folder
//! must exist and take a new file. It neither creates nor truncates the output: the folder is
//! tried with the very partial file [`write_replacing`] will write, made and removed at once.
//! [`write_replacing`] (the library's, which [`cylvol::io::write_file`] writes meshes with)
//! writes to that sibling partial file and renames it over the target once complete, so that
//! a command that fails leaves what was at the path as it was.

use std::path::{Path, PathBuf};

use cylvol::Error;

/// The sibling file a write to `path` goes through ([`cylvol::io::partial_path`]), or an
/// error naming `option` when `path` names no file.
fn partial_path(option: &str, path: &Path) -> Result<PathBuf, Error> {
    cylvol::io::partial_path(path)
        .ok_or_else(|| Error::Invalid(format!("{option} {}: not a file name", path.display())))
}

/// The folder `path` is in (`.` for a bare name).
fn folder_of(path: &Path) -> &Path {
    match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    }
}

/// Refuses `path`, given with `option` (`-o`, `--plot`), unless its extension is one of
/// `extensions` (lower case, without the dot; compared in any case) and it can be written
/// ([`check_folder`]). `what` names what the command writes there ("a PNG image").
pub fn check(option: &str, path: &Path, what: &str, extensions: &[&str]) -> Result<(), Error> {
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    if !ext.as_deref().is_some_and(|e| extensions.contains(&e)) {
        let names: Vec<String> = extensions.iter().map(|e| format!(".{e}")).collect();
        return Err(Error::Invalid(format!(
            "{option} {}: writes {what}, so the name must end in {}",
            path.display(),
            names.join(" or ")
        )));
    }
    check_folder(option, path)
}

/// Refuses `path`, given with `option`, where a file cannot be written: a folder already has
/// that name, or its folder does not exist, is not a folder, or does not take a new file.
/// Nothing is left behind, and an existing file at `path` is not touched.
pub fn check_folder(option: &str, path: &Path) -> Result<(), Error> {
    let refuse = |why: String| Error::Invalid(format!("{option} {}: {why}", path.display()));
    if path.is_dir() {
        return Err(refuse("is a folder; give a file name".into()));
    }
    let folder = folder_of(path);
    match std::fs::metadata(folder) {
        Ok(m) if m.is_dir() => {}
        Ok(_) => return Err(refuse(format!("{} is not a folder", folder.display()))),
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
            return Err(refuse(format!(
                "the folder {} does not exist",
                folder.display()
            )))
        }
        Err(e) => return Err(refuse(format!("{}: {e}", folder.display()))),
    }
    let partial = partial_path(option, path)?;
    std::fs::File::create(&partial)
        .map_err(|e| refuse(format!("cannot write in {}: {e}", folder.display())))?;
    std::fs::remove_file(&partial)
        .map_err(|e| refuse(format!("cannot write in {}: {e}", folder.display())))
}

pub use cylvol::io::write_replacing;

#[cfg(test)]
mod tests {
    use super::*;

    fn files_in(dir: &Path) -> Vec<String> {
        let mut names: Vec<String> = std::fs::read_dir(dir)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        names.sort();
        names
    }

    #[test]
    fn outputs_are_checked_without_touching_anything() {
        let dir = tempfile::tempdir().unwrap();
        let kept = dir.path().join("kept.png");
        std::fs::write(&kept, "keep me").unwrap();
        check("-o", &kept, "a PNG image", &["png"]).unwrap();
        check("-o", &dir.path().join("NEW.PNG"), "a PNG image", &["png"]).unwrap();
        assert_eq!(std::fs::read_to_string(&kept).unwrap(), "keep me");
        assert_eq!(files_in(dir.path()), ["kept.png"]);

        let refused = |path: &Path, exts: &[&str]| {
            check("--plot", path, "an SVG plot", exts)
                .unwrap_err()
                .to_string()
        };
        let jpg = dir.path().join("out.jpg");
        assert_eq!(
            refused(&jpg, &["svg"]),
            format!(
                "--plot {}: writes an SVG plot, so the name must end in .svg",
                jpg.display()
            )
        );
        assert!(refused(&dir.path().join("noext"), &["vtk", "vtu"]).contains("in .vtk or .vtu"));
        let missing = dir.path().join("missing/p.svg");
        assert!(
            refused(&missing, &["svg"]).ends_with(&format!(
                "the folder {} does not exist",
                dir.path().join("missing").display()
            )),
            "{}",
            refused(&missing, &["svg"])
        );
        assert!(refused(&kept.join("p.svg"), &["svg"]).ends_with("kept.png is not a folder"));
        let folder = dir.path().join("folder.svg");
        std::fs::create_dir(&folder).unwrap();
        assert!(refused(&folder, &["svg"]).ends_with("is a folder; give a file name"));
        assert_eq!(files_in(dir.path()), ["folder.svg", "kept.png"]);
        assert!(!jpg.exists() && !missing.exists());
    }

    #[test]
    fn a_failed_write_leaves_the_old_file_and_no_partial() {
        let dir = tempfile::tempdir().unwrap();
        let out = dir.path().join("out.svg");
        std::fs::write(&out, "old").unwrap();
        let err = write_replacing(&out, |partial| {
            std::fs::write(partial, "half").unwrap();
            Err(Error::Io {
                path: partial.to_path_buf(),
                source: std::io::Error::other("disk full"),
            })
        })
        .unwrap_err();
        assert_eq!(err.to_string(), format!("{}: disk full", out.display()));
        assert_eq!(std::fs::read_to_string(&out).unwrap(), "old");
        assert_eq!(files_in(dir.path()), ["out.svg"]);
        write_replacing(&out, |partial| {
            assert_ne!(partial, out);
            std::fs::write(partial, "new").map_err(|source| Error::Io {
                path: partial.to_path_buf(),
                source,
            })
        })
        .unwrap();
        assert_eq!(std::fs::read_to_string(&out).unwrap(), "new");
        assert_eq!(files_in(dir.path()), ["out.svg"]);
    }
}
