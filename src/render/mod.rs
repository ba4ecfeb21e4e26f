//! Volume rendering by ray casting: the camera, the transfer function, the two sampling paths
//! (`paper` and `fast`), shading, images and the work counters.
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

pub mod accuracy;
pub mod boundary;
pub mod camera;
pub mod chords;
pub mod clip;
pub mod image;
pub mod march;
pub mod plot;
pub mod ray_faces;
pub mod raycast;
pub mod shading;
pub mod skip;
pub mod surface;
pub mod topology;
pub mod transfer;
pub mod transparency;
pub mod walk;

pub use camera::{
    Camera, CameraFrame, MatrixRays, Projection, RayGenerator, RaySource, DEFAULT_VIEW_ANGLE,
};
pub use clip::{ClipPlanes, MAX_CLIP_PLANES};
pub use image::Image;
pub use raycast::{
    default_step, Blend, Derived, Interpolation, Neighbours, NoNeighbours, RayResult,
    RenderOptions, RenderPath, RenderStats, Renderer, ScalarField, Volume, DEFAULT_MARCH_REACH,
    MAX_SAMPLES_PER_RAY,
};
pub use shading::Shading;
pub use topology::{face_neighbours, unchecked_neighbours, Topology};
pub use transfer::{
    GradientOpacity, TransferFunction, TransferTable, DEFAULT_TABLE_SIZE, GRADIENT_TABLE_SIZE,
};
