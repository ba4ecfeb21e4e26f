//! The active scalar of a mesh gathered for rendering ([`ScalarField`]), a mesh with its
//! structure and scalar ready to render ([`Volume`]), the scalar at a point of a cell, and the
//! default sample step.

use std::borrow::Cow;

use glam::{DMat3, DVec3};
use rayon::prelude::*;

use super::options::Interpolation;
use crate::accel::Accel;
use crate::geometry::bounds::{cell_bounds, Aabb};
use crate::mesh::{Association, Component};
use crate::{Error, Mesh};

/// The default step: half the mean cell size, the cell size being its box diagonal ÷ √3 (the
/// edge of a cube with that diagonal). Falls back to 1/1000 of the mesh diagonal if every cell
/// is flat.
pub fn default_step(mesh: &Mesh) -> f64 {
    let n = mesh.cell_count().max(1) as f64;
    // Summed in fixed chunks, then the chunks in order: the same bits whatever the threads
    // (a parallel `sum` groups the terms as the work was split).
    const CHUNK: usize = 4096;
    let chunk_sums: Vec<f64> = (0..mesh.cell_count().div_ceil(CHUNK))
        .into_par_iter()
        .map(|k| {
            (k * CHUNK..((k + 1) * CHUNK).min(mesh.cell_count()))
                .map(|c| cell_bounds(&mesh.cell_corners(c)).diagonal())
                .sum::<f64>()
        })
        .collect();
    let total: f64 = chunk_sums.iter().sum();
    let step = total / n / 3f64.sqrt() / 2.0;
    if step > 0.0 && step.is_finite() {
        step
    } else {
        let b = mesh.bounds();
        let d = DVec3::new(b[1] - b[0], b[3] - b[2], b[5] - b[4]).length();
        if d > 0.0 && d.is_finite() {
            d / 1000.0
        } else {
            1.0
        }
    }
}

/// The active scalar of a mesh gathered for rendering: its values, association and range,
/// each cell's scalar range, and the mesh's bounds. Gathered once by [`ScalarField::gather`]
/// and shared by every [`Volume`] over the same mesh and scalars (one per structure, or one
/// per frame), so a render does not gather it again.
#[derive(Clone, Debug, PartialEq)]
pub struct ScalarField {
    association: Association,
    scalars: Vec<f64>,
    cell_ranges: Vec<[f64; 2]>,
    range: [f64; 2],
    bounds: Aabb,
}

impl ScalarField {
    /// Gathers the active scalar of `mesh` (an error if it has none, or if any of its values
    /// is NaN or infinite: [`Mesh::drawn_scalars`]) and each cell's range.
    pub fn gather(mesh: &Mesh) -> Result<ScalarField, Error> {
        let (association, scalars) = mesh.drawn_scalars()?;
        let range = mesh
            .scalar_range()
            .ok_or_else(|| Error::Invalid("the mesh has no scalar array to render".into()))?;
        Ok(ScalarField::from_values(mesh, association, scalars, range))
    }

    /// The field of `mesh`'s drawn vector component in a copy whose vectors are the mesh's
    /// turned by the rotation `turn`, as the Angular Periodic Filter rotates vectors: `None` where turning
    /// changes nothing drawn (a one-component array, a vector's magnitude). Tensors' components
    /// are refused, and so is a turned value that is not finite (a non-finite value in another
    /// component of the vector).
    pub(crate) fn turned(mesh: &Mesh, turn: DMat3) -> Result<Option<ScalarField>, Error> {
        Ok(turned_values(mesh, turn)?.map(|(association, scalars)| {
            let range = range_of(&scalars);
            ScalarField::from_values(mesh, association, scalars, range)
        }))
    }

    /// The field of `scalars` over `mesh` with the range `range`.
    fn from_values(
        mesh: &Mesh,
        association: Association,
        scalars: Vec<f64>,
        range: [f64; 2],
    ) -> ScalarField {
        let cell_ranges = match association {
            Association::Point => mesh
                .cells()
                .par_iter()
                .map(|c| {
                    c.iter()
                        .fold([f64::INFINITY, f64::NEG_INFINITY], |[lo, hi], &i| {
                            let v = scalars[i as usize];
                            [lo.min(v), hi.max(v)]
                        })
                })
                .collect(),
            Association::Cell => scalars.iter().map(|&v| [v, v]).collect(),
        };
        let b = mesh.bounds();
        let bounds = Aabb::new(DVec3::new(b[0], b[2], b[4]), DVec3::new(b[1], b[3], b[5]));
        ScalarField {
            association,
            scalars,
            cell_ranges,
            range,
            bounds,
        }
    }

    /// `[min, max]` of the scalar.
    pub fn range(&self) -> [f64; 2] {
        self.range
    }

    /// Whether the field has the shape of `mesh`'s cells and points.
    fn fits(&self, mesh: &Mesh) -> bool {
        let values = match self.association {
            Association::Point => mesh.point_count(),
            Association::Cell => mesh.cell_count(),
        };
        self.cell_ranges.len() == mesh.cell_count() && self.scalars.len() == values
    }
}

/// The drawn vector component of `mesh` in a copy whose vectors are turned by the rotation `turn`, with
/// its association ([`ScalarField::turned`]).
fn turned_values(mesh: &Mesh, turn: DMat3) -> Result<Option<(Association, Vec<f64>)>, Error> {
    let (Some(active), Some(array)) = (mesh.active_scalar(), mesh.active_array()) else {
        return Ok(None);
    };
    let Component::Index(c) = active.component else {
        return Ok(None);
    };
    match array.components {
        1 => return Ok(None),
        3 => {}
        n => {
            return Err(Error::Invalid(format!(
                "component {c} of the {n}-component array '{}' cannot be drawn in periodic \
                 copies (only a vector's components are turned with the copies): draw its \
                 magnitude, or draw the sector alone",
                array.name
            )))
        }
    }
    let scalars: Vec<f64> = array
        .values
        .par_chunks_exact(3)
        .map(|v| (turn * DVec3::from_slice(v))[c])
        .collect();
    if let Some(i) = scalars.iter().position(|v| !v.is_finite()) {
        return Err(Error::Invalid(format!(
            "{} array '{}' turned into a periodic copy has a non-finite component {c} at tuple \
             {i} (another of its components is not finite there)",
            active.association, array.name
        )));
    }
    Ok(Some((active.association, scalars)))
}

/// `[min, max]` of `values` (all finite).
fn range_of(values: &[f64]) -> [f64; 2] {
    values
        .iter()
        .fold([f64::INFINITY, f64::NEG_INFINITY], |[lo, hi], &v| {
            [lo.min(v), hi.max(v)]
        })
}

/// `[min, max]` of `mesh`'s drawn vector component over copies whose vectors are turned by
/// each of the rotations `turns` (`None` where turning changes nothing drawn).
pub(crate) fn turned_range(mesh: &Mesh, turns: &[DMat3]) -> Result<Option<[f64; 2]>, Error> {
    let mut range: Option<[f64; 2]> = None;
    for &turn in turns {
        let Some((_, values)) = turned_values(mesh, turn)? else {
            return Ok(None);
        };
        let [lo, hi] = range_of(&values);
        range = Some(range.map_or([lo, hi], |[a, b]| [a.min(lo), b.max(hi)]));
    }
    Ok(range)
}

/// A mesh with its structure and active scalar ([`ScalarField`]), ready to render.
#[derive(Clone, Debug)]
pub struct Volume<'a> {
    mesh: &'a Mesh,
    accel: &'a Accel,
    field: Cow<'a, ScalarField>,
}

impl<'a> Volume<'a> {
    /// Gathers the active scalar of `mesh` (an error if it has none, or if any of its values
    /// is NaN or infinite: [`Mesh::drawn_scalars`]) and each cell's range.
    pub fn new(mesh: &'a Mesh, accel: &'a Accel) -> Result<Volume<'a>, Error> {
        Ok(Volume {
            mesh,
            accel,
            field: Cow::Owned(ScalarField::gather(mesh)?),
        })
    }

    /// A volume over a field gathered before from the same mesh (an error if its sizes do
    /// not fit the mesh).
    ///
    /// ```
    /// use cylvol::accel::{Accel, AccelParams, StructureKind};
    /// use cylvol::axis::Axis;
    /// use cylvol::datasets::{generate, Dataset};
    /// use cylvol::render::{ScalarField, Volume};
    /// let a = generate(Dataset::PumpInlet, 2000).unwrap();
    /// let b = generate(Dataset::PumpInlet, 4000).unwrap();
    /// let params = AccelParams::default();
    /// let accel = Accel::build(&a, StructureKind::CartBvh, &Axis::Z, &params).unwrap();
    /// let field = ScalarField::gather(&a).unwrap();
    /// let v = Volume::with_field(&a, &accel, &field).unwrap();
    /// assert_eq!(v.scalar_range(), Volume::new(&a, &accel).unwrap().scalar_range());
    /// assert_eq!(v.cell_range(7), Volume::new(&a, &accel).unwrap().cell_range(7));
    /// assert!(Volume::with_field(&b, &accel, &field).is_err());
    /// ```
    pub fn with_field(
        mesh: &'a Mesh,
        accel: &'a Accel,
        field: &'a ScalarField,
    ) -> Result<Volume<'a>, Error> {
        if !field.fits(mesh) {
            return Err(Error::Invalid(
                "the scalar field was gathered from another mesh".into(),
            ));
        }
        Ok(Volume {
            mesh,
            accel,
            field: Cow::Borrowed(field),
        })
    }

    /// This volume with its drawn vector component as it reads in a copy whose vectors are
    /// turned by the rotation `turn` ([`ScalarField::turned`]; `None` where that changes nothing).
    pub(crate) fn turned(&self, turn: DMat3) -> Result<Option<Volume<'a>>, Error> {
        Ok(ScalarField::turned(self.mesh, turn)?.map(|field| Volume {
            mesh: self.mesh,
            accel: self.accel,
            field: Cow::Owned(field),
        }))
    }

    /// The mesh.
    pub fn mesh(&self) -> &Mesh {
        self.mesh
    }

    /// The structure.
    pub fn accel(&self) -> &Accel {
        self.accel
    }

    /// `[min, max]` of the active scalar.
    pub fn scalar_range(&self) -> [f64; 2] {
        self.field.range
    }

    /// `[min, max]` of the scalar over cell `c` (its corners' values for point data).
    pub fn cell_range(&self, c: u32) -> [f64; 2] {
        self.field.cell_ranges[c as usize]
    }

    /// Every cell's `[min, max]` of the scalar.
    pub(crate) fn cell_ranges(&self) -> &[[f64; 2]] {
        &self.field.cell_ranges
    }

    /// The box of the mesh's points.
    pub(crate) fn bounds(&self) -> &Aabb {
        &self.field.bounds
    }

    /// The scalar at parameters `param` (in the cell's cube) of `cell`: the trilinear (or
    /// nearest-corner, by `interpolation`) interpolant of point data, with the corner values;
    /// a cell's value.
    #[inline]
    pub(crate) fn scalar_at(
        &self,
        cell: u32,
        param: DVec3,
        interpolation: Interpolation,
    ) -> (f64, Option<[f64; 8]>) {
        let field = &*self.field;
        match field.association {
            Association::Point => {
                let values = self.mesh.cells()[cell as usize].map(|i| field.scalars[i as usize]);
                (interpolation.sample(&values, param), Some(values))
            }
            Association::Cell => (field.scalars[cell as usize], None),
        }
    }
}
