//! Named data arrays attached to points or cells, and the choice of the scalar a render uses.

use std::fmt;

/// Whether an array holds one tuple per point or one per cell.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Association {
    /// One tuple per point (interpolated inside cells).
    Point,
    /// One tuple per cell (constant inside each cell).
    Cell,
}

impl fmt::Display for Association {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Association::Point => "point",
            Association::Cell => "cell",
        })
    }
}

/// How a scalar is taken from an array with several components.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Component {
    /// One component by index (the only choice for one-component arrays: `Index(0)`).
    Index(usize),
    /// The Euclidean norm of the tuple (the default for vectors).
    Magnitude,
}

/// A named array of `f64` tuples, stored tuple after tuple.
#[derive(Clone, Debug, PartialEq)]
pub struct DataArray {
    /// The array's name as in the file (`p`, `Density`, …).
    pub name: String,
    /// Components per tuple: 1 for scalars, 3 for vectors.
    pub components: usize,
    /// `tuples × components` values.
    pub values: Vec<f64>,
}

impl DataArray {
    /// A one-component array.
    pub fn scalar(name: impl Into<String>, values: Vec<f64>) -> DataArray {
        DataArray {
            name: name.into(),
            components: 1,
            values,
        }
    }

    /// An array of 3-vectors, given as flat `x, y, z` values.
    pub fn vector(name: impl Into<String>, values: Vec<f64>) -> DataArray {
        DataArray {
            name: name.into(),
            components: 3,
            values,
        }
    }

    /// Number of tuples (values ÷ components).
    pub fn tuples(&self) -> usize {
        self.values.len() / self.components.max(1)
    }

    /// The scalar the component choice takes from tuple `i`.
    pub fn scalar_at(&self, i: usize, component: Component) -> f64 {
        let tuple = &self.values[i * self.components..(i + 1) * self.components];
        match component {
            Component::Index(c) => tuple[c],
            Component::Magnitude => tuple.iter().map(|v| v * v).sum::<f64>().sqrt(),
        }
    }

    /// The default component choice: the value for one-component arrays, magnitude otherwise.
    pub fn default_component(&self) -> Component {
        if self.components == 1 {
            Component::Index(0)
        } else {
            Component::Magnitude
        }
    }

    /// All scalars the component choice takes from this array.
    pub fn scalars(&self, component: Component) -> Vec<f64> {
        (0..self.tuples())
            .map(|i| self.scalar_at(i, component))
            .collect()
    }

    /// `[min, max]` of the finite scalars the component choice takes, NaN and infinities
    /// left out as VTK's `GetFiniteRange` leaves them (`None` when no scalar is finite).
    ///
    /// ```
    /// use cylvol::{Component, DataArray};
    /// let t = DataArray::scalar("T", vec![2.0, f64::NAN, -1.0, f64::INFINITY]);
    /// assert_eq!(t.range(Component::Index(0)), Some([-1.0, 2.0]));
    /// assert_eq!(DataArray::scalar("T", vec![f64::NAN]).range(Component::Index(0)), None);
    /// ```
    pub fn range(&self, component: Component) -> Option<[f64; 2]> {
        (0..self.tuples())
            .map(|i| self.scalar_at(i, component))
            .filter(|v| v.is_finite())
            .fold(None, |acc, v| match acc {
                None => Some([v, v]),
                Some([lo, hi]) => Some([lo.min(v), hi.max(v)]),
            })
    }

    /// How many of the array's values (all components) are NaN or infinite.
    pub fn non_finite_count(&self) -> usize {
        self.values.iter().filter(|v| !v.is_finite()).count()
    }
}

/// What a non-finite scalar is called in messages: `NaN`, `+inf` or `-inf`.
fn non_finite_name(v: f64) -> &'static str {
    if v.is_nan() {
        "NaN"
    } else if v > 0.0 {
        "+inf"
    } else {
        "-inf"
    }
}

/// An array holding NaN or infinite values, as [`super::Mesh::non_finite_arrays`] lists it.
#[derive(Clone, Debug, PartialEq)]
pub struct NonFiniteArray {
    /// Point or cell data.
    pub association: Association,
    /// The array's name.
    pub name: String,
    /// How many of its values (all components) are NaN or infinite.
    pub count: usize,
    /// How many values it has (tuples × components).
    pub values: usize,
}

impl fmt::Display for NonFiniteArray {
    /// `point array 'T': 3 of 1200 values are NaN or infinite`.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let (count, values) = (self.count, self.values);
        let verb = if count == 1 { "is" } else { "are" };
        write!(
            f,
            "{} array '{}': {count} of {values} values {verb} NaN or infinite",
            self.association, self.name
        )
    }
}

/// The refusal of scalars a render would draw where any is NaN or infinite; `None` when all
/// are finite. `what` names them (`point array 'T'`, `the magnitude of point array 'U'`);
/// `association` says what an index counts. One message for every interface (the command
/// line, the library's renderer and the C ABI), naming how many and the first.
///
/// ```
/// use cylvol::mesh::non_finite_refusal;
/// use cylvol::Association;
/// let m = non_finite_refusal("point array 'T'", Association::Point, &[1.0, f64::NAN, f64::NAN]);
/// assert_eq!(
///     m.as_deref(),
///     Some("point array 'T' cannot be drawn: 2 of its 3 values are NaN or infinite (the \
///           first, NaN, at point 1); draw another array")
/// );
/// assert!(non_finite_refusal("point array 'p'", Association::Point, &[0.5]).is_none());
/// ```
pub fn non_finite_refusal(what: &str, association: Association, scalars: &[f64]) -> Option<String> {
    let first = scalars.iter().position(|v| !v.is_finite())?;
    let count = scalars[first..].iter().filter(|v| !v.is_finite()).count();
    let values = scalars.len();
    let (count_text, verb) = if count == 1 {
        ("1 of its".to_string(), "is")
    } else {
        (format!("{count} of its"), "are")
    };
    Some(format!(
        "{what} cannot be drawn: {count_text} {values} values {verb} NaN or infinite (the \
         first, {}, at {association} {first}); draw another array",
        non_finite_name(scalars[first])
    ))
}

/// The scalar a render uses: which array, where, and which component.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ActiveScalar {
    /// Point or cell data.
    pub association: Association,
    /// Index into the mesh's point or cell arrays.
    pub array: usize,
    /// Which component (or the magnitude).
    pub component: Component,
}

/// Whether points and cells both hold an array named `name`.
fn shared(name: &str, point: &[DataArray], cell: &[DataArray]) -> bool {
    let has = |arrays: &[DataArray]| arrays.iter().any(|a| a.name == name);
    has(point) && has(cell)
}

/// The names of all arrays, point arrays first, each as [`super::Mesh::set_active_scalar`]
/// takes it: a name that points and cells share comes as `point:NAME` and `cell:NAME`.
pub(crate) fn selectors(point: &[DataArray], cell: &[DataArray]) -> Vec<String> {
    let tagged = point
        .iter()
        .map(|a| (Association::Point, a))
        .chain(cell.iter().map(|a| (Association::Cell, a)));
    tagged
        .map(|(association, a)| {
            if shared(&a.name, point, cell) {
                format!("{association}:{}", a.name)
            } else {
                a.name.clone()
            }
        })
        .collect()
}

impl ActiveScalar {
    /// The scalars this selection takes, as messages name them: `point array 'T'`,
    /// `component 2 of point array 'U'`, `the magnitude of cell array 'U'`.
    pub fn describe(&self, point: &[DataArray], cell: &[DataArray]) -> String {
        let arrays = match self.association {
            Association::Point => point,
            Association::Cell => cell,
        };
        let Some(array) = arrays.get(self.array) else {
            return String::new();
        };
        let whole = format!("{} array '{}'", self.association, array.name);
        match self.component {
            _ if array.components == 1 => whole,
            Component::Index(k) => format!("component {k} of {whole}"),
            Component::Magnitude => format!("the magnitude of {whole}"),
        }
    }

    /// This selection as [`super::Mesh::set_active_scalar`] (and `cylvol --scalar`) takes it,
    /// given the mesh's point and cell arrays: the array's name (`p`), with `cell:` before it
    /// where a point array has the same name (the bare name picks the point array:
    /// `cell:p`), and `[k]` after it for component `k` of an array of several (`U[2]`; `U`
    /// is its magnitude).
    ///
    /// ```
    /// use cylvol::{CellKind, DataArray, Mesh, MeshParts};
    /// let corner = |i: i32| glam::DVec3::new((i & 1).into(), (i >> 1 & 1).into(), (i >> 2).into());
    /// let mut mesh = Mesh::from_parts(MeshParts {
    ///     points: (0..8).map(corner).collect(),
    ///     cells: vec![[0, 1, 3, 2, 4, 5, 7, 6]],
    ///     kinds: vec![CellKind::Hexahedron],
    ///     point_data: vec![
    ///         DataArray::scalar("p", vec![0.0; 8]),
    ///         DataArray::vector("U", vec![0.0; 24]),
    ///     ],
    ///     cell_data: vec![DataArray::scalar("p", vec![1.0]), DataArray::scalar("k", vec![2.0])],
    /// })
    /// .unwrap();
    /// for name in ["U[2]", "U", "p", "cell:p", "k"] {
    ///     mesh.set_active_scalar(name).unwrap();
    ///     let active = mesh.active_scalar().unwrap();
    ///     assert_eq!(active.selector(mesh.point_data(), mesh.cell_data()), name);
    /// }
    /// // As --scalar is told: `point:` is never needed, since points are searched first.
    /// mesh.set_active_scalar("point:p").unwrap();
    /// let active = mesh.active_scalar().unwrap();
    /// assert_eq!(active.selector(mesh.point_data(), mesh.cell_data()), "p");
    /// ```
    pub fn selector(&self, point: &[DataArray], cell: &[DataArray]) -> String {
        let arrays = match self.association {
            Association::Point => point,
            Association::Cell => cell,
        };
        let Some(array) = arrays.get(self.array) else {
            return String::new();
        };
        let name = match self.association {
            Association::Cell if shared(&array.name, point, cell) => {
                format!("cell:{}", array.name)
            }
            _ => array.name.clone(),
        };
        match self.component {
            Component::Index(k) if array.components > 1 => format!("{name}[{k}]"),
            _ => name,
        }
    }
}
