//! Proofs by parity that a point past the mesh's boundary lies outside the mesh (fast path).
//!
//! Along the segment of a ray from a point known to be in the mesh to a point tested, the
//! ray passes between the mesh and the space outside only where it crosses a boundary face.
//! The tested point is outside where the segment crosses one boundary face exactly once,
//! transversally, away from the face's edges and from both ends (a robust count of a line's
//! crossings of a bilinear patch, [`crate::geometry::patch::segment_crossings`]), and may
//! cross no other: by the boundary surface's conservative bound, then for the faces that
//! bound leaves, by their count of crossings (zero, told robustly). So where the march leaves
//! the mesh by the plane of a face without a neighbour, the next sample is proved outside
//! with no cell tested and no structure look-up, and the exit's crossing is that face's; the
//! same proof confirms the boundary searches' "outside" at the ray's ends.

use glam::DVec3;

use super::search::Local;
use super::surface::{face_corners, BoundarySurface};
use super::{Boundary, Stretch};
use crate::accel::Counters;
use crate::geometry::bounds::cell_bounds;
use crate::geometry::patch::{segment_crossings, Crossings};
use crate::render::stats::Work;
use crate::Mesh;

/// The distance from a segment's ends, relative to the cell's size, within which a crossing
/// of a boundary face does not count for a proof by parity.
pub(crate) const PARITY_MARGIN: f64 = 1e-6;

/// A proof by parity under way ([`Boundary::proven_outside`]): the boundary surface, and the
/// segment with the margin from its ends within which a crossing does not count, and where
/// it crosses the face it leaves the mesh by.
struct Parity<'r> {
    surface: &'r BoundarySurface,
    mesh: &'r Mesh,
    stretch: Stretch<'r>,
    margin: f64,
    crossing: f64,
}

impl Parity<'_> {
    /// Where the segment crosses the boundary face `(cell, face)`, where that is told
    /// robustly ([`segment_crossings`]).
    fn crossings(&self, (cell, face): (u32, u8)) -> Option<Crossings> {
        let (lo, hi) = self.stretch.range();
        let patch = face_corners(self.mesh, cell, face);
        segment_crossings(
            &patch,
            self.stretch.ray.origin,
            self.stretch.ray.dir,
            lo,
            hi,
            self.margin,
        )
    }
}

/// A sample past an exit from the mesh proved outside ([`Boundary::proven_outside_until`]).
#[derive(Clone, Copy, Debug)]
pub(crate) struct ProvedExit {
    /// Where the ray crosses the boundary face it leaves by (exactly: the bilinear face).
    pub(crate) crossing: f64,
    /// The next possible boundary crossing: its `t` and the cell of its face (none: the
    /// ray's end).
    pub(crate) next: (f64, Option<u32>),
}

/// Where the sample past an exit from the mesh by the face planes lies
/// ([`Boundary::past_exit`]).
pub(crate) enum Exit {
    /// In this cell, at these parameters.
    Inside(u32, DVec3),
    /// Outside the mesh, proved.
    Outside(ProvedExit),
    /// The structure must say.
    Undecided,
}

impl Boundary<'_> {
    /// Whether the point at `stretch.t` is outside the mesh, proved by parity from the point at
    /// `stretch.t_inside`, which is in it (see the module documentation): the segment crosses the
    /// boundary face `face` (`(cell, face)`) exactly once, with a margin of [`PARITY_MARGIN`]
    /// of the size of `stretch.inside_cell` (far above the containment tolerance by which the
    /// inside end may lie outside it), and may cross no other
    /// ([`BoundarySurface::may_cross_other`], then the count of crossings). Fast path only
    /// (the paper path asks the structure); the surface's node visits are counted in
    /// `surface_visits`.
    pub(crate) fn proven_outside(
        &self,
        stretch: Stretch<'_>,
        face: (u32, u8),
        work: &mut Work,
    ) -> bool {
        let Some(parity) = self.parity(stretch, face) else {
            return false;
        };
        let mut c = Counters::default();
        let crosses =
            parity
                .surface
                .may_cross_other(stretch.ray, stretch.range(), face, &mut c, |f| {
                    parity.crossings(f).map_or(true, |c| c.count() > 0)
                });
        work.surface(&c);
        !crosses
    }

    /// [`Boundary::proven_outside`] for a segment ahead of its inside end, with where it
    /// crosses `face` (the exit from the mesh, exactly) and the next boundary crossing from
    /// `stretch.t` on (up to `t_end`), found in the same traversal of the surface
    /// ([`BoundarySurface::sole_crossing_then_next`]). `None` where the point is not proved
    /// outside.
    pub(crate) fn proven_outside_until(
        &self,
        stretch: Stretch<'_>,
        face: (u32, u8),
        t_end: f64,
        work: &mut Work,
    ) -> Option<ProvedExit> {
        if stretch.t <= stretch.t_inside {
            return None;
        }
        let parity = self.parity(stretch, face)?;
        let mut c = Counters::default();
        let next = parity.surface.sole_crossing_then_next(
            stretch.ray,
            (stretch.t_inside, stretch.t),
            t_end,
            face,
            &mut c,
            |f| parity.crossings(f).map_or(true, |c| c.count() > 0),
        );
        work.surface(&c);
        next.map(|n| ProvedExit {
            crossing: parity.crossing,
            next: n.map_or((t_end, None), |(t, cell)| (t, Some(cell))),
        })
    }

    /// The common part of the proofs by parity: where `face` is crossed exactly once by the
    /// segment (and the path is the fast one, with a boundary surface), what the rest of the
    /// proof needs.
    fn parity<'s>(&'s self, stretch: Stretch<'s>, face: (u32, u8)) -> Option<Parity<'s>> {
        if !self.fast {
            return None;
        }
        let surface = self.surface?;
        let mesh = self.cells.mesh;
        let n = mesh.cell_count();
        if stretch.inside_cell as usize >= n || face.0 as usize >= n || face.1 >= 6 {
            return None;
        }
        let margin = PARITY_MARGIN
            * cell_bounds(&mesh.cell_corners(stretch.inside_cell as usize)).diagonal();
        let mut parity = Parity {
            surface,
            mesh,
            stretch,
            margin,
            crossing: f64::NAN,
        };
        match *parity.crossings(face)?.ts() {
            [t] => {
                parity.crossing = t;
                Some(parity)
            }
            _ => None,
        }
    }

    /// Where the sample at `stretch.t` lies when the march from the sample at `stretch.t_inside` left
    /// the mesh by the plane of the boundary face `face` (`(cell, face)`): outside where that
    /// is proved by parity ([`Boundary::proven_outside_until`], no cell tested), with the next
    /// boundary crossing up to `t_end`; else by a local boundary search from the cell (with
    /// `guess`, about the parameters there of the sample before) whose answer outside must be
    /// proved the same way.
    pub(crate) fn past_exit(
        &self,
        stretch: Stretch<'_>,
        face: (u32, u8),
        guess: DVec3,
        t_end: f64,
        work: &mut Work,
    ) -> Exit {
        // The march also stops at a face that is its own cell's neighbour: not a boundary face.
        if !self.cells.on_boundary(face.0, face.1 as usize) {
            return Exit::Undecided;
        }
        if let Some(next) = self.proven_outside_until(stretch, face, t_end, work) {
            return Exit::Outside(next);
        }
        let p = stretch.ray.at(stretch.t);
        match self.local_locate(p, face.0, guess, &mut None, &mut work.counters) {
            Local::Inside(c, q) => Exit::Inside(c, q),
            Local::Outside(f) | Local::Beyond(f) if f != face => self
                .proven_outside_until(stretch, f, t_end, work)
                .map_or(Exit::Undecided, Exit::Outside),
            _ => Exit::Undecided,
        }
    }
}
