//! Resolution of a command-line `INPUT`: a mesh file (`.vtk`, `.vtu`, `.pvtu`, PLOT3D grid) or a
//! synthetic dataset `NAME[:CELLS]` such as `pump-rotor:2100000`.

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
    /// error for anything but a PLOT3D grid.
    pub fn load(&self, options: &ReadOptions) -> Result<Mesh, Error> {
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
            Input::File(path) => load_file(path, options),
        }
    }
}

fn load_file(path: &Path, options: &ReadOptions) -> Result<Mesh, Error> {
    if !path.exists() {
        return Err(Error::Invalid(format!(
            "{}: no such file, and not a dataset name (pump-inlet, pump-rotor, pump-diffuser)",
            path.display()
        )));
    }
    io::read_file(path, options)
}

/// Parses and loads an `INPUT` in one step.
pub fn load(spec: &str, options: &ReadOptions) -> Result<Mesh, Error> {
    Input::parse(spec)?.load(options)
}
