//! Volume rendering by ray casting: the camera, the transfer function, the renderer and its
//! options, images and the work counters.
//!
//! A [`Renderer`] casts each ray of an image ([`RaySource`]: a [`Camera`]'s, or a view and
//! projection matrix's) through a [`Volume`] (a mesh, its structure and its scalar) in one
//! short loop over parts with one job each: a *locator* says where the next sample lies
//! (through the structure on the `paper` path, by marching from cell to cell on the `fast`
//! one), a *boundary* part says where the ray crosses the mesh's boundary, and an
//! *accumulator* makes the pixel of the samples (front-to-back compositing, or a maximum- or
//! minimum-intensity projection). `docs/architecture.md` draws the whole way from a file to a
//! pixel.
//!
//! ```
//! use cylvol::accel::{Accel, AccelParams, StructureKind};
//! use cylvol::axis::Axis;
//! use cylvol::render::{default_step, Camera, Renderer, RenderOptions, TransferFunction, Volume};
//! let mesh = cylvol::datasets::generate(cylvol::datasets::Dataset::PumpInlet, 2000).unwrap();
//! let accel = Accel::build(&mesh, StructureKind::CartBvh, &Axis::Z, &AccelParams::default()).unwrap();
//! let volume = Volume::new(&mesh, &accel).unwrap();
//! let [lo, hi] = volume.scalar_range();
//! let tf = TransferFunction::default_for_range(lo, hi, 0.3, 0.1);
//! let options = RenderOptions::new(16, 16, default_step(&mesh));
//! let renderer = Renderer::new(&volume, &tf, &options).unwrap();
//! let camera = Camera::view(mesh.bounds(), 16, 16, 30.0, 20.0, 1.0);
//! let (image, stats) = renderer.render(&camera, None).unwrap();
//! assert_eq!(image.rgba.len(), 256);
//! assert_eq!(stats.rays, 256);
//! ```

mod accumulate;
mod boundary;
mod camera;
mod cast;
mod clip;
mod faces;
mod field;
mod frame;
mod image;
mod locate;
mod options;
mod periodic;
mod ray;
mod renderer;
mod shading;
mod stats;
mod transfer;
mod transparency;
mod walk;

pub use accumulate::RayResult;
pub use boundary::search::BISECTIONS;
pub use boundary::surface::BoundarySurface;
pub use camera::{
    band_projection, Camera, CameraFrame, MatrixRays, Projection, RayGenerator, RaySource,
    DEFAULT_VIEW_ANGLE,
};
pub use clip::{ClipPlanes, MAX_CLIP_PLANES};
pub use faces::{face_neighbours, unchecked_neighbours, Topology};
pub use field::{default_step, ScalarField, Volume};
pub use image::Image;
pub use options::{
    Blend, Interpolation, RenderOptions, RenderPath, DEFAULT_MARCH_REACH, MAX_SAMPLES_PER_RAY,
};
pub use periodic::Copies;
pub use renderer::{Derived, Renderer};
pub use shading::Shading;
pub use stats::RenderStats;
pub use transfer::{
    GradientOpacity, TransferFunction, TransferTable, DEFAULT_TABLE_SIZE, GRADIENT_TABLE_SIZE,
    VTK_MAPPER_TABLE_ENTRIES,
};
pub use walk::{Neighbours, NoNeighbours};
