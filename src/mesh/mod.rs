//! The mesh model: points in `f64`, cells as collapsed hexahedra in VTK order, named point and
//! cell data arrays with one active scalar. A [`Mesh`] is always valid: the only way to make one
//! is [`Mesh::from_parts`], which checks everything the renderer relies on.
//!
//! Data arrays may hold NaN or infinite values, as VTK's arrays may (a diverged variable, a
//! masked region): the mesh keeps them as they are, [`Mesh::non_finite_arrays`] says which
//! arrays hold them and how many, and only the scalars a render draws must be finite
//! ([`Mesh::drawn_scalars`] refuses them, naming the array and the count).
//!
//! Points are stored in `f64` so a mesh placed 10⁶ units from the origin keeps its cells' shape
//! to well below a micro-unit (an `f32` there resolves only 0.06 units).

mod cell_kind;
pub(crate) mod data;
mod refine;
pub mod topology;
pub mod validate;
mod vtk_cells;

pub use cell_kind::{
    vtk_type_name, CellKind, VTK_EMPTY_CELL, VTK_HEXAHEDRON, VTK_PYRAMID, VTK_TETRA, VTK_VOXEL,
    VTK_WEDGE,
};
pub use data::{
    non_finite_refusal, ActiveScalar, Association, Component, DataArray, NonFiniteArray,
};
pub use refine::{physical_memory, refined_bytes, MAX_REFINEMENT};
pub(crate) use vtk_cells::cells_from_ids;
pub use vtk_cells::{cells_from_vtk, ConvertedCells, OffsetStyle};

use glam::DVec3;

use crate::error::{Error, MeshError};

/// The unchecked contents of a mesh, as readers and generators assemble them.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct MeshParts {
    /// Point coordinates.
    pub points: Vec<DVec3>,
    /// Eight point indices per cell, VTK hexahedron order (collapsed for other kinds).
    pub cells: Vec<[u32; 8]>,
    /// The kind of each cell (same length as `cells`).
    pub kinds: Vec<CellKind>,
    /// Arrays with one tuple per point.
    pub point_data: Vec<DataArray>,
    /// Arrays with one tuple per cell.
    pub cell_data: Vec<DataArray>,
}

/// A validated hexahedral mesh with data arrays.
#[derive(Clone, Debug, PartialEq)]
pub struct Mesh {
    points: Vec<DVec3>,
    cells: Vec<[u32; 8]>,
    kinds: Vec<CellKind>,
    point_data: Vec<DataArray>,
    cell_data: Vec<DataArray>,
    active: Option<ActiveScalar>,
}

impl Mesh {
    /// Validates the parts and makes a mesh, choosing the default active scalar: the first point
    /// array whose values are all finite and not all equal, else the first such cell array,
    /// else the first all-finite point array, else the first all-finite cell array, else the
    /// first point array, else the first cell array.
    ///
    /// Errors: empty mesh, non-finite coordinates, out-of-range indices, arrays of the wrong
    /// length, inverted cells (see [`MeshError`]). NaN and infinite array values are kept
    /// ([`Mesh::non_finite_arrays`]).
    pub fn from_parts(parts: MeshParts) -> Result<Mesh, MeshError> {
        validate::validate(&parts)?;
        let MeshParts {
            points,
            cells,
            kinds,
            point_data,
            cell_data,
        } = parts;
        let mut mesh = Mesh {
            points,
            cells,
            kinds,
            point_data,
            cell_data,
            active: None,
        };
        mesh.active = mesh.default_active();
        Ok(mesh)
    }

    /// Replaces the point and cell data arrays, the geometry kept as it is (and not checked
    /// again): each array must have one tuple per point (or cell), as for
    /// [`Mesh::from_parts`]. The active scalar becomes the default one of the new arrays. On
    /// an error the mesh is unchanged.
    ///
    /// ```
    /// use cylvol::datasets::{generate, Dataset};
    /// use cylvol::DataArray;
    /// let mut mesh = generate(Dataset::PumpInlet, 1000).unwrap();
    /// let n = mesh.point_count();
    /// let ramp = DataArray::scalar("ramp", (0..n).map(|i| i as f64).collect());
    /// mesh.replace_arrays(vec![ramp], vec![]).unwrap();
    /// assert_eq!(mesh.scalar_range(), Some([0.0, (n - 1) as f64]));
    /// let short = DataArray::scalar("short", vec![1.0; n - 1]);
    /// assert!(mesh.replace_arrays(vec![short], vec![]).is_err());
    /// assert_eq!(mesh.point_data()[0].name, "ramp");
    /// ```
    pub fn replace_arrays(
        &mut self,
        point_data: Vec<DataArray>,
        cell_data: Vec<DataArray>,
    ) -> Result<(), MeshError> {
        validate::check_arrays(&point_data, Association::Point, self.points.len())?;
        validate::check_arrays(&cell_data, Association::Cell, self.cells.len())?;
        self.point_data = point_data;
        self.cell_data = cell_data;
        self.active = self.default_active();
        Ok(())
    }

    /// The parts this mesh was made of (for writers and transformations).
    pub fn into_parts(self) -> MeshParts {
        MeshParts {
            points: self.points,
            cells: self.cells,
            kinds: self.kinds,
            point_data: self.point_data,
            cell_data: self.cell_data,
        }
    }

    fn default_active(&self) -> Option<ActiveScalar> {
        // What an array must be to be picked, most wanted first: finite and varying, finite,
        // anything.
        #[derive(Clone, Copy)]
        enum Need {
            Varying,
            Finite,
            Nothing,
        }
        let pick = |association: Association, arrays: &[DataArray], need: Need| {
            arrays.iter().enumerate().find_map(|(i, a)| {
                let component = a.default_component();
                let finite = || a.non_finite_count() == 0;
                let fits = match need {
                    Need::Varying => finite() && a.range(component).is_some_and(|[lo, hi]| hi > lo),
                    Need::Finite => finite(),
                    Need::Nothing => true,
                };
                fits.then_some(ActiveScalar {
                    association,
                    array: i,
                    component,
                })
            })
        };
        [Need::Varying, Need::Finite, Need::Nothing]
            .into_iter()
            .find_map(|need| {
                pick(Association::Point, &self.point_data, need)
                    .or_else(|| pick(Association::Cell, &self.cell_data, need))
            })
    }

    /// The arrays holding NaN or infinite values, point arrays first, each with how many.
    ///
    /// ```
    /// use cylvol::{CellKind, DataArray, Mesh, MeshParts};
    /// let corner = |i: i32| glam::DVec3::new((i & 1).into(), (i >> 1 & 1).into(), (i >> 2).into());
    /// let mut t = vec![300.0; 8];
    /// t[3] = f64::NAN;
    /// let mesh = Mesh::from_parts(MeshParts {
    ///     points: (0..8).map(corner).collect(),
    ///     cells: vec![[0, 1, 3, 2, 4, 5, 7, 6]],
    ///     kinds: vec![CellKind::Hexahedron],
    ///     point_data: vec![DataArray::scalar("T", t), DataArray::scalar("p", vec![1.0; 8])],
    ///     cell_data: vec![],
    /// })
    /// .unwrap();
    /// let bad = mesh.non_finite_arrays();
    /// assert_eq!((bad.len(), bad[0].name.as_str(), bad[0].count), (1, "T", 1));
    /// assert_eq!(bad[0].to_string(), "point array 'T': 1 of 8 values is NaN or infinite");
    /// // The default scalar is an array that can be drawn.
    /// assert_eq!(mesh.active_array().unwrap().name, "p");
    /// ```
    pub fn non_finite_arrays(&self) -> Vec<NonFiniteArray> {
        let tagged = self
            .point_data
            .iter()
            .map(|a| (Association::Point, a))
            .chain(self.cell_data.iter().map(|a| (Association::Cell, a)));
        tagged
            .filter_map(|(association, a)| {
                let count = a.non_finite_count();
                (count > 0).then(|| NonFiniteArray {
                    association,
                    name: a.name.clone(),
                    count,
                    values: a.values.len(),
                })
            })
            .collect()
    }

    /// The active scalar's values as a render draws them (per point or per cell): an error
    /// where the mesh has no array, or where any of them is NaN or infinite (naming the
    /// array, how many and the first: [`non_finite_refusal`]). Every renderer takes its
    /// scalars through this, so that an array with such values is refused alike everywhere.
    pub fn drawn_scalars(&self) -> Result<(Association, Vec<f64>), Error> {
        let (association, scalars) = self.active_scalars().ok_or_else(|| {
            Error::Invalid("the mesh has no point or cell array to render".into())
        })?;
        let what = self
            .active
            .as_ref()
            .map(|a| a.describe(&self.point_data, &self.cell_data))
            .unwrap_or_default();
        match non_finite_refusal(&what, association, &scalars) {
            Some(refusal) => Err(Error::Invalid(refusal)),
            None => Ok((association, scalars)),
        }
    }

    /// Point coordinates.
    pub fn points(&self) -> &[DVec3] {
        &self.points
    }

    /// Cells as eight point indices each (VTK hexahedron order, collapsed for other kinds).
    pub fn cells(&self) -> &[[u32; 8]] {
        &self.cells
    }

    /// The cells' point ids as VTK lists them, cell after cell in each kind's VTK vertex order
    /// (VTK's `connectivity` array).
    ///
    /// ```
    /// use cylvol::{CellKind, Mesh, MeshParts};
    /// use glam::DVec3;
    /// let mesh = Mesh::from_parts(MeshParts {
    ///     points: (0..6).map(|i| DVec3::new(i as f64, (i % 3) as f64, (i / 3) as f64)).collect(),
    ///     cells: vec![CellKind::Wedge.collapse(&[0, 1, 2, 3, 4, 5])],
    ///     kinds: vec![CellKind::Wedge],
    ///     ..Default::default()
    /// })
    /// .unwrap();
    /// assert_eq!(mesh.vtk_connectivity().collect::<Vec<_>>(), [0, 1, 2, 3, 4, 5]);
    /// assert_eq!(mesh.vtk_cell_ends().collect::<Vec<_>>(), [6]);
    /// assert_eq!(mesh.vtk_cell_types().collect::<Vec<_>>(), [13]);
    /// ```
    pub fn vtk_connectivity(&self) -> impl Iterator<Item = u32> + '_ {
        self.cells
            .iter()
            .zip(&self.kinds)
            .flat_map(|(c, k)| k.vtk_slots().iter().map(move |&s| c[s]))
    }

    /// Where each cell's ids end in [`Mesh::vtk_connectivity`] (VTK's `offsets` array, with no
    /// leading zero).
    pub fn vtk_cell_ends(&self) -> impl Iterator<Item = usize> + '_ {
        self.kinds.iter().scan(0, |end, k| {
            *end += k.vertex_count();
            Some(*end)
        })
    }

    /// Each cell's VTK cell type code.
    pub fn vtk_cell_types(&self) -> impl Iterator<Item = u8> + '_ {
        self.kinds.iter().map(|k| k.vtk_type())
    }

    /// The kind of each cell.
    pub fn kinds(&self) -> &[CellKind] {
        &self.kinds
    }

    /// Number of points.
    pub fn point_count(&self) -> usize {
        self.points.len()
    }

    /// Number of cells.
    pub fn cell_count(&self) -> usize {
        self.cells.len()
    }

    /// The eight corner positions of cell `c`.
    #[inline]
    pub fn cell_corners(&self, c: usize) -> [DVec3; 8] {
        // Indexed one by one rather than by `array::map`, which the hot loops of the ray
        // caster paid for in a call and a copy of the array.
        let [a, b, c2, d, e, f, g, h] = self.cells[c];
        let p = &self.points;
        [
            p[a as usize],
            p[b as usize],
            p[c2 as usize],
            p[d as usize],
            p[e as usize],
            p[f as usize],
            p[g as usize],
            p[h as usize],
        ]
    }

    /// [`Mesh::cell_corners`] written into `out` (one store a corner, where assigning the
    /// returned array to a field costs a copy of its 192 bytes through a temporary).
    ///
    /// ```
    /// use cylvol::datasets::{generate, Dataset};
    /// use glam::DVec3;
    /// let mesh = generate(Dataset::PumpInlet, 2000).unwrap();
    /// let mut out = [DVec3::ZERO; 8];
    /// mesh.cell_corners_into(5, &mut out);
    /// assert_eq!(out, mesh.cell_corners(5));
    /// ```
    #[inline]
    pub fn cell_corners_into(&self, c: usize, out: &mut [DVec3; 8]) {
        let ids = &self.cells[c];
        for (o, &i) in out.iter_mut().zip(ids) {
            *o = self.points[i as usize];
        }
    }

    /// Number of cells of each kind, in [`CellKind::ALL`] order.
    pub fn kind_counts(&self) -> [(CellKind, usize); 4] {
        let mut counts = [0usize; 4];
        for k in &self.kinds {
            counts[*k as usize] += 1;
        }
        CellKind::ALL.map(|k| (k, counts[k as usize]))
    }

    /// Arrays with one tuple per point.
    pub fn point_data(&self) -> &[DataArray] {
        &self.point_data
    }

    /// Arrays with one tuple per cell.
    pub fn cell_data(&self) -> &[DataArray] {
        &self.cell_data
    }

    /// The arrays of one association.
    pub fn arrays(&self, association: Association) -> &[DataArray] {
        match association {
            Association::Point => &self.point_data,
            Association::Cell => &self.cell_data,
        }
    }

    /// The active scalar selection, if the mesh has any array.
    pub fn active_scalar(&self) -> Option<&ActiveScalar> {
        self.active.as_ref()
    }

    /// The array the active scalar comes from.
    pub fn active_array(&self) -> Option<&DataArray> {
        self.active
            .as_ref()
            .map(|a| &self.arrays(a.association)[a.array])
    }

    /// Chooses the active scalar by name. `name` may be prefixed `point:` or `cell:`; without a
    /// prefix point arrays are searched first. A suffix `[k]` picks component `k` of a vector
    /// (its magnitude otherwise).
    pub fn set_active_scalar(&mut self, name: &str) -> Result<(), Error> {
        let (assocs, rest): (&[Association], &str) = if let Some(r) = name.strip_prefix("point:") {
            (&[Association::Point], r)
        } else if let Some(r) = name.strip_prefix("cell:") {
            (&[Association::Cell], r)
        } else {
            (&[Association::Point, Association::Cell], name)
        };
        let (base, component) = match rest.strip_suffix(']').and_then(|r| r.rsplit_once('[')) {
            Some((base, k)) => {
                let k: usize = k.parse().map_err(|_| {
                    Error::Invalid(format!("bad component in scalar name '{name}'"))
                })?;
                (base, Some(k))
            }
            None => (rest, None),
        };
        for &association in assocs {
            if let Some(i) = self.arrays(association).iter().position(|a| a.name == base) {
                let array = &self.arrays(association)[i];
                let component = match component {
                    Some(k) if k < array.components => Component::Index(k),
                    Some(k) => {
                        return Err(Error::Invalid(format!(
                            "{association} array '{base}' has {} components; component {k} does not exist",
                            array.components
                        )))
                    }
                    None => array.default_component(),
                };
                self.active = Some(ActiveScalar {
                    association,
                    array: i,
                    component,
                });
                return Ok(());
            }
        }
        let names = data::selectors(&self.point_data, &self.cell_data);
        Err(Error::Invalid(format!(
            "no scalar array named '{name}' (the mesh has: {})",
            if names.is_empty() {
                "none".to_string()
            } else {
                names.join(", ")
            }
        )))
    }

    /// Draws `component` of the active array (an error where the mesh has no array or the
    /// array has no such component).
    pub fn set_active_component(&mut self, component: Component) -> Result<(), Error> {
        let Some(active) = self.active.clone() else {
            return Err(Error::Invalid("the mesh has no array to draw".into()));
        };
        let array = &self.arrays(active.association)[active.array];
        if let Component::Index(k) = component {
            if k >= array.components {
                return Err(Error::Invalid(format!(
                    "{} array '{}' has {} components; component {k} does not exist",
                    active.association, array.name, array.components
                )));
            }
        }
        self.active = Some(ActiveScalar {
            component,
            ..active
        });
        Ok(())
    }

    /// The active scalar's values (per point or per cell), `None` if the mesh has no array.
    pub fn active_scalars(&self) -> Option<(Association, Vec<f64>)> {
        let a = self.active.as_ref()?;
        Some((
            a.association,
            self.arrays(a.association)[a.array].scalars(a.component),
        ))
    }

    /// `[min, max]` of the active scalar's finite values ([`DataArray::range`]).
    pub fn scalar_range(&self) -> Option<[f64; 2]> {
        let a = self.active.as_ref()?;
        self.arrays(a.association)[a.array].range(a.component)
    }

    /// Axis-aligned bounds `[xmin, xmax, ymin, ymax, zmin, zmax]` (VTK's order) of the points.
    pub fn bounds(&self) -> [f64; 6] {
        let (lo, hi) = self.points.iter().fold(
            (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY)),
            |(lo, hi), p| (lo.min(*p), hi.max(*p)),
        );
        [lo.x, hi.x, lo.y, hi.y, lo.z, hi.z]
    }
}

#[cfg(test)]
mod tests;
