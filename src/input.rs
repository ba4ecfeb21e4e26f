//! Resolution of a command-line `INPUT`: a mesh file (`.vtk`, `.vtu`, `.pvtu`, `.vts`, `.pvts`,
//! PLOT3D grid) or a synthetic dataset `NAME[:CELLS]` such as `pump-rotor:2100000`. Loading
//! one says on standard error what a user should know (a PLOT3D grid without a Q file, what
//! the reader did beyond reading, arrays holding NaN or infinite values), or gives it to a
//! caller's log ([`Input::load_logged`]).

use std::path::{Path, PathBuf};

use crate::datasets::{self, Dataset};
use crate::io::{self, ReadOptions};
use crate::{Error, Mesh};

/// What an `INPUT` argument names.
#[derive(Clone, Debug, PartialEq)]
pub enum Input {
    /// A synthetic dataset and its requested cell count.
    Synthetic(Dataset, usize),
    /// A mesh file.
    File(PathBuf),
}

impl Input {
    /// Parses an `INPUT`: a dataset name (optionally `:CELLS`) or else a file path.
    pub fn parse(spec: &str) -> Result<Input, Error> {
        Ok(match datasets::parse_spec(spec)? {
            Some((dataset, cells)) => Input::Synthetic(dataset, cells),
            None => Input::File(PathBuf::from(spec)),
        })
    }

    /// A short label for reports: the dataset name, or the file name.
    pub fn label(&self) -> String {
        match self {
            Input::Synthetic(d, _) => d.name().to_string(),
            Input::File(p) => p
                .file_name()
                .map(|n| n.to_string_lossy().into_owned())
                .unwrap_or_else(|| p.display().to_string()),
        }
    }

    /// Loads the mesh: generates the dataset or reads the file. A Q file in `options` is an
    /// error for anything but a PLOT3D grid. Says nothing; [`Input::load_logged`] gives the
    /// notes a user should see.
    pub fn load(&self, options: &ReadOptions) -> Result<Mesh, Error> {
        self.load_logged(options, &mut |_| {})
    }

    /// [`Input::load`], giving `log` what a user should know of the load (the `cylvol`
    /// program writes it to standard error): a PLOT3D grid with no Q file given and none
    /// beside it (so no arrays to render) says so, and which names were looked for; what the
    /// reader did beyond reading ([`io::read_file_logged`]: bytes after a PLOT3D file's data
    /// ignored, PLOT3D grids joined); each array holding NaN or infinite values is named
    /// with how many (it is kept, but cannot be drawn: [`Mesh::drawn_scalars`]).
    ///
    /// ```
    /// use cylvol::input::Input;
    /// let dir = tempfile::tempdir().unwrap();
    /// let grid = dir.path().join("ductxyz.bin");
    /// // A big-endian 2×2×2 grid, no Q file beside it.
    /// let mut xyz: Vec<u8> = [2i32, 2, 2].iter().flat_map(|v| v.to_be_bytes()).collect();
    /// for axis in 0..3 {
    ///     xyz.extend((0..8).flat_map(|n| (((n >> axis) & 1) as f32).to_be_bytes()));
    /// }
    /// std::fs::write(&grid, &xyz).unwrap();
    /// let mut notes = Vec::new();
    /// let input = Input::parse(grid.to_str().unwrap()).unwrap();
    /// let mesh = input.load_logged(&Default::default(), &mut |n| notes.push(n)).unwrap();
    /// assert!(mesh.point_data().is_empty());
    /// assert!(notes[0].starts_with("no PLOT3D Q file found beside"), "{notes:?}");
    /// assert!(notes[0].contains("ductq.bin"), "{notes:?}");
    /// ```
    pub fn load_logged(
        &self,
        options: &ReadOptions,
        log: &mut dyn FnMut(String),
    ) -> Result<Mesh, Error> {
        let mesh = self.load_mesh(options, log)?;
        for array in mesh.non_finite_arrays() {
            log(format!("{array}: it is kept, but cannot be drawn"));
        }
        Ok(mesh)
    }

    fn load_mesh(&self, options: &ReadOptions, log: &mut dyn FnMut(String)) -> Result<Mesh, Error> {
        match self {
            Input::Synthetic(dataset, cells) => {
                if let Some(q) = &options.q_file {
                    return Err(Error::Invalid(format!(
                        "{}: a PLOT3D Q file goes with a PLOT3D grid, but {} is a synthetic \
                         dataset",
                        q.display(),
                        dataset.name()
                    )));
                }
                datasets::generate(*dataset, *cells)
            }
            Input::File(path) => load_file(path, options, log),
        }
    }
}

fn load_file(
    path: &Path,
    options: &ReadOptions,
    log: &mut dyn FnMut(String),
) -> Result<Mesh, Error> {
    if !path.exists() {
        return Err(Error::Invalid(format!(
            "{}: no such file, and not a dataset name (pump-inlet, pump-rotor, pump-diffuser)",
            path.display()
        )));
    }
    if options.q_file.is_none() && io::Format::from_path(path) == Some(io::Format::Plot3d) {
        let names = io::plot3d_q_names(path);
        match names.iter().find(|p| p.is_file()) {
            // Read the file found here, so what was looked for is what is read.
            Some(q) => {
                let options = ReadOptions {
                    q_file: Some(q.clone()),
                };
                return io::read_file_logged(path, &options, log);
            }
            None => {
                let looked_for: Vec<String> = names
                    .iter()
                    .filter_map(|p| p.file_name())
                    .map(|n| n.to_string_lossy().into_owned())
                    .collect();
                let looked = if looked_for.is_empty() {
                    "no name to look for: the grid's name is not UTF-8".to_string()
                } else {
                    format!("looked for {}", looked_for.join(", "))
                };
                log(format!(
                    "no PLOT3D Q file found beside {} ({looked}): the mesh has no point arrays \
                     to render; give its Q file with --q FILE",
                    path.display()
                ));
            }
        }
    }
    io::read_file_logged(path, options, log)
}

/// Parses and loads an `INPUT` in one step.
pub fn load(spec: &str, options: &ReadOptions) -> Result<Mesh, Error> {
    Input::parse(spec)?.load(options)
}
