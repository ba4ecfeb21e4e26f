//! Sort-based two-level grids (Kalojanov & Slusallek 2009; Kalojanov, Billeter & Slusallek
//! 2011), in Cartesian `(x, y, z)` or cylindrical `(r, φ, h)` coordinates, `φ` the
//! pseudo-angle of θ ([`crate::geometry::pseudo_angle`]).
//!
//! # Structure
//! The grid indexes boxes ([`Pieces<Aabb>`](crate::accel::space::Pieces)) given in its own
//! coordinates — for a cylindrical grid the `(r, φ, h)` boxes of
//! [`super::space::linear_boxes`], φ in about `[−2, 2]` (θ in `[−π, π]`), and a query point
//! comes as [`crate::accel::Coordinates::query`] makes it (no `atan2`). The domain is
//! the union of the boxes. The top level splits it into `R_x × R_y × R_z` cells by the density
//! rule ([`GridParams::top_density`]); every non-empty top cell is split again, with its own
//! resolution from its own number of pieces ([`GridParams::leaf_density`]). A second-level
//! ("leaf") cell holds the distinct **cell ids** of the pieces whose boxes overlap it, in the
//! order candidates are offered in ([`CandidateOrder`]: increasing ids, as the talk's grids,
//! or the largest share of the leaf cell first). Memory: a `u32` per reference, a `u32` range
//! start per leaf cell (its end is the next one's start) and 8 bytes per top cell (its first
//! leaf cell and its resolution).
//!
//! # Cell shape
//! Both levels shape their cells like the mean piece they hold rather than as cubes
//! (`shaped_lengths` in `resolution.rs`): a grid cell then meets the fewest pieces for its volume.
//! The mean is each piece's extent along each axis (at the second level clipped to the top
//! cell), weighted by the share of the volume the piece's queries come from — in cylindrical
//! coordinates its mid-radius, so the wide-angled pieces near the axis, which hold little
//! volume, do not coarsen the grid's angles for all the rest. Measured on the pump datasets
//! and the real meshes (`cylvol bench`, 256², hexahedra tested per sample on the paper
//! path), both grids test fewer cells than with cubic cells — the Cartesian grid 1–31 %
//! fewer, the cylindrical one 4–16 % — in less memory (the full pump rotor: 54.9 and 52.1
//! bytes a cell against 62.2 and 60.8, `cylvol stats pump-rotor`).
//!
//! # Build
//! Two rounds of the sort-based construction: emit a `(grid cell, id)` pair for every grid cell
//! a box overlaps — counted per primitive in parallel, prefix-summed, then filled in parallel
//! into disjoint slices, without locks — group them by grid cell with counting sorts
//! (round one: a stable parallel counting sort of pieces by top cell; round two: per top cell in
//! parallel, straight into the final reference array), so each cell's `[begin, end)` range is
//! read off directly — the result sorting the pairs would give. Round one pairs top cells
//! with pieces; round two pairs leaf cells with cell ids (a cell reaching one leaf cell through
//! two pieces — straddle sectors, both sides of the seam — is kept once).
//!
//! # Robustness
//! A coordinate `x` falls in cell `clamp(⌊(x − origin) · inv⌋, 0, R − 1)` along each axis. The
//! function is monotone in `x` (subtraction and multiplication by a positive constant round
//! monotonically), and the build computes a box's cell range with the very same function as the
//! query. So a point inside a box always maps to a cell that references the box, whatever the
//! rounding; points on the domain's max face are clamped into the last cell. A point outside
//! the domain (or NaN) finds nothing and costs nothing.
//!
//! # Densities
//! `top_density` λ₁ sizes the top level (`≈ λ₁N` top cells), `leaf_density` λ₂ each top cell's
//! second level (`≈ λ₂ n_t` leaf cells for `n_t` pieces in it). The defaults were chosen by
//! measuring memory per mesh cell against hexahedra tested per point location — see
//! [`GridParams::DEFAULT`] and `benches/grid.rs`. Pump-rotor, 300 k cells, Cartesian
//! (cylindrical within ±15 %):
//!
//! | λ₁ | λ₂ | grid cells / cell | references / cell | bytes / cell | tests / location |
//! |---|---|---|---|---|---|
//! | 1/64 | 0.125 | 0.29 | 9.4 | 39 | 23.7 |
//! | 1/64 | 0.25 | 0.57 | 13.9 | 58 | 17.6 |
//! | 1/64 | 1 | 2.24 | 34.0 | 145 | 10.9 |
//! | 1/16 | 1 | 3.46 | 50.3 | 215 | 9.2 |
//! | 1/4 | 2 | 11.4 | 134 | 582 | 7.0 |
//! | 1/4 | 4 | 22.6 | 238 | 1042 | 6.3 |
//!
//! (`cargo bench --bench grid -- sweep`, cell-id candidate order; cubic second-level cells
//! take 9–15 % more memory and 6–11 % more tests at the same densities.)
//!
//! The rotor's thin, stretched cells overlap many grid cells whatever their size, so memory
//! grows much faster than tests fall; the default sits at the ≤ 64 bytes per cell budget.

mod build;
mod mask;
mod resolution;
mod traverse;
mod validation;
mod walk;

use std::mem::size_of;

use glam::DVec3;

use super::space::Coordinates;
use crate::geometry::bounds::Aabb;

pub use build::build_grid;
pub use mask::{GridMask, MaskedCell};

/// The order in which a leaf cell offers its candidates (and stores its references).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum CandidateOrder {
    /// Cell ids in increasing order: what the sort-based construction gives, the talk's grids.
    #[default]
    Cells,
    /// The cells whose pieces' boxes cover the largest share of the leaf cell first (ties in
    /// cell order): a query in the leaf cell lies in a box with a probability near the share
    /// it covers, so the likeliest candidates are tested first. The cell holding a sample of
    /// the paper path is then the 2nd to 4th tested rather than the 5th to 9th (the
    /// combustor, the mixer, `pump-inlet:300000`), and the grids' hexahedra tested fall by
    /// 38–62 % (`cylvol bench --grid-order share` against `cells` on the seven meshes); a
    /// point outside every cell still tests every candidate. It changes what the talk's comparison measures — the cylindrical grid's
    /// fewer candidates matter less once the likeliest come first — so the presets that
    /// reproduce it keep [`CandidateOrder::Cells`].
    LargestShare,
}

impl CandidateOrder {
    /// Both orders.
    pub const ALL: [CandidateOrder; 2] = [CandidateOrder::Cells, CandidateOrder::LargestShare];

    /// `cells` or `share` (what [`str::parse`] reads).
    pub fn name(self) -> &'static str {
        match self {
            CandidateOrder::Cells => "cells",
            CandidateOrder::LargestShare => "share",
        }
    }
}

impl std::str::FromStr for CandidateOrder {
    type Err = crate::Error;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        crate::error::by_name(
            &CandidateOrder::ALL,
            CandidateOrder::name,
            s,
            "candidate order",
        )
    }
}

/// Build parameters: the densities of the two levels and the candidates' order.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GridParams {
    /// Top-level density λ₁: about `λ₁ N` top cells for `N` pieces.
    pub top_density: f64,
    /// Second-level density λ₂: about `λ₂ n` leaf cells in a top cell holding `n` pieces.
    pub leaf_density: f64,
    /// The order of each leaf cell's candidates.
    pub order: CandidateOrder,
}

impl GridParams {
    /// The measured default, chosen for memory: at most about 64 bytes per mesh cell on the pump
    /// datasets and the real meshes (pump-rotor 300 k: ≈ 50 bytes, ≈ 0.5 grid cells and
    /// ≈ 12 references per mesh cell, ≈ 17–19 candidates offered per point location). Finer
    /// grids buy few tests for much memory on meshes with thin, stretched cells (pump-rotor
    /// 300 k: 4× the memory for 30 % fewer tests, 17× for 60 % fewer), so coarse is the default
    /// and [`GridParams::FAST`] the option.
    pub const DEFAULT: GridParams = GridParams {
        top_density: 1.0 / 64.0,
        leaf_density: 0.2,
        order: CandidateOrder::Cells,
    };

    /// Finer cells, the likeliest candidates first ([`CandidateOrder::LargestShare`]), fewer
    /// hexahedra tested, ten times the memory (pump-rotor 300 k: ≈ 590 bytes per mesh cell,
    /// ≈ 3 tests per location).
    pub const FAST: GridParams = GridParams {
        top_density: 1.0 / 4.0,
        leaf_density: 2.0,
        order: CandidateOrder::LargestShare,
    };

    /// Fewer, larger cells: the least memory (pump-rotor 300 k: ≈ 38 bytes per mesh cell,
    /// ≈ 21–24 tests per location).
    pub const COMPACT: GridParams = GridParams {
        top_density: 1.0 / 64.0,
        leaf_density: 0.125,
        order: CandidateOrder::Cells,
    };

    /// Close to the talk's grid sizes (about 11 grid cells per hexahedron on the pump rotor).
    pub const PAPER: GridParams = GridParams {
        top_density: 1.0 / 16.0,
        leaf_density: 3.0,
        order: CandidateOrder::Cells,
    };

    /// Every preset with its name.
    pub const PRESETS: [(&'static str, GridParams); 4] = [
        ("default", GridParams::DEFAULT),
        ("fast", GridParams::FAST),
        ("compact", GridParams::COMPACT),
        ("paper", GridParams::PAPER),
    ];
}

impl Default for GridParams {
    fn default() -> Self {
        GridParams::DEFAULT
    }
}

/// A top-level cell: where its leaf cells start, and its second-level resolution (all zero
/// for an empty top cell, which has no leaf cells).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub(crate) struct TopCell {
    /// Index of its first leaf cell.
    pub(crate) first: u32,
    /// Second-level resolution.
    pub(crate) res: [u8; 3],
}

/// A two-level grid over boxes in `(x, y, z)` or `(r, φ, h)`; see the module documentation.
#[derive(Clone, Debug)]
pub struct TwoLevelGrid {
    /// Coordinates and build time (boxed: rarely read, keeps the grid small).
    pub(crate) meta: Box<Meta>,
    /// The union of the boxes (empty for no valid box).
    pub(crate) domain: Aabb,
    /// Top-level resolution.
    pub(crate) top_res: [u32; 3],
    /// Top cell size per axis (`extent / R`).
    pub(crate) top_size: DVec3,
    /// `R / extent` per axis (0 where the extent is 0).
    pub(crate) top_inv: DVec3,
    /// Top cells, x fastest.
    pub(crate) top: Vec<TopCell>,
    /// Start of each leaf cell's references, plus one final entry (= `refs.len()`).
    pub(crate) leaf_begin: Vec<u32>,
    /// Cell ids, distinct within each leaf cell, in the build's [`CandidateOrder`].
    pub(crate) refs: Vec<u32>,
}

/// What a query does not need.
#[derive(Clone, Debug)]
pub(crate) struct Meta {
    pub(crate) coordinates: Coordinates,
    /// Build time in seconds.
    pub(crate) build_s: f64,
}

/// Size and cost of a built grid.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct GridStats {
    /// Grid cells of both levels: top cells plus leaf cells.
    pub grid_cells: usize,
    /// Top-level cells.
    pub top_cells: usize,
    /// Second-level cells.
    pub leaf_cells: usize,
    /// References (cell ids) held by the leaf cells.
    pub references: usize,
    /// Heap bytes held (the capacity of every array times its element size).
    pub bytes: usize,
    /// Build time in seconds.
    pub build_s: f64,
}

impl TwoLevelGrid {
    /// The coordinates the grid works in.
    pub fn coordinates(&self) -> Coordinates {
        self.meta.coordinates
    }

    /// The grid's domain: the union of the boxes it was built over.
    pub fn domain(&self) -> Aabb {
        self.domain
    }

    /// The top-level resolution.
    pub fn top_resolution(&self) -> [u32; 3] {
        self.top_res
    }

    /// Cell counts, references, memory and build time.
    pub fn stats(&self) -> GridStats {
        let leaf_cells = self.leaf_begin.len().saturating_sub(1);
        GridStats {
            grid_cells: self.top.len() + leaf_cells,
            top_cells: self.top.len(),
            leaf_cells,
            references: self.refs.len(),
            bytes: self.top.capacity() * size_of::<TopCell>()
                + self.leaf_begin.capacity() * size_of::<u32>()
                + self.refs.capacity() * size_of::<u32>()
                + size_of::<Meta>(),
            build_s: self.meta.build_s,
        }
    }
}

/// The cell of `x` along one axis: `clamp(⌊(x − origin) · inv⌋, 0, res − 1)` (0 for NaN).
/// Monotone in `x`; the build and the query both use it, so they agree.
#[inline]
pub(crate) fn axis_cell(x: f64, origin: f64, inv: f64, res: u32) -> u32 {
    let t = (x - origin) * inv;
    if t >= res as f64 {
        res - 1
    } else if t > 0.0 {
        t as u32
    } else {
        0
    }
}

/// [`axis_cell`] on all three axes.
#[inline]
pub(crate) fn cell_of(p: DVec3, origin: DVec3, inv: DVec3, res: [u32; 3]) -> [u32; 3] {
    [
        axis_cell(p.x, origin.x, inv.x, res[0]),
        axis_cell(p.y, origin.y, inv.y, res[1]),
        axis_cell(p.z, origin.z, inv.z, res[2]),
    ]
}

/// `R / extent`, or 0 where the extent is not positive (one cell there).
#[inline]
pub(crate) fn inverse_size(size: DVec3, res: [u32; 3]) -> DVec3 {
    let f = |s: f64, r: u32| if s > 0.0 { r as f64 / s } else { 0.0 };
    DVec3::new(f(size.x, res[0]), f(size.y, res[1]), f(size.z, res[2]))
}

/// Linear index, x fastest.
#[inline]
pub(crate) fn linear(c: [u32; 3], res: [u32; 3]) -> usize {
    (c[2] as usize * res[1] as usize + c[1] as usize) * res[0] as usize + c[0] as usize
}

impl TwoLevelGrid {
    /// The top cell's integer coordinates from its linear index.
    #[inline]
    pub(crate) fn top_coords(&self, t: usize) -> [u32; 3] {
        let [rx, ry, _] = self.top_res.map(|r| r as usize);
        [
            (t % rx) as u32,
            ((t / rx) % ry) as u32,
            (t / (rx * ry)) as u32,
        ]
    }

    /// Origin and `R / size` of a top cell's second level.
    #[inline]
    pub(crate) fn leaf_frame(&self, tc: [u32; 3], res: [u8; 3]) -> (DVec3, DVec3) {
        let origin =
            self.domain.min + DVec3::new(tc[0] as f64, tc[1] as f64, tc[2] as f64) * self.top_size;
        let inv = inverse_size(self.top_size, res.map(u32::from));
        (origin, inv)
    }
}
