//! cylvol: ray casting of large unstructured hexahedral volume meshes (the CFD meshes of pumps,
//! turbines, combustors) with acceleration structures in Cartesian and cylindrical coordinates.
//!
//! The crate is organised by concern:
//! - [`accel`]: the four acceleration structures behind one point-location interface;
//! - [`mesh`]: the mesh model (points, cells as collapsed hexahedra, named data arrays) and its
//!   validation;
//! - [`geometry`]: cell geometry — the trilinear map, its Jacobian and inverse, containment,
//!   Cartesian and cylindrical bounds;
//! - [`axis`]: detection of the axis a machine turns about;
//! - [`render`]: the ray caster — camera, transfer function, the `paper` and `fast` paths,
//!   shading, images;
//! - [`io`]: readers and writers for legacy VTK, VTU and PLOT3D files;
//! - [`datasets`]: the deterministic synthetic pump datasets;
//! - [`input`]: resolution of a command-line `INPUT` (a file or a synthetic dataset name);
//! - [`ffi`]: the C ABI (`include/cylvol.h`): meshes from caller arrays, volumes, rendering
//!   into caller memory.
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
