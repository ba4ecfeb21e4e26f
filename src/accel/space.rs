//! The coordinates a structure works in, and the bounded pieces of cells it indexes.
//!
//! Cartesian structures index each cell by its box. Cylindrical ones work in `(r, θ, h)` about
//! the machine axis: a cell is bounded by a sector ([`CylBounds`]), and a cell that straddles
//! the axis is cut into several sectors ([`straddle_sectors`]) so that no bound degenerates to
//! the whole circle. A *piece* is one bound and the cell it belongs to; a cell may have several.
//!
//! Every bound is padded by the containment slack of [`crate::geometry::containment`], so a
//! point that [`crate::geometry::containment::locate_in_cell`] accepts always lies in one of
//! its cell's pieces — a structure never misses a cell that brute force finds.
//!
//! **The seam.** θ is periodic. For a sector mesh (a 90° mixer, an 18° combustor) the frame is
//! rotated so that θ = ±π falls in the widest angular gap the mesh leaves, so no cell crosses
//! the seam and the grid's θ range is the sector's own. For a full ring some cells cross it: a
//! BVH keeps their arcs whole ([`crate::geometry::cylindrical::ThetaInterval`] unions on the
//! circle); a grid references them on both sides ([`linear_boxes`]).
//!
//! **Queries** compare pseudo-angles ([`crate::geometry::pseudo_angle`]) instead of angles:
//! `(r, φ, h)` ([`Coordinates::query`]) takes one division where `(r, θ, h)` takes an `atan2`,
//! and both cylindrical structures store their arcs' ends as padded pseudo-angles.

use std::f64::consts::{PI, TAU};

use glam::DVec3;
use rayon::prelude::*;

use crate::axis::Axis;
use crate::geometry::bounds::Aabb;
use crate::geometry::containment::{reject_box, CONTAINMENT_TOLERANCE};
use crate::geometry::cylindrical::{
    normalize_angle, straddle_sectors, CylBounds, CylFrame, FramePoints, ThetaInterval,
};
use crate::geometry::pseudo_angle::padded_pseudo_arc;
use crate::Mesh;

/// Sectors a cell straddling the axis is cut into, by default.
pub const DEFAULT_STRADDLE_SECTORS: usize = 8;

/// The coordinates of a structure: points are mapped by [`Coordinates::query`] before a
/// query.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Coordinates {
    /// `(x, y, z)` as given.
    Cartesian,
    /// `(r, θ, h)` in this frame, `θ ∈ (−π, π]`; the structures compare `(r, φ, h)`, `φ` the
    /// angle's pseudo-angle.
    Cylindrical(CylFrame),
}

impl Coordinates {
    /// The point in these coordinates: `(x, y, z)`, or `(r, θ, h)` with `θ ∈ (−π, π]`.
    ///
    /// ```
    /// use cylvol::accel::Coordinates;
    /// use cylvol::geometry::cylindrical::CylFrame;
    /// use glam::DVec3;
    /// let c = Coordinates::Cylindrical(CylFrame::new(DVec3::ZERO, DVec3::Z).unwrap());
    /// let q = c.of(DVec3::new(0.0, 2.0, 5.0));
    /// assert!((q - DVec3::new(2.0, std::f64::consts::FRAC_PI_2, 5.0)).length() < 1e-15);
    /// ```
    #[inline]
    pub fn of(&self, p: DVec3) -> DVec3 {
        match self {
            Coordinates::Cartesian => p,
            Coordinates::Cylindrical(frame) => {
                let (r, theta, h) = frame.to_cylindrical(p);
                DVec3::new(r, theta, h)
            }
        }
    }

    /// The point as the structures compare it ([`Structure::find`](super::Structure::find)
    /// takes it): `(x, y, z)`, or `(r, φ, h)` with `φ ∈ (−2, 2]` the pseudo-angle of θ
    /// ([`crate::geometry::pseudo_angle`]), made with one division instead of an `atan2`.
    ///
    /// ```
    /// use cylvol::accel::Coordinates;
    /// use cylvol::geometry::cylindrical::CylFrame;
    /// use glam::DVec3;
    /// let c = Coordinates::Cylindrical(CylFrame::new(DVec3::ZERO, DVec3::Z).unwrap());
    /// assert_eq!(c.query(DVec3::new(0.0, 2.0, 5.0)), DVec3::new(2.0, 1.0, 5.0));
    /// assert_eq!(Coordinates::Cartesian.query(DVec3::ONE), DVec3::ONE);
    /// ```
    #[inline]
    pub fn query(&self, p: DVec3) -> DVec3 {
        match self {
            Coordinates::Cartesian => p,
            Coordinates::Cylindrical(frame) => frame.to_pseudo_cylindrical(p),
        }
    }
}

/// Bounded pieces of cells: `bounds[i]` bounds (part of) cell `cells[i]`.
#[derive(Clone, Debug, PartialEq)]
pub struct Pieces<B> {
    /// The bounds of each piece.
    pub bounds: Vec<B>,
    /// The cell each piece belongs to.
    pub cells: Vec<u32>,
}

impl<B> Default for Pieces<B> {
    fn default() -> Self {
        Pieces {
            bounds: Vec::new(),
            cells: Vec::new(),
        }
    }
}

impl<B> Pieces<B> {
    /// Number of pieces.
    pub fn len(&self) -> usize {
        self.bounds.len()
    }

    /// Whether there are none.
    pub fn is_empty(&self) -> bool {
        self.bounds.is_empty()
    }
}

/// One piece per cell: its box, padded by the containment slack.
pub fn cartesian_pieces(mesh: &Mesh) -> Pieces<Aabb> {
    let bounds: Vec<Aabb> = (0..mesh.cell_count())
        .into_par_iter()
        .map(|c| reject_box(&mesh.cell_corners(c)))
        .collect();
    let cells = (0..bounds.len() as u32).collect();
    Pieces { bounds, cells }
}

/// The padded sector pieces of every cell in `frame`: one per cell, or up to
/// `straddle_sectors_k` for a cell straddling the axis.
pub fn cylindrical_pieces(
    mesh: &Mesh,
    frame: &CylFrame,
    straddle_sectors_k: usize,
) -> Pieces<CylBounds> {
    let margin =
        |corners: &[DVec3; 8]| 4.0 * CONTAINMENT_TOLERANCE * reject_box(corners).diagonal();
    // One pass, no allocation per cell: the bounds of every cell, from its points' coordinates
    // in the frame (each point's made once).
    let points = FramePoints::new(mesh.points(), frame);
    let whole: Vec<CylBounds> = (0..mesh.cell_count())
        .into_par_iter()
        .map(|c| {
            let corners = mesh.cell_corners(c);
            let bounds = points.cell_bounds(&corners, &mesh.cells()[c]);
            pad(bounds, margin(&corners))
        })
        .collect();
    drop(points);
    let straddling: Vec<(usize, Vec<CylBounds>)> = whole
        .par_iter()
        .enumerate()
        .filter(|(_, b)| b.straddles_axis)
        .map(|(c, _)| {
            let corners = mesh.cell_corners(c);
            let sectors = straddle_sectors(&corners, frame, straddle_sectors_k)
                .into_iter()
                .map(|sector| pad(sector, margin(&corners)))
                .collect();
            (c, sectors)
        })
        .collect();
    let cells = piece_cells(whole.len(), &straddling);
    Pieces {
        bounds: splice_sectors(whole, straddling),
        cells,
    }
}

/// The cell of every piece: each cell once, in order, a straddling cell (`straddling`, in
/// increasing cell order, with its sectors) once per sector.
fn piece_cells(cell_count: usize, straddling: &[(usize, Vec<CylBounds>)]) -> Vec<u32> {
    let extra: usize = straddling.iter().map(|(_, s)| s.len()).sum();
    let mut cells = Vec::with_capacity(cell_count - straddling.len() + extra);
    let mut next = 0;
    for (c, sectors) in straddling {
        cells.extend(next as u32..*c as u32);
        cells.extend(std::iter::repeat(*c as u32).take(sectors.len()));
        next = c + 1;
    }
    cells.extend(next as u32..cell_count as u32);
    cells
}

/// The bounds of every cell with each straddling cell's (in increasing cell order) replaced
/// by its sectors, in place: the vector grows (without a copy where the allocator can extend
/// it), then the runs of cells between straddling ones move to their places from the back.
/// Cells on the axis are few (an O-grid's core), so this moves memory where a second vector
/// of every piece would allocate and fill it anew.
fn splice_sectors(
    mut bounds: Vec<CylBounds>,
    straddling: Vec<(usize, Vec<CylBounds>)>,
) -> Vec<CylBounds> {
    if straddling.iter().any(|(_, s)| s.is_empty()) {
        // A cell with no sector moves the later ones down: not moved in place (never met in
        // practice: a straddling cell's hull meets the wedges about the axis).
        return spliced_copy(&bounds, &straddling);
    }
    let n = bounds.len();
    let total = n - straddling.len() + straddling.iter().map(|(_, s)| s.len()).sum::<usize>();
    bounds.resize(total, CylBounds::EMPTY);
    // `end` is the end of the cells still to place (their old places), `to` the end of
    // their new places; the straddling cells are placed from the last, so every run moves up
    // and nothing is overwritten before it has moved.
    let (mut end, mut to) = (n, total);
    for (c, sectors) in straddling.into_iter().rev() {
        let at = to - (end - c - 1);
        bounds.copy_within(c + 1..end, at);
        to = at - sectors.len();
        bounds[to..at].copy_from_slice(&sectors);
        end = c;
    }
    debug_assert_eq!(to, end, "the cells before the first straddling one stay");
    bounds
}

/// [`splice_sectors`] into a new vector.
fn spliced_copy(bounds: &[CylBounds], straddling: &[(usize, Vec<CylBounds>)]) -> Vec<CylBounds> {
    let mut out = Vec::with_capacity(bounds.len());
    let mut next = 0;
    for (c, sectors) in straddling {
        out.extend_from_slice(&bounds[next..*c]);
        out.extend_from_slice(sectors);
        next = c + 1;
    }
    out.extend_from_slice(&bounds[next..]);
    out
}

/// Pads a sector by a distance `m` in every direction (θ by the angle `m` subtends at `r_min`).
fn pad(b: CylBounds, m: f64) -> CylBounds {
    if b.is_empty() {
        return b;
    }
    let r0 = b.r[0] - m;
    let h = [b.h[0] - m, b.h[1] + m];
    if r0 <= 0.0 && !b.theta.is_full() && b.theta.width() < PI && !b.straddles_axis {
        // Padding reaches the axis: the padded set wraps around it.
        return CylBounds {
            r: [0.0, b.r[1] + m],
            theta: ThetaInterval::FULL,
            h,
            straddles_axis: true,
        };
    }
    let theta = if b.theta.is_full() || r0 <= 0.0 {
        b.theta
    } else {
        b.theta.padded((m / r0).min(PI))
    };
    CylBounds {
        r: [r0.max(0.0), b.r[1] + m],
        theta,
        h,
        straddles_axis: b.straddles_axis,
    }
}

/// The frame about `axis` rotated so that θ = ±π lies in the middle of the widest angular gap
/// the pieces leave (none for a full ring: the seam then stays where the frame puts it).
/// Returns the frame and the pieces rotated into it.
pub fn seam_frame(axis: &Axis, pieces: Pieces<CylBounds>) -> Option<(CylFrame, Pieces<CylBounds>)> {
    let frame = CylFrame::new(axis.origin, axis.direction)?;
    const BINS: usize = 4096;
    let bin_of = |t: f64| (((t + PI) / TAU * BINS as f64) as usize).min(BINS - 1);
    // The bins the pieces' arcs cover, marked in parallel chunks and merged (`None` once a
    // piece covers the whole circle).
    let covered = pieces
        .bounds
        .par_chunks(1 << 14)
        .map(|chunk| {
            let mut covered = vec![false; BINS];
            for b in chunk.iter().filter(|b| !b.is_empty()) {
                if b.theta.is_full() {
                    return None;
                }
                for [lo, hi] in b.theta.ranges() {
                    for slot in &mut covered[bin_of(lo)..=bin_of(hi)] {
                        *slot = true;
                    }
                }
            }
            Some(covered)
        })
        .reduce_with(|a, b| {
            let (mut a, b) = (a?, b?);
            for (x, y) in a.iter_mut().zip(b) {
                *x |= y;
            }
            Some(a)
        })
        .unwrap_or_else(|| Some(vec![false; BINS]));
    let Some(covered) = covered else {
        return Some((frame, pieces));
    };
    // Widest circular run of uncovered bins.
    let (mut best_len, mut best_start) = (0usize, 0usize);
    let mut run = 0usize;
    for i in 0..2 * BINS {
        if covered[i % BINS] {
            run = 0;
        } else {
            run += 1;
            if run > best_len && run <= BINS {
                best_len = run;
                best_start = i + 1 - run;
            }
        }
    }
    if best_len < 2 {
        return Some((frame, pieces));
    }
    // θ at the gap's middle becomes ±π: rotate the frame by (gap middle − π).
    let middle = -PI + (best_start as f64 + best_len as f64 / 2.0) * TAU / BINS as f64;
    let shift = normalize_angle(middle - PI);
    let (s, c) = shift.sin_cos();
    let rotated = CylFrame {
        origin: frame.origin,
        axis: frame.axis,
        e1: frame.e1 * c + frame.e2 * s,
        e2: frame.e2 * c - frame.e1 * s,
    };
    // Rotated in place: the pieces' bounds are the largest array of the build.
    let mut pieces = pieces;
    pieces.bounds.par_iter_mut().for_each(|b| {
        if !(b.is_empty() || b.theta.is_full()) {
            b.theta = ThetaInterval::new(normalize_angle(b.theta.start() - shift), b.theta.width());
        }
    });
    Some((rotated, pieces))
}

/// Sector pieces as boxes in `(r, φ, h)`, the coordinates [`Coordinates::query`] makes: an arc
/// `[θ₀, θ₁]` within `[−π, π]` becomes `[φ₀, φ₁]`, its pseudo-angles padded by
/// [`THETA_PAD`](crate::geometry::pseudo_angle::THETA_PAD) ([`padded_pseudo_arc`]), so about `[−2, 2]`; an arc crossing the seam gives
/// two boxes (the cell is referenced on both sides). For the grids.
pub fn linear_boxes(pieces: &Pieces<CylBounds>) -> Pieces<Aabb> {
    const CHUNK: usize = 1 << 14;
    let n = pieces.bounds.len().min(pieces.cells.len());
    let (bounds, cells) = (&pieces.bounds[..n], &pieces.cells[..n]);
    // Boxes per chunk of pieces (one or two per piece, none for an empty one), so every chunk
    // fills its own slices of the output, in piece order.
    let counts: Vec<usize> = bounds
        .par_chunks(CHUNK)
        .map(|chunk| chunk.iter().map(|b| b.theta.ranges().count()).sum())
        .collect();
    let total = counts.iter().sum();
    let mut out = Pieces {
        bounds: vec![Aabb::EMPTY; total],
        cells: vec![0; total],
    };
    let mut tasks = Vec::with_capacity(counts.len());
    let (mut rest_b, mut rest_c) = (&mut out.bounds[..], &mut out.cells[..]);
    for (k, &count) in counts.iter().enumerate() {
        let (head_b, tail_b) = std::mem::take(&mut rest_b).split_at_mut(count);
        let (head_c, tail_c) = std::mem::take(&mut rest_c).split_at_mut(count);
        tasks.push((k, head_b, head_c));
        (rest_b, rest_c) = (tail_b, tail_c);
    }
    tasks.into_par_iter().for_each(|(k, out_b, out_c)| {
        let from = k * CHUNK..((k + 1) * CHUNK).min(n);
        let mut j = 0;
        for (b, &cell) in bounds[from.clone()].iter().zip(&cells[from]) {
            for [lo, hi] in b.theta.ranges() {
                let [lo, hi] = padded_pseudo_arc(lo, hi);
                out_b[j] = Aabb::new(
                    DVec3::new(b.r[0], lo, b.h[0]),
                    DVec3::new(b.r[1], hi, b.h[1]),
                );
                out_c[j] = cell;
                j += 1;
            }
        }
    });
    out
}
