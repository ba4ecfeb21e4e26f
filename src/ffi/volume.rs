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
use crate::axis::periodic::{self, PeriodicRequest};
use crate::axis::{detect_with_report, Axis};
use crate::render::{Copies, Topology};
use crate::render::{Derived, RenderStats, ScalarField, Volume};
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
    /// Periodic copies: 0 draws the mesh as it is; -1 finds whether the mesh is a
    /// rotationally periodic sector about the axis and how many copies close the wheel (the
    /// build fails, saying why, where it is not); N ≥ 1 draws N copies, each the sector
    /// turned by 360°/N (the sector's span must be 360°/N). Added after the fields above:
    /// fill the struct with cylvol_build_params_default() first.
    pub periodic: i32,
    /// With `periodic`: draw copies `copies_first` to `copies_end − 1` only; both 0 draw
    /// every copy. A range outside 0..N is an error.
    pub copies_first: i32,
    /// See `copies_first`.
    pub copies_end: i32,
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
            periodic: 0,
            copies_first: 0,
            copies_end: 0,
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
    /// The copies that close the wheel where periodic copies are drawn (0 where not).
    pub periodic_copies: i32,
    /// The first copy drawn.
    pub copies_first: i32,
    /// One past the last copy drawn.
    pub copies_end: i32,
    /// The sector's angular span in degrees (0 where no copies are drawn).
    pub periodic_span_degrees: f64,
    /// The side faces that land on the other side, turned by 360°/N, and are joined.
    pub periodic_matched_faces: u64,
    /// The worst distance between a side's point, turned, and the other side's, as a fraction
    /// of the cell edge there.
    pub periodic_worst_mismatch: f64,
    /// The box of what is drawn, `[xmin, xmax, ymin, ymax, zmin, zmax]` (VTK's order): the
    /// mesh's, or the cylinder about the axis that holds the copies drawn.
    pub bounds: [f64; 6],
}

impl Default for CylvolBuildStats {
    /// Zeros, the structure AUTO (what a build never reports).
    fn default() -> Self {
        CylvolBuildStats {
            structure: CylvolStructure::Auto,
            build_seconds: 0.0,
            bytes: 0,
            cells: 0,
            axis_origin: [0.0; 3],
            axis_direction: [0.0; 3],
            axis_clear: 0,
            area_ratio: 0.0,
            periodic_copies: 0,
            copies_first: 0,
            copies_end: 0,
            periodic_span_degrees: 0.0,
            periodic_matched_faces: 0,
            periodic_worst_mismatch: 0.0,
            bounds: [0.0; 6],
        }
    }
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
    /// The periodic copies drawn instead of the mesh alone, if any.
    pub(crate) copies: Option<Copies>,
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
    let copies = periodic_copies(&mesh, &axis, params)?;
    if let Some(c) = &copies {
        neighbours = neighbours.with_periodic_sides(&mesh, c.periodicity()).0;
    }
    let found = copies.as_ref().map(|c| *c.periodicity());
    let (first, end) = copies.as_ref().map_or((0, 0), Copies::range);
    let build = CylvolBuildStats {
        structure: to_c(accel.kind()),
        build_seconds: started.elapsed().as_secs_f64(),
        bytes: accel.stats().bytes() as u64,
        cells: mesh.cell_count() as u64,
        axis_origin: axis.origin.to_array(),
        axis_direction: axis.direction.to_array(),
        axis_clear: i32::from(clear),
        area_ratio: ratio,
        periodic_copies: found.map_or(0, |p| p.copies as i32),
        copies_first: first as i32,
        copies_end: end as i32,
        periodic_span_degrees: found.map_or(0.0, |p| p.span_degrees()),
        periodic_matched_faces: found.map_or(0, |p| p.matched_faces as u64),
        periodic_worst_mismatch: found.map_or(0.0, |p| p.worst_mismatch),
        bounds: copies.as_ref().map_or(mesh.bounds(), Copies::bounds),
    };
    Ok(CylvolVolume {
        mesh,
        accel,
        neighbours,
        field,
        derived: None,
        default_step,
        copies,
        build,
        last_render: (0.0, RenderStats::default()),
        last_error: CString::default(),
    })
}

/// The periodic copies `params` ask for about `axis`: found, checked, or none.
fn periodic_copies(
    mesh: &Mesh,
    axis: &Axis,
    params: &CylvolBuildParams,
) -> Result<Option<Copies>, Failure> {
    let request = match params.periodic {
        0 => PeriodicRequest::Off,
        -1 => PeriodicRequest::Auto,
        n if n >= 1 => PeriodicRequest::Copies(n as u32),
        n => {
            return Err(Failure::invalid(format!(
                "params->periodic = {n} (0 off, -1 auto, or the number of copies)"
            )))
        }
    };
    let range = match (params.copies_first, params.copies_end) {
        (0, 0) => None,
        (a, b) if a >= 0 && b >= 0 => Some((a as u32, b as u32)),
        (a, b) => {
            return Err(Failure::invalid(format!(
                "params->copies_first, copies_end = {a}, {b} (copies are numbered from 0)"
            )))
        }
    };
    if request == PeriodicRequest::Off {
        if range.is_some() {
            return Err(Failure::invalid(
                "params->copies_first and copies_end need params->periodic (-1 auto or N)",
            ));
        }
        return Ok(None);
    }
    let found = periodic::resolve(mesh, axis, request)
        .map_err(|e| Failure::invalid(format!("periodic copies: {e}")))?;
    found
        .map(|p| Copies::new(mesh, p, range))
        .transpose()
        .map_err(|e| Failure::invalid(format!("periodic copies: {e}")))
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

/// `[min, max]` of what the volume draws, into `range[0]` and `range[1]`: the active scalar's
/// range, or where periodic copies draw a vector's component (which turns with each copy),
/// its range over every copy drawn. Transfer tables made for the volume should span it.
///
/// Errors: NULL_POINTER (`volume`, `range`), NO_SCALARS (the volume has no scalars).
///
/// # Safety
/// `volume` a live handle; `range` valid for writing two doubles.
#[no_mangle]
pub unsafe extern "C" fn cylvol_volume_scalar_range(
    volume: *mut CylvolVolume,
    range: *mut f64,
) -> CylvolStatus {
    // SAFETY: the caller vouches for the pointers.
    unsafe {
        on_volume("cylvol_volume_scalar_range", volume, |v| {
            let out = arrays::slice_mut(range, 2, "range")?;
            let field = v.field.as_ref().ok_or_else(|| {
                Failure::new(CylvolStatus::NoScalars, "the volume has no scalar array")
            })?;
            let drawn = match &v.copies {
                Some(c) => c.scalar_range(&Volume::with_field(&v.mesh, &v.accel, field)?)?,
                None => field.range(),
            };
            out.copy_from_slice(&drawn);
            Ok(())
        })
    }
}
