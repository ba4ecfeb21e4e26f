//! Volume handles: a mesh (shared with its handle, never copied for the build) with the
//! acceleration structure built over it, the face neighbours the fast path walks, the
//! statistics of the build and of the last render, and the detail of the handle's last
//! failure.

use std::ffi::{c_char, c_void, CString};
use std::sync::Arc;
use std::time::Instant;

use glam::DVec3;

use super::arrays;
use super::codes::{AssociationCode, Code, CylvolStructure, StructureCode, ValueTypeCode};
use super::mesh::{read_scalars, replace_scalars, CylvolMesh, GivenScalars};
use super::status::{self, c_string, CylvolStatus, Failure};
use crate::accel::choose::{cylindrical_area_ratio, structure_for_ratio};
use crate::accel::{Accel, AccelParams, BvhParams, GridParams, StructureKind};
use crate::axis::{detect_with_report, Axis};
use crate::render::Topology;
use crate::render::{Derived, RenderStats, ScalarField};
use crate::Mesh;

/// How to build a volume's structure.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CylvolBuildParams {
    /// The structure; AUTO picks it from the mesh.
    pub structure: StructureCode,
    /// Nonzero: detect the axis; zero: use `axis_origin` and `axis_direction`.
    pub axis_auto: i32,
    /// A point on the axis (when given).
    pub axis_origin: [f64; 3],
    /// The axis direction, any non-zero length (when given).
    pub axis_direction: [f64; 3],
    /// 0 default, 1 fast build, 2 compact (grids) / fine (BVHs), 3 the talk's grid sizes
    /// (grids; BVHs as 0), 4 fine grids (fewest cells tested, about ten times the memory; BVHs
    /// as 2).
    pub preset: i32,
}

impl Default for CylvolBuildParams {
    /// AUTO, axis detected, preset 0.
    fn default() -> Self {
        CylvolBuildParams {
            structure: CylvolStructure::Auto.into(),
            axis_auto: 1,
            axis_origin: [0.0; 3],
            axis_direction: [0.0, 0.0, 1.0],
            preset: 0,
        }
    }
}

/// The figures of a volume's build.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CylvolBuildStats {
    /// The structure built (never AUTO).
    pub structure: CylvolStructure,
    /// Wall time of the whole build in seconds (axis detection, structure, face neighbours,
    /// default step).
    pub build_seconds: f64,
    /// Heap bytes of the structure.
    pub bytes: u64,
    /// Cells of the mesh.
    pub cells: u64,
    /// A point on the axis used (detected or given).
    pub axis_origin: [f64; 3],
    /// The axis direction used (unit).
    pub axis_direction: [f64; 3],
    /// Whether the detected axis was clear (1 when the axis was given).
    pub axis_clear: i32,
    /// Cylindrical ÷ Cartesian bound surface area measured by AUTO (0 if not measured).
    pub area_ratio: f64,
}

/// An opaque volume: the mesh (shared with the mesh handle it was built from, until either
/// changes its scalars) and the structure built over it.
pub struct CylvolVolume {
    pub(crate) mesh: Arc<Mesh>,
    pub(crate) accel: Accel,
    pub(crate) neighbours: Topology,
    /// The active scalar gathered for rendering (`None` while the mesh has none), kept
    /// across renders and gathered again when the scalars change.
    pub(crate) field: Option<ScalarField>,
    /// What the last render derived from its transfer table and this volume (transparent
    /// cells, visible nodes, the nodes' scalar ranges), taken over by the next render of the
    /// same table; dropped when the scalars change.
    pub(crate) derived: Option<Derived>,
    pub(crate) default_step: f64,
    pub(crate) build: CylvolBuildStats,
    /// The last successful render's time in seconds and counters (zeros before the first).
    pub(crate) last_render: (f64, RenderStats),
    pub(crate) last_error: CString,
}

impl CylvolVolume {
    /// The mesh.
    pub(crate) fn mesh(&self) -> &Mesh {
        &self.mesh
    }
}

/// Runs `body` on the volume behind `volume` inside the panic boundary, keeping a failure's
/// detail in the volume as well.
///
/// # Safety
/// `volume` NULL or a live handle used by this thread only.
pub(crate) unsafe fn on_volume(
    function: &str,
    volume: *mut CylvolVolume,
    body: impl FnOnce(&mut CylvolVolume) -> Result<(), Failure>,
) -> CylvolStatus {
    match status::guard(function, || {
        // SAFETY: the caller vouches for the handle.
        let v = unsafe { arrays::handle_mut(volume, "volume")? };
        body(v)
    }) {
        Ok(()) => CylvolStatus::Ok,
        Err(f) => {
            // SAFETY: as above; the body's borrow has ended.
            if let Some(v) = unsafe { volume.as_mut() } {
                v.last_error = c_string(&f.detail);
            }
            f.status
        }
    }
}

fn accel_params(preset: i32) -> Result<AccelParams, Failure> {
    let (grid, bvh) = match preset {
        0 => (GridParams::DEFAULT, BvhParams::BALANCED),
        1 => (GridParams::DEFAULT, BvhParams::FAST_BUILD),
        2 => (GridParams::COMPACT, BvhParams::FINE),
        3 => (GridParams::PAPER, BvhParams::BALANCED),
        4 => (GridParams::FAST, BvhParams::FINE),
        p => {
            return Err(Failure::invalid(format!(
                "params->preset = {p} (must be 0 to 4)"
            )))
        }
    };
    Ok(AccelParams {
        grid,
        bvh,
        ..AccelParams::default()
    })
}

fn to_c(kind: StructureKind) -> CylvolStructure {
    match kind {
        StructureKind::CartGrid => CylvolStructure::CartesianGrid,
        StructureKind::CylGrid => CylvolStructure::CylindricalGrid,
        StructureKind::CartBvh => CylvolStructure::CartesianBvh,
        StructureKind::CylBvh => CylvolStructure::CylindricalBvh,
    }
}

/// Builds a volume over `mesh` (shared, not copied) as `params` say.
pub(crate) fn build(mesh: Arc<Mesh>, params: &CylvolBuildParams) -> Result<CylvolVolume, Failure> {
    let started = Instant::now();
    let structure = params.structure.decode("params->structure")?;
    let accel_params = accel_params(params.preset)?;
    // The face neighbours and their surface, the default step and the scalars need no
    // structure: made alongside it, so that each fills the cores the other's sequential
    // parts leave idle.
    let (built, (mut neighbours, default_step, field)) = rayon::join(
        || structure_of(&mesh, structure, params, &accel_params),
        || {
            (
                crate::render::unchecked_neighbours(&mesh),
                crate::render::default_step(&mesh),
                ScalarField::gather(&mesh).ok(),
            )
        },
    );
    let (accel, axis, clear, ratio) = built?;
    neighbours.check_boundary(&mesh, &accel);
    let build = CylvolBuildStats {
        structure: to_c(accel.kind()),
        build_seconds: started.elapsed().as_secs_f64(),
        bytes: accel.stats().bytes() as u64,
        cells: mesh.cell_count() as u64,
        axis_origin: axis.origin.to_array(),
        axis_direction: axis.direction.to_array(),
        axis_clear: i32::from(clear),
        area_ratio: ratio,
    };
    Ok(CylvolVolume {
        mesh,
        accel,
        neighbours,
        field,
        derived: None,
        default_step,
        build,
        last_render: (0.0, RenderStats::default()),
        last_error: CString::default(),
    })
}

/// The structure `params` ask for, built (AUTO's choice made), with the axis used (detected
/// or given), whether it was clear, and the area ratio AUTO measured (0 if none).
fn structure_of(
    mesh: &Mesh,
    structure: CylvolStructure,
    params: &CylvolBuildParams,
    accel_params: &AccelParams,
) -> Result<(Accel, Axis, bool, f64), Failure> {
    let (axis, clear) = if params.axis_auto != 0 {
        let d = detect_with_report(mesh);
        (d.axis, d.clear)
    } else {
        arrays::finite(&params.axis_origin, "params->axis_origin")?;
        arrays::finite(&params.axis_direction, "params->axis_direction")?;
        let axis = Axis::new(
            DVec3::from_array(params.axis_origin),
            DVec3::from_array(params.axis_direction),
        )
        .map_err(|e| Failure::invalid(format!("params: {e}")))?;
        (axis, true)
    };
    let (kind, ratio) = match structure {
        CylvolStructure::Auto => {
            let ratio = cylindrical_area_ratio(mesh, &axis);
            (structure_for_ratio(ratio), ratio.unwrap_or(0.0))
        }
        CylvolStructure::CartesianGrid => (StructureKind::CartGrid, 0.0),
        CylvolStructure::CylindricalGrid => (StructureKind::CylGrid, 0.0),
        CylvolStructure::CartesianBvh => (StructureKind::CartBvh, 0.0),
        CylvolStructure::CylindricalBvh => (StructureKind::CylBvh, 0.0),
    };
    let accel = Accel::build(mesh, kind, &axis, accel_params)?;
    Ok((accel, axis, clear, ratio))
}

/// Fills `params` with the defaults: AUTO, axis detected, preset 0.
///
/// # Safety
/// `params` NULL (nothing happens) or valid for writing a `CylvolBuildParams`.
#[no_mangle]
pub unsafe extern "C" fn cylvol_build_params_default(params: *mut CylvolBuildParams) {
    let _ = status::guard("cylvol_build_params_default", || {
        // SAFETY: the caller vouches for the pointer.
        unsafe { arrays::write(params, CylvolBuildParams::default(), "params") }
    });
}

/// Builds the structure over the mesh's current cells and active scalars into a new volume,
/// which keeps them: the mesh may be freed afterwards, and later changes to it do not affect
/// the volume. (The volume shares the mesh's memory rather than copying it; whichever of the
/// two changes its scalars first gets a copy then.) `params` NULL means the defaults. A mesh without scalars makes a
/// volume that renders only after [`cylvol_volume_set_scalars`]. On failure `*out` is NULL.
///
/// Errors: NULL_POINTER (`mesh`, `out`), INVALID_ARGUMENT (a bad structure or preset value, a
/// given axis that is not finite or has zero direction).
///
/// # Safety
/// `mesh` a live handle nobody changes during the call; `params` NULL or readable; `out`
/// valid for writing a pointer.
#[no_mangle]
pub unsafe extern "C" fn cylvol_volume_new(
    mesh: *const CylvolMesh,
    params: *const CylvolBuildParams,
    out: *mut *mut CylvolVolume,
) -> CylvolStatus {
    status::status("cylvol_volume_new", || {
        // SAFETY: the caller vouches for the pointers.
        unsafe { arrays::write(out, std::ptr::null_mut(), "out")? };
        let m = unsafe { arrays::handle(mesh, "mesh")? }.shared();
        let params = unsafe { params.as_ref() }.copied().unwrap_or_default();
        let volume = build(m, &params)?;
        // SAFETY: checked non-NULL and aligned above.
        unsafe { out.write(Box::into_raw(Box::new(volume))) };
        Ok(())
    })
}

/// Frees a volume (NULL is fine).
///
/// # Safety
/// `volume` NULL or a live handle from [`cylvol_volume_new`], not used afterwards.
#[no_mangle]
pub unsafe extern "C" fn cylvol_volume_free(volume: *mut CylvolVolume) {
    // SAFETY: the caller vouches for the handle.
    unsafe { arrays::free_handle("cylvol_volume_free", volume) }
}

/// Replaces the active scalars of the volume without rebuilding the structure (the same rules
/// as [`super::cylvol_mesh_set_scalars`]).
///
/// # Safety
/// `volume` a live handle; the arrays as for [`super::cylvol_mesh_set_scalars`].
#[no_mangle]
pub unsafe extern "C" fn cylvol_volume_set_scalars(
    volume: *mut CylvolVolume,
    name: *const c_char,
    association: AssociationCode,
    values: *const c_void,
    value_type: ValueTypeCode,
    n_tuples: usize,
    n_components: usize,
    component: i32,
) -> CylvolStatus {
    // SAFETY: the caller vouches for the handle and arrays.
    unsafe {
        on_volume("cylvol_volume_set_scalars", volume, |v| {
            let m = v.mesh();
            let counts = (m.point_count(), m.cell_count());
            let given = GivenScalars {
                name,
                association,
                values,
                value_type,
                n_tuples,
                n_components,
                component,
            };
            let scalars = read_scalars(given, counts)?;
            replace_scalars(&mut v.mesh, scalars)?;
            v.field = ScalarField::gather(v.mesh()).ok();
            v.derived = None;
            Ok(())
        })
    }
}

/// The detail of the volume's last failure, or `""`. Valid until the next call on the volume.
///
/// # Safety
/// `volume` NULL or a live handle.
#[no_mangle]
pub unsafe extern "C" fn cylvol_volume_last_error(volume: *const CylvolVolume) -> *const c_char {
    status::guard("cylvol_volume_last_error", || {
        // SAFETY: the caller vouches for the handle.
        Ok(match unsafe { volume.as_ref() } {
            Some(v) => v.last_error.as_ptr(),
            None => c"cylvol_volume_last_error: volume is NULL".as_ptr(),
        })
    })
    .unwrap_or(c"".as_ptr())
}

/// The figures of the volume's build.
///
/// # Safety
/// `volume` a live handle; `stats` valid for writing.
#[no_mangle]
pub unsafe extern "C" fn cylvol_volume_build_stats(
    volume: *const CylvolVolume,
    stats: *mut CylvolBuildStats,
) -> CylvolStatus {
    status::status("cylvol_volume_build_stats", || {
        // SAFETY: the caller vouches for the pointers.
        let v = unsafe { arrays::handle(volume, "volume")? };
        unsafe { arrays::write(stats, v.build, "stats") }
    })
}

/// The default step the renderer uses for this volume (half the mean cell size).
///
/// # Safety
/// `volume` a live handle; `step` valid for writing.
#[no_mangle]
pub unsafe extern "C" fn cylvol_volume_default_step(
    volume: *const CylvolVolume,
    step: *mut f64,
) -> CylvolStatus {
    status::status("cylvol_volume_default_step", || {
        // SAFETY: the caller vouches for the pointers.
        let v = unsafe { arrays::handle(volume, "volume")? };
        unsafe { arrays::write(step, v.default_step, "step") }
    })
}
