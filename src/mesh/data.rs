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

    /// `[min, max]` of the scalars the component choice takes (`None` for an empty array).
    pub fn range(&self, component: Component) -> Option<[f64; 2]> {
        (0..self.tuples())
            .map(|i| self.scalar_at(i, component))
            .fold(None, |acc, v| match acc {
                None => Some([v, v]),
                Some([lo, hi]) => Some([lo.min(v), hi.max(v)]),
            })
    }
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
