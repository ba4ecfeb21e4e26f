//! Mesh handles: a mesh made from caller arrays (points, `vtkCellArray`-style cells and VTK
//! type codes), its active scalar array, counts, bounds and scalar range.
//!
//! A handle keeps only what rendering needs: the geometry and the active scalar, reduced to
//! the chosen component (or the magnitude) as a one-component array under the caller's name.

use std::ffi::{c_char, c_void, CStr};
use std::sync::Arc;

use super::arrays::{self, product};
use super::codes::{AssociationCode, Code, CylvolAssociation, IndexTypeCode, ValueTypeCode};
use super::status::{self, CylvolStatus, Failure};
use crate::mesh::{cells_from_vtk, OffsetStyle};
use crate::{Association, Component, DataArray, Mesh, MeshParts};

/// An opaque mesh: geometry and (at most) one active scalar array. Volumes built from it
/// share it rather than copy it; replacing its scalars afterwards copies it first (so a volume
/// keeps the mesh it was built with).
pub struct CylvolMesh {
    mesh: Arc<Mesh>,
}

impl CylvolMesh {
    /// The mesh.
    pub fn mesh(&self) -> &Mesh {
        &self.mesh
    }

    /// The mesh, shared.
    pub(crate) fn shared(&self) -> Arc<Mesh> {
        Arc::clone(&self.mesh)
    }
}

/// A scalar array as a caller gives it, checked: the association and a one-component array
/// of the chosen component (or the magnitude).
pub struct Scalars {
    /// Point or cell data.
    pub association: Association,
    /// The array: the scalar values, one per point or cell, or a vector whose component is
    /// drawn (kept whole, so that periodic copies can turn it).
    pub array: DataArray,
    /// The component drawn.
    pub component: Component,
}

/// A scalar array as a caller passes it to the C ABI, unchecked.
pub struct GivenScalars {
    /// The array's name: NULL or a NUL-terminated string.
    pub name: *const c_char,
    /// Point or cell data.
    pub association: AssociationCode,
    /// The values.
    pub values: *const c_void,
    /// Their type.
    pub value_type: ValueTypeCode,
    /// Tuples (points or cells).
    pub n_tuples: usize,
    /// Components a tuple.
    pub n_components: usize,
    /// The component taken (or the magnitude).
    pub component: i32,
}

/// Reads and checks a caller's scalar array for a mesh of `points` points and `cells` cells.
///
/// # Safety
/// `given.values` as [`arrays::slice`] for `n_tuples × n_components` values; `given.name`
/// NULL or a NUL-terminated string.
pub unsafe fn read_scalars(
    given: GivenScalars,
    (points, cells): (usize, usize),
) -> Result<Scalars, Failure> {
    let GivenScalars {
        name,
        association,
        values,
        value_type,
        n_tuples,
        n_components,
        component,
    } = given;
    let association = match association.decode("association")? {
        CylvolAssociation::POINT_DATA => Association::Point,
        CylvolAssociation::CELL_DATA => Association::Cell,
    };
    let value_type = value_type.decode("value_type")?;
    if values.is_null() {
        return Err(Failure::null("values"));
    }
    if n_components == 0 {
        return Err(Failure::invalid("n_components is 0"));
    }
    let expected = match association {
        Association::Point => points,
        Association::Cell => cells,
    };
    if n_tuples != expected {
        return Err(Failure::new(
            CylvolStatus::LengthMismatch,
            format!("n_tuples = {n_tuples} for {association} data of a mesh with {expected} {association}s"),
        ));
    }
    if component < -1 || component >= 0 && component as usize >= n_components {
        return Err(Failure::new(
            CylvolStatus::OutOfRange,
            format!("component {component} of an array with {n_components} component(s) (use -1 for the magnitude)"),
        ));
    }
    let len = product(n_tuples, n_components, "values")?;
    // SAFETY: the caller vouches for `len` values.
    let raw = unsafe { arrays::values(values, value_type, len, "values")? };
    // A vector's component is drawn from the whole vector, kept (a periodic copy draws the
    // component of the vector turned with it); anything else is kept as the values drawn.
    let mut vector = None;
    let scalars: Vec<f64> = if n_components == 1 {
        raw
    } else if component >= 0 {
        let drawn = raw
            .chunks_exact(n_components)
            .map(|t| t[component as usize])
            .collect();
        if n_components == 3 {
            vector = Some(raw);
        }
        drawn
    } else {
        raw.chunks_exact(n_components)
            .map(|t| t.iter().map(|v| v * v).sum::<f64>().sqrt())
            .collect()
    };
    let name = if name.is_null() {
        "scalars".to_string()
    } else {
        // SAFETY: the caller vouches for a NUL-terminated string.
        unsafe { CStr::from_ptr(name) }
            .to_string_lossy()
            .into_owned()
    };
    // Only the scalars drawn must be finite (a NaN in another component is not drawn), as
    // for a mesh read from a file: the same refusal, naming how many and the first. A
    // magnitude of huge finite components can overflow, and is refused alike.
    let what = match (n_components, component) {
        (1, _) => format!("{association} array '{name}'"),
        (_, -1) => format!("the magnitude of {association} array '{name}'"),
        (_, k) => format!("component {k} of {association} array '{name}'"),
    };
    if let Some(refusal) = crate::mesh::non_finite_refusal(&what, association, &scalars) {
        return Err(Failure::invalid(refusal));
    }
    let (array, component) = match vector {
        Some(v) => (
            DataArray::vector(name, v),
            Component::Index(component as usize),
        ),
        None => (DataArray::scalar(name, scalars), Component::Index(0)),
    };
    Ok(Scalars {
        association,
        array,
        component,
    })
}

/// Makes `scalars` the only array (the active scalar) of the mesh in `slot`, copying the
/// mesh first where it is shared (with a volume built from it), the geometry not checked
/// again. On an error (none is expected: the scalars are checked) the mesh is unchanged.
pub fn replace_scalars(slot: &mut Arc<Mesh>, scalars: Scalars) -> Result<(), Failure> {
    let (point_data, cell_data) = match scalars.association {
        Association::Point => (vec![scalars.array], Vec::new()),
        Association::Cell => (Vec::new(), vec![scalars.array]),
    };
    let mesh = Arc::make_mut(slot);
    mesh.replace_arrays(point_data, cell_data)?;
    mesh.set_active_component(scalars.component)
        .map_err(|e| Failure::invalid(e.to_string()))?;
    Ok(())
}

/// Makes a mesh from caller arrays; everything is copied, so the caller may free its arrays
/// as soon as this returns.
///
/// `points`: `n_points × 3` values of `points_type`. Cells as `vtkCellArray` holds them:
/// `offsets` has `n_cells + 1` entries (`offsets[0] == 0`, the last `== connectivity_len`),
/// `connectivity` the point ids, both of `index_type`; `cell_types` has `n_cells` VTK type
/// codes (12 hexahedron, 11 voxel, 13 wedge, 14 pyramid, 10 tetrahedron). The mesh has no
/// scalars until [`cylvol_mesh_set_scalars`]. On failure `*out` is set to NULL.
///
/// Errors: NULL_POINTER (any array or `out`), INVALID_ARGUMENT (a NaN or infinite coordinate,
/// a bad enum value, `offsets[0] != 0`), OUT_OF_RANGE (a point id or offset out of range),
/// LENGTH_MISMATCH (the last offset is not `connectivity_len`, a cell's vertex count is not its
/// type's), UNSUPPORTED_CELL (any other type code), INVALID_MESH (no points or cells, inverted
/// cells).
///
/// # Safety
/// Each pointer must point to the number of elements stated (or be NULL); `out` must be
/// valid for writing a pointer.
#[no_mangle]
pub unsafe extern "C" fn cylvol_mesh_new(
    points: *const c_void,
    points_type: ValueTypeCode,
    n_points: usize,
    offsets: *const c_void,
    connectivity: *const c_void,
    index_type: IndexTypeCode,
    connectivity_len: usize,
    cell_types: *const u8,
    n_cells: usize,
    out: *mut *mut CylvolMesh,
) -> CylvolStatus {
    status::status("cylvol_mesh_new", || {
        // SAFETY: the caller vouches for `out`.
        unsafe { arrays::write(out, std::ptr::null_mut(), "out")? };
        let points_type = points_type.decode("points_type")?;
        let index_type = index_type.decode("index_type")?;
        // SAFETY: the caller vouches for the arrays' lengths.
        let points = unsafe { arrays::points(points, points_type, n_points, "points")? };
        let n_offsets = n_cells
            .checked_add(1)
            .ok_or_else(|| Failure::invalid("n_cells is too large"))?;
        // SAFETY: as above.
        let offsets = unsafe { arrays::indices(offsets, index_type, n_offsets, "offsets")? };
        let connectivity =
            unsafe { arrays::indices(connectivity, index_type, connectivity_len, "connectivity")? };
        let types = unsafe { arrays::slice(cell_types, n_cells, "cell_types")? };
        if offsets[0] != 0 {
            return Err(Failure::invalid(format!(
                "offsets[0] = {} (must be 0)",
                offsets[0]
            )));
        }
        let last = offsets[n_cells];
        if last != connectivity_len as i64 {
            return Err(Failure::new(
                CylvolStatus::LengthMismatch,
                format!("offsets[{n_cells}] = {last} but connectivity_len = {connectivity_len}"),
            ));
        }
        let cells = cells_from_vtk(
            &connectivity,
            &offsets,
            OffsetStyle::Starts,
            types,
            n_points,
        )?;
        let mesh = Mesh::from_parts(MeshParts {
            points,
            cells: cells.cells,
            kinds: cells.kinds,
            point_data: Vec::new(),
            cell_data: Vec::new(),
        })?;
        let handle = Box::into_raw(Box::new(CylvolMesh {
            mesh: Arc::new(mesh),
        }));
        // SAFETY: checked non-NULL and aligned above.
        unsafe { out.write(handle) };
        Ok(())
    })
}

/// Adds (copies) a scalar array and makes it the active one, replacing the previous one.
/// `values`: `n_tuples × n_components` values of `value_type`; `n_tuples` must equal the point
/// (or cell) count. `component`: which component to use, or -1 for the magnitude (for a
/// one-component array 0 and -1 both mean the value). `name` may be NULL.
///
/// Errors: NULL_POINTER, INVALID_ARGUMENT (a NaN or infinite value among the scalars drawn:
/// the component chosen, or the magnitude; other components may hold them, as a mesh read
/// from a file may; a bad enum value, `n_components == 0`), LENGTH_MISMATCH (`n_tuples`),
/// OUT_OF_RANGE (`component`).
///
/// # Safety
/// `mesh` a live handle; `values` `n_tuples × n_components` readable values; `name` NULL or
/// NUL-terminated.
#[no_mangle]
pub unsafe extern "C" fn cylvol_mesh_set_scalars(
    mesh: *mut CylvolMesh,
    name: *const c_char,
    association: AssociationCode,
    values: *const c_void,
    value_type: ValueTypeCode,
    n_tuples: usize,
    n_components: usize,
    component: i32,
) -> CylvolStatus {
    status::status("cylvol_mesh_set_scalars", || {
        // SAFETY: the caller vouches for the handle.
        let handle = unsafe { arrays::handle_mut(mesh, "mesh")? };
        let m = handle.mesh();
        let counts = (m.point_count(), m.cell_count());
        // SAFETY: the caller vouches for the arrays.
        let scalars = unsafe {
            let given = GivenScalars {
                name,
                association,
                values,
                value_type,
                n_tuples,
                n_components,
                component,
            };
            read_scalars(given, counts)?
        };
        replace_scalars(&mut handle.mesh, scalars)
    })
}

/// The numbers of points and cells.
///
/// # Safety
/// `mesh` a live handle; the outputs valid for writing.
#[no_mangle]
pub unsafe extern "C" fn cylvol_mesh_counts(
    mesh: *const CylvolMesh,
    n_points: *mut usize,
    n_cells: *mut usize,
) -> CylvolStatus {
    status::status("cylvol_mesh_counts", || {
        // SAFETY: the caller vouches for the handle and outputs.
        let m = unsafe { arrays::handle(mesh, "mesh")? }.mesh();
        if n_points.is_null() || n_cells.is_null() {
            return Err(Failure::null(if n_points.is_null() {
                "n_points"
            } else {
                "n_cells"
            }));
        }
        unsafe {
            arrays::write(n_points, m.point_count(), "n_points")?;
            arrays::write(n_cells, m.cell_count(), "n_cells")
        }
    })
}

/// The mesh bounds `xmin, xmax, ymin, ymax, zmin, zmax`.
///
/// # Safety
/// `mesh` a live handle; `bounds` valid for writing 6 doubles.
/// cbindgen:ptrs-as-arrays=[[bounds;6]]
#[allow(rustdoc::broken_intra_doc_links)] // the cbindgen annotation above
#[no_mangle]
pub unsafe extern "C" fn cylvol_mesh_bounds(
    mesh: *const CylvolMesh,
    bounds: *mut f64,
) -> CylvolStatus {
    status::status("cylvol_mesh_bounds", || {
        // SAFETY: the caller vouches for the handle and output.
        let m = unsafe { arrays::handle(mesh, "mesh")? }.mesh();
        let out = unsafe { arrays::slice_mut(bounds, 6, "bounds")? };
        out.copy_from_slice(&m.bounds());
        Ok(())
    })
}

/// The active scalar's `[min, max]`; NO_SCALARS if none is set.
///
/// # Safety
/// `mesh` a live handle; `range` valid for writing 2 doubles.
/// cbindgen:ptrs-as-arrays=[[range;2]]
#[allow(rustdoc::broken_intra_doc_links)] // the cbindgen annotation above
#[no_mangle]
pub unsafe extern "C" fn cylvol_mesh_scalar_range(
    mesh: *const CylvolMesh,
    range: *mut f64,
) -> CylvolStatus {
    status::status("cylvol_mesh_scalar_range", || {
        // SAFETY: the caller vouches for the handle and output.
        let m = unsafe { arrays::handle(mesh, "mesh")? }.mesh();
        let out = unsafe { arrays::slice_mut(range, 2, "range")? };
        let r = m.scalar_range().ok_or_else(|| {
            Failure::new(
                CylvolStatus::NoScalars,
                "the mesh has no scalar array (cylvol_mesh_set_scalars)",
            )
        })?;
        out.copy_from_slice(&r);
        Ok(())
    })
}

/// Frees a mesh (NULL is fine). Volumes built from it keep the mesh as it was.
///
/// # Safety
/// `mesh` NULL or a live handle from [`cylvol_mesh_new`], not used afterwards.
#[no_mangle]
pub unsafe extern "C" fn cylvol_mesh_free(mesh: *mut CylvolMesh) {
    // SAFETY: the caller vouches for the handle.
    unsafe { arrays::free_handle("cylvol_mesh_free", mesh) }
}
