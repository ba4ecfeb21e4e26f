//! The synthetic pump datasets: deterministic hexahedral meshes of a centrifugal pump's
//! suction pipe, impeller and diffuser, the project's benchmark data.
//!
//! All three turn about the z axis through the origin and fit together (lengths in units of
//! the impeller's outer radius): the pipe ([`Dataset::PumpInlet`], `r ≤ 0.40`,
//! `0.10 ≤ z ≤ 2.10`) feeds the impeller's eye, the impeller ([`Dataset::PumpRotor`],
//! `0.30 ≤ r ≤ 1.00`, `0 ≤ z ≤ 0.45`) feeds the diffuser ([`Dataset::PumpDiffuser`],
//! `1.05 ≤ r ≤ 1.80`, `−0.0465 ≤ z ≤ 0.2065`). Each is a set of structured blocks whose points
//! are placed in cylindrical coordinates — grid lines follow arcs, blades and vanes, so cells
//! are curved and sheared in θ like real turbomachinery meshes — and numbered once: the mesh
//! is conforming (neighbouring cells share points, no point is duplicated, the full 360° rings
//! close by sharing their seam points), and every cell is a positively oriented hexahedron.
//! Each carries point arrays `pressure` (the active scalar: smooth, rising with radius, with
//! blade loading and wakes, varying along the axis) and `velocity` (3 components).
//!
//! The geometry of each dataset is documented in its module: [`inlet`], [`rotor`],
//! [`diffuser`] (the two rings share [`ring`]).
//!
//! **Resolution.** A request for `N` cells fixes three block resolutions in a fixed shape
//! ratio per dataset (see [`Layout`]): scaled by `s = ∛(N / cells at scale 1)`, the first two
//! are tried at the seven integers nearest their ideal values, the third is the integer that
//! brings the count nearest `N`, and the closest count wins. For every `N` in
//! [`MIN_CELLS`]`..=`[`MAX_CELLS`] the count is within ±5 % of `N` (in practice within 1 % from
//! 20,000 cells and 0.25 % from 1 M). At the default sizes: `pump-inlet` 899,808 cells
//! (919,464 points), `pump-rotor` 2,099,160 (2,199,708), `pump-diffuser` 3,400,320 (3,566,838).
//!
//! **Cost.** Points and cells are computed by index in parallel (rayon), so the output is
//! identical for any thread count. A mesh takes about 92 bytes per cell (points, cells,
//! kinds, `pressure`, `velocity`).

mod blocks;
pub mod diffuser;
mod field;
pub mod inlet;
pub mod ring;
pub mod rotor;

use std::fmt;

use crate::{Error, Mesh};

/// The fewest cells a dataset can be asked for.
pub const MIN_CELLS: usize = 1_000;

/// The most cells a dataset can be asked for (about 18 GB of mesh).
pub const MAX_CELLS: usize = 200_000_000;

/// A built-in synthetic dataset.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Dataset {
    /// `pump-inlet`: the suction pipe, an O-grid whose cells touch and straddle the axis.
    PumpInlet,
    /// `pump-rotor`: the impeller, a ring of 7 twisted, backward-swept blades.
    PumpRotor,
    /// `pump-diffuser`: the diffuser, a widening annulus with 11 spiral vanes.
    PumpDiffuser,
}

impl Dataset {
    /// All datasets, in the order reports list them.
    pub const ALL: [Dataset; 3] = [
        Dataset::PumpInlet,
        Dataset::PumpRotor,
        Dataset::PumpDiffuser,
    ];

    /// The dataset's name: `pump-inlet`, `pump-rotor` or `pump-diffuser`.
    pub fn name(self) -> &'static str {
        match self {
            Dataset::PumpInlet => "pump-inlet",
            Dataset::PumpRotor => "pump-rotor",
            Dataset::PumpDiffuser => "pump-diffuser",
        }
    }

    /// The dataset with this exact name, if any.
    pub fn from_name(name: &str) -> Option<Dataset> {
        Dataset::ALL.into_iter().find(|d| d.name() == name)
    }

    /// The default size, as in the talk: 900,000, 2,100,000 and 3,400,000 cells.
    pub fn default_cells(self) -> usize {
        match self {
            Dataset::PumpInlet => 900_000,
            Dataset::PumpRotor => 2_100_000,
            Dataset::PumpDiffuser => 3_400_000,
        }
    }

    /// A one-line description for help texts.
    pub fn description(self) -> &'static str {
        match self {
            Dataset::PumpInlet => {
                "suction pipe meshed as an O-grid (core block + 4 O-blocks); cells touch and straddle the axis"
            }
            Dataset::PumpRotor => {
                "impeller ring: 7 twisted backward-swept thick blades, cells clustered at blades, hub and shroud"
            }
            Dataset::PumpDiffuser => {
                "vaned diffuser: widening annulus with 11 log-spiral vanes, full 360° ring"
            }
        }
    }
}

impl fmt::Display for Dataset {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// The block resolutions a dataset is built at.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Layout {
    /// The O-grid pipe: a `core × core` H-block and four `core × layers` O-blocks, in
    /// `levels` layers along the axis.
    Pipe {
        /// Core cells per side (even).
        core: usize,
        /// Cells from the core boundary to the wall.
        layers: usize,
        /// Cells along the axis.
        levels: usize,
    },
    /// A bladed ring of `blades` passages.
    Ring {
        /// Blades (passages).
        blades: usize,
        /// Radial cells upstream of the blades, along them, and downstream.
        radial: [usize; 3],
        /// Cells across one passage.
        per_passage: usize,
        /// Cells from hub to shroud.
        axial: usize,
    },
}

impl Layout {
    /// Number of cells.
    pub fn cells(&self) -> usize {
        match *self {
            Layout::Pipe {
                core,
                layers,
                levels,
            } => inlet::cells([core, layers, levels]),
            Layout::Ring {
                blades,
                radial,
                per_passage,
                axial,
            } => blades * per_passage * radial.iter().sum::<usize>() * axial,
        }
    }

    /// Number of points.
    pub fn points(&self) -> usize {
        match *self {
            Layout::Pipe {
                core,
                layers,
                levels,
            } => ((core + 1) * (core + 1) + 4 * core * layers) * (levels + 1),
            Layout::Ring {
                blades,
                radial,
                per_passage,
                axial,
            } => {
                let nr: usize = radial.iter().sum();
                let base = (nr + 1) * blades * per_passage * (axial + 1);
                base + (radial[1] - 1) * blades * (axial + 1)
            }
        }
    }
}

fn check_cells(dataset: Dataset, cells: usize) -> Result<(), Error> {
    if cells < MIN_CELLS {
        return Err(Error::Invalid(format!(
            "{dataset}: {cells} cells is too few; ask for at least {MIN_CELLS}"
        )));
    }
    if cells > MAX_CELLS {
        return Err(Error::Invalid(format!(
            "{dataset}: {cells} cells is too many; ask for at most {MAX_CELLS}"
        )));
    }
    Ok(())
}

/// The block resolutions [`generate`] uses for about `cells` cells; `layout(..)?.cells()` is
/// the exact count it makes. Errors as [`generate`].
pub fn layout(dataset: Dataset, cells: usize) -> Result<Layout, Error> {
    check_cells(dataset, cells)?;
    Ok(match dataset {
        Dataset::PumpInlet => {
            let d = inlet::dims(cells);
            Layout::Pipe {
                core: d.core,
                layers: d.layers,
                levels: d.levels,
            }
        }
        Dataset::PumpRotor | Dataset::PumpDiffuser => {
            let shape = ring_shape(dataset);
            let d = shape.dims(cells);
            Layout::Ring {
                blades: shape.blades,
                radial: d.radial,
                per_passage: d.per_passage,
                axial: d.axial,
            }
        }
    })
}

fn ring_shape(dataset: Dataset) -> &'static ring::RingShape {
    match dataset {
        Dataset::PumpDiffuser => &diffuser::SHAPE,
        _ => &rotor::SHAPE,
    }
}

/// Generates a dataset with about `cells` cells (within ±5 %; see [`layout`] for the exact
/// count). Deterministic: the same arguments give the same mesh on any number of threads.
///
/// Errors: [`Error::Invalid`] when `cells` is outside [`MIN_CELLS`]`..=`[`MAX_CELLS`].
///
/// ```
/// use cylvol::datasets::{generate, Dataset};
/// let mesh = generate(Dataset::PumpRotor, 5_000).unwrap();
/// assert!(mesh.cell_count().abs_diff(5_000) <= 250);
/// assert_eq!(mesh.active_array().unwrap().name, "pressure");
/// ```
pub fn generate(dataset: Dataset, cells: usize) -> Result<Mesh, Error> {
    match layout(dataset, cells)? {
        Layout::Pipe {
            core,
            layers,
            levels,
        } => inlet::build(inlet::PipeDims {
            core,
            layers,
            levels,
        }),
        Layout::Ring {
            radial,
            per_passage,
            axial,
            ..
        } => ring_shape(dataset).build(ring::RingDims {
            radial,
            per_passage,
            axial,
        }),
    }
}

/// Parses a dataset specification `NAME` or `NAME:CELLS` (a command-line `INPUT`).
///
/// `CELLS` is a whole number, optionally with `_` separators (`2_100_000`) and a `k`/`K`
/// (thousand) or `M`/`m` (million) suffix, which may follow a decimal (`2.1M`, `900k`).
/// Without `:CELLS` the dataset's [`Dataset::default_cells`] is used.
///
/// Returns `Ok(None)` when `NAME` is not a dataset name (the caller then treats the whole
/// `spec` as a file path), and [`Error::Invalid`] when it is one but `CELLS` is malformed or
/// outside [`MIN_CELLS`]`..=`[`MAX_CELLS`].
///
/// ```
/// use cylvol::datasets::{parse_spec, Dataset};
/// assert_eq!(parse_spec("pump-rotor:2.1M").unwrap(), Some((Dataset::PumpRotor, 2_100_000)));
/// assert_eq!(parse_spec("pump-inlet").unwrap(), Some((Dataset::PumpInlet, 900_000)));
/// assert_eq!(parse_spec("mixer.vtu").unwrap(), None);
/// assert!(parse_spec("pump-diffuser:12").is_err());
/// ```
pub fn parse_spec(spec: &str) -> Result<Option<(Dataset, usize)>, Error> {
    let (name, cells) = match spec.split_once(':') {
        Some((name, cells)) => (name, Some(cells)),
        None => (spec, None),
    };
    let Some(dataset) = Dataset::from_name(name) else {
        return Ok(None);
    };
    let cells = match cells {
        None => dataset.default_cells(),
        Some(text) => parse_cells(text).map_err(|why| {
            Error::Invalid(format!(
                "{dataset}: bad cell count '{text}': {why} (e.g. {dataset}:{}, {dataset}:2.1M, {dataset}:900k)",
                dataset.default_cells()
            ))
        })?,
    };
    check_cells(dataset, cells)?;
    Ok(Some((dataset, cells)))
}

/// A cell count: digits with `_` separators, optionally a decimal, optionally `k`/`M`.
fn parse_cells(text: &str) -> Result<usize, String> {
    if text.is_empty() {
        return Err("it is empty".into());
    }
    let (number, multiplier) = if let Some(n) = text.strip_suffix(['k', 'K']) {
        (n, 1_000u128)
    } else if let Some(n) = text.strip_suffix(['M', 'm']) {
        (n, 1_000_000u128)
    } else {
        (text, 1u128)
    };
    if number.starts_with('_') || number.ends_with('_') || number.contains("__") {
        return Err("'_' may only separate digits".into());
    }
    let digits: String = number.chars().filter(|&c| c != '_').collect();
    let (whole, fraction) = digits.split_once('.').unwrap_or((&digits, ""));
    let all_digits = |s: &str| s.bytes().all(|b| b.is_ascii_digit());
    if (whole.is_empty() && fraction.is_empty()) || !all_digits(whole) || !all_digits(fraction) {
        return Err("expected a whole number, optionally with a k or M suffix".into());
    }
    let too_many = || format!("more than {MAX_CELLS} cells");
    // Leading zeros cannot overflow; anything longer than 30 significant digits is too many.
    let whole = whole.trim_start_matches('0');
    if whole.len() > 30 {
        return Err(too_many());
    }
    let fraction = fraction.trim_end_matches('0');
    if fraction.len() > 6 {
        return Err("not a whole number of cells".into());
    }
    let w: u128 = if whole.is_empty() {
        0
    } else {
        whole.parse().map_err(|_| too_many())?
    };
    let f: u128 = if fraction.is_empty() {
        0
    } else {
        fraction.parse().map_err(|_| "bad decimal".to_string())?
    };
    let scale = 10u128.pow(fraction.len() as u32);
    let frac_cells = f * multiplier;
    if frac_cells % scale != 0 {
        return Err("not a whole number of cells".into());
    }
    let total = w
        .checked_mul(multiplier)
        .and_then(|v| v.checked_add(frac_cells / scale))
        .ok_or_else(too_many)?;
    Ok(usize::try_from(total).unwrap_or(usize::MAX))
}
