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
    cylindrical_bounds, normalize_angle, straddle_sectors, CylBounds, CylFrame, ThetaInterval,
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
    // One pass, no allocation per cell: the bounds of every cell.
    let whole: Vec<CylBounds> = (0..mesh.cell_count())
        .into_par_iter()
        .map(|c| {
            let corners = mesh.cell_corners(c);
            pad(cylindrical_bounds(&corners, frame), margin(&corners))
        })
        .collect();
    let straddling = whole.iter().filter(|b| b.straddles_axis).count();
    if straddling == 0 {
        let cells = (0..whole.len() as u32).collect();
        return Pieces {
            bounds: whole,
            cells,
        };
    }
    // Cells on the axis (few: the O-grid's core) are cut into sectors.
    let mut pieces = Pieces {
        bounds: Vec::with_capacity(whole.len() + straddling * straddle_sectors_k),
        cells: Vec::with_capacity(whole.len() + straddling * straddle_sectors_k),
    };
    for (c, b) in whole.into_iter().enumerate() {
        if b.straddles_axis {
            let corners = mesh.cell_corners(c);
            for sector in straddle_sectors(&corners, frame, straddle_sectors_k) {
                pieces.bounds.push(pad(sector, margin(&corners)));
                pieces.cells.push(c as u32);
            }
        } else {
            pieces.bounds.push(b);
            pieces.cells.push(c as u32);
        }
    }
    pieces
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
