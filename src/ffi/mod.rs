//! The C ABI (`include/cylvol.h`, generated from this module by cbindgen): meshes from caller
//! arrays, volumes (a mesh with its acceleration structure) and rendering into caller memory.
//!
//! # Conventions
//! - **Handles** ([`CylvolMesh`], [`CylvolVolume`]) are opaque; each has a `_free` function
//!   that accepts NULL. Every array passed in is copied: the caller may free it when the call
//!   returns.
//! - **Errors**: every fallible call returns a [`CylvolStatus`]; the detail of the last failure
//!   on the calling thread is [`cylvol_last_error`], and a volume keeps its own
//!   ([`cylvol_volume_last_error`]). NULL pointers, wrong lengths, out-of-range indices, NaN or
//!   infinite values and unknown enum values are reported, never trusted. Every exported body
//!   runs inside a panic boundary ([`status::guard`]): a panic (a bug) returns
//!   [`CylvolStatus::Panic`] instead of crossing into C.
//! - **Enums** arrive as plain integers ([`codes`]) and are checked before use.
//! - **Threads**: every function may be called concurrently on *different* handles; one handle
//!   must not be used from two threads at once (a render writes the volume's statistics and
//!   last error). Meshes are only read by [`cylvol_volume_new`], so several volumes may be
//!   built from one mesh in parallel while nobody calls [`cylvol_mesh_set_scalars`] on it.
//!   Rendering is parallel inside (rayon's global pool).
//!
//! ```
//! use cylvol::ffi::*;
//! use std::ptr::null_mut;
//! // One unit cube, a point scalar, rendered 4 × 4 from +z.
//! let points: [f64; 24] = [0., 0., 0., 1., 0., 0., 1., 1., 0., 0., 1., 0.,
//!                          0., 0., 1., 1., 0., 1., 1., 1., 1., 0., 1., 1.];
//! let (offsets, conn, types) = ([0i64, 8], [0i64, 1, 2, 3, 4, 5, 6, 7], [12u8]);
//! let mut mesh = null_mut();
//! unsafe {
//!     let s = cylvol_mesh_new(points.as_ptr().cast(), CylvolValueType::F64.into(), 8,
//!         offsets.as_ptr().cast(), conn.as_ptr().cast(), CylvolIndexType::I64.into(), 8,
//!         types.as_ptr(), 1, &mut mesh);
//!     assert_eq!(s, CylvolStatus::Ok);
//!     let values = [0.0f32, 1., 2., 3., 4., 5., 6., 7.];
//!     cylvol_mesh_set_scalars(mesh, c"p".as_ptr(), CylvolAssociation::POINT_DATA.into(),
//!         values.as_ptr().cast(), CylvolValueType::F32.into(), 8, 1, 0);
//!     let mut volume = null_mut();
//!     assert_eq!(cylvol_volume_new(mesh, std::ptr::null(), &mut volume), CylvolStatus::Ok);
//!     cylvol_mesh_free(mesh);
//!     let mut camera = CylvolCamera::default();
//!     camera.eye = [0.5, 0.5, 5.0];
//!     camera.focal_point = [0.5, 0.5, 0.5];
//!     let (rgb, opacity) = ([0f32, 0., 1., 1., 0., 0.], [0.5f32, 0.5]);
//!     let transfer = CylvolTransfer {
//!         rgb: rgb.as_ptr(), n_color: 2, opacity: opacity.as_ptr(), n_opacity: 2,
//!         range: [0.0, 7.0], unit_distance: 1.0,
//!         gradient_opacity: std::ptr::null(), n_gradient_opacity: 0, gradient_range: [0.0; 2],
//!     };
//!     let mut params = CylvolRenderParams::default();
//!     (params.width, params.height) = (4, 4);
//!     let mut pixels = vec![0u8; 4 * 4 * 4];
//!     let s = cylvol_render(volume, &camera, &transfer, &params, std::ptr::null(),
//!         null_mut(), CylvolPixelFormat::RGBA8.into(), pixels.as_mut_ptr().cast(), pixels.len());
//!     assert_eq!(s, CylvolStatus::Ok);
//!     cylvol_volume_free(volume);
//! }
//! ```

// The modules in the order of the header (cbindgen follows it).
pub mod status;

pub mod codes;

pub mod arrays;

pub mod mesh;

pub mod volume;

pub mod camera;

pub mod render;

pub use camera::{cylvol_camera_default, CylvolCamera};
pub use codes::{
    AssociationCode, BlendCode, CameraModeCode, Code, CylvolAssociation, CylvolBlend,
    CylvolCameraMode, CylvolIndexType, CylvolInterpolation, CylvolPath, CylvolPixelFormat,
    CylvolStructure, CylvolValueType, IndexTypeCode, InterpolationCode, PathCode, PixelFormatCode,
    StructureCode, ValueTypeCode,
};
pub use mesh::{
    cylvol_mesh_bounds, cylvol_mesh_counts, cylvol_mesh_free, cylvol_mesh_new,
    cylvol_mesh_scalar_range, cylvol_mesh_set_scalars, CylvolMesh,
};
pub use render::{
    cylvol_render, cylvol_render_params_default, cylvol_volume_render_stats, CylvolRenderParams,
    CylvolRenderStats, CylvolTransfer,
};
pub use status::{
    cylvol_last_error, cylvol_status_message, cylvol_version, CylvolStatus, StatusCode,
};
pub use volume::{
    cylvol_build_params_default, cylvol_volume_build_stats, cylvol_volume_default_step,
    cylvol_volume_free, cylvol_volume_last_error, cylvol_volume_new, cylvol_volume_scalar_range,
    cylvol_volume_set_scalars, CylvolBuildParams, CylvolBuildStats, CylvolVolume,
};
