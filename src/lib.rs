//! cylvol: ray casting of large unstructured hexahedral volume meshes (the CFD meshes of pumps,
//! turbines, combustors) with acceleration structures in Cartesian and cylindrical coordinates.
//! The method comes from the talk by J. Wang, M. Elshehaly and Y. Cao, *Cylindrical
//! Acceleration Structures for Large Hexahedral Volume Visualization*, IEEE Symposium on Large
//! Data Analysis and Visualization (LDAV), 2015: "the talk" in this documentation.
//!
//! The crate is organised by concern:
//! - [`accel`]: the four acceleration structures behind one point-location interface;
//! - [`mesh`]: the mesh model (points, cells as collapsed hexahedra, named data arrays) and its
//!   validation;
//! - [`geometry`]: cell geometry — the trilinear map, its Jacobian and inverse, containment,
//!   Cartesian and cylindrical bounds;
//! - [`axis`]: detection of the axis a machine turns about;
//! - [`render`]: the ray caster — camera, transfer function, the renderer and its options
//!   (the `paper` and `fast` paths, blend modes, shading, clipping planes), images and work
//!   counters;
//! - [`io`]: readers and writers for legacy VTK, VTU and PLOT3D files;
//! - [`datasets`]: the deterministic synthetic pump datasets;
//! - [`input`]: resolution of a command-line `INPUT` (a file or a synthetic dataset name);
//! - [`ffi`]: the C ABI (`include/cylvol.h`): meshes from caller arrays, volumes, rendering
//!   into caller memory.
//!
//! `docs/architecture.md` draws the way from a file to a pixel and the parts of the ray caster
//! with their contracts. The `cylvol` program (`src/main.rs`, the `cli` feature) is a user of
//! this API.
//!
//! # Rendering a mesh
//!
//! Load a mesh (a file through [`input::load`], or a synthetic dataset), find the machine's
//! axis, build a structure about it, and render with a transfer function and a camera as
//! VTK's ray caster would:
//!
//! ```
//! use cylvol::accel::{choose::auto_structure, Accel, AccelParams};
//! use cylvol::datasets::{generate, Dataset};
//! use cylvol::render::{
//!     default_step, face_neighbours, Camera, RenderOptions, Renderer, TransferFunction, Volume,
//! };
//!
//! # fn main() -> Result<(), cylvol::Error> {
//! // Or: cylvol::input::load("rotor.vtu", &cylvol::io::ReadOptions::default())?
//! let mesh = generate(Dataset::PumpRotor, 5_000)?;
//! let axis = cylvol::axis::detect(&mesh);
//! // The cylindrical BVH here: the summed area of sector bounds is below the boxes'.
//! let kind = auto_structure(&mesh, &axis);
//! let accel = Accel::build(&mesh, kind, &axis, &AccelParams::default())?;
//! let volume = Volume::new(&mesh, &accel)?;
//! let [lo, hi] = volume.scalar_range();
//! // Cool to warm, transparent over the lowest quarter of the range.
//! let transfer = TransferFunction::default_for_range(lo, hi, 0.8, 0.2);
//! let (width, height) = (64, 48);
//! let options = RenderOptions::new(width, height, default_step(&mesh));
//! // VTK's ResetCamera, then Azimuth(30), Elevation(20), Zoom(1).
//! let camera = Camera::view(mesh.bounds(), width, height, 30.0, 20.0, 1.0);
//! // The fast path walks from cell to cell through the face neighbours.
//! let neighbours = face_neighbours(&mesh, &accel);
//! let renderer = Renderer::new(&volume, &transfer, &options)?.with_topology(&neighbours);
//! let (image, stats) = renderer.render(&camera, None)?;
//! assert!(stats.samples_located > 0 && image.rgba.iter().any(|p| p[3] > 0.0));
//! // image.write_png(std::path::Path::new("rotor.png"), Some([0.0; 3]))?;
//! # Ok(())
//! # }
//! ```
#![deny(missing_docs)]

pub mod accel;
pub mod axis;
pub mod datasets;
pub mod error;
pub mod ffi;
pub mod geometry;
pub mod input;
pub mod io;
pub mod mesh;
pub mod render;
#[cfg(test)]
mod testing;

pub use error::{Error, MeshError, ReadError};
pub use mesh::{Association, CellKind, Component, DataArray, Mesh, MeshParts};

/// The version of this crate, as in `Cargo.toml`.
pub const VERSION: &str = env!("CARGO_PKG_VERSION");
