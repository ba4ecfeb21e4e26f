//! The search for where a ray crosses the mesh's boundary between a point inside (a sample
//! in a cell) and a point outside, and the test of a point near a sample for being in the
//! mesh.
//!
//! # Finding the crossing
//! With complete face neighbours the crossing is found exactly: it is the first crossing of a
//! face without a neighbour — each a bilinear patch, the trilinear map's own face, whose
//! crossing by a line is the root of a quadratic
//! ([`crate::geometry::patch::segment_crossings`]). The boundary surface offers the faces
//! whose bounds the segment meets, nearest first
//! ([`super::surface::BoundarySurface::first_face_crossing`]); where one of them cannot be
//! told, the ray is followed from the inside sample's cell across the faces it crosses until
//! it crosses one without a neighbour ([`boundary_face_crossing`]). On the fast path, where
//! the sample past an exit is proved outside by parity ([`super::proof`]), the crossing of the
//! exit face is already in hand. Where neither can tell (a crossing within `1e-6` of a face's
//! edge, a grazing ray) or without neighbours, the crossing is found by [`BISECTIONS`]
//! bisection steps on exact mesh containment, then refined once by linear interpolation of
//! the violated parametric coordinate of the cell at the inside end of the bracket. Where the
//! refinement does not land inside the bracket, the bracket's midpoint is taken: the crossing
//! is then off by at most `step / 2^(BISECTIONS + 1)`.
//!
//! # Containment without the structure
//! Each bisection point is tested in the cell of the inside end of the bracket first. With
//! complete face neighbours (see [`crate::render::Neighbours`]) a point outside that cell is
//! followed locally: across the face it lies farthest beyond (by the cell's parametric
//! coordinates) that has a neighbour, up to [`MAX_BOUNDARY_WALK`] cells, until a cell holds
//! it — or it lies beyond faces without a neighbour only, i.e. beyond the mesh's boundary,
//! and is outside with no structure look-up. The structure decides where the local search
//! cannot (no neighbours, a degenerate face of a collapsed cell, the budget spent). An
//! "outside" for a point that does not lie between two samples (the ray's start and end, the
//! look-ahead at early termination) is confirmed by parity along the ray from the sample
//! inside where the boundary surface allows it ([`super::proof`]), by the structure
//! otherwise; so is a point the local search leaves beyond the plane of a boundary face with
//! no parameters (far beyond a thin cell).

use glam::DVec3;

use super::{Boundary, Stretch};
use crate::accel::Counters;
use crate::geometry::bounds::cell_bounds;
use crate::geometry::containment::{locate_in_cell, param_inside, CONTAINMENT_TOLERANCE};
use crate::geometry::inverse::invert;
use crate::mesh::topology::FaceKey;
use crate::render::ray::Ray;
use crate::render::stats::Work;
use crate::render::walk::march::{boundary_face_crossing, boundary_plane_crossing};
use crate::render::walk::point::{farthest_face, violated_face};

/// Bisection steps of a crossing search.
pub const BISECTIONS: u32 = 6;

/// Cells a boundary search tests locally before it asks the structure.
pub(crate) const MAX_BOUNDARY_WALK: usize = 6;

/// A bracket of a boundary crossing: `t_outside` outside the mesh, `t_inside` in cell
/// `inside.0` at parameters `inside.1`, and the outside end's parameters in that cell where a
/// search computed them.
struct Bracket {
    t_outside: f64,
    t_inside: f64,
    inside: (u32, DVec3),
    outside_q: Option<DVec3>,
}

/// A local boundary search's answer.
pub(crate) enum Local {
    /// In this cell, at these parameters.
    Inside(u32, DVec3),
    /// Beyond boundary faces only, farthest beyond this one (`(cell, face)`).
    Outside((u32, u8)),
    /// No parameters, beyond the plane of this boundary face (`(cell, face)`): outside where
    /// that is proved ([`Boundary::proven_outside`]), else the structure must say.
    Beyond((u32, u8)),
    /// The structure must say.
    Undecided,
}

/// How far parametric coordinates `q` lie beyond face `f` (0–5: `u = 0`, `u = 1`, `v = 0`,
/// `v = 1`, `w = 0`, `w = 1`); negative inside.
#[inline]
fn face_violation(q: DVec3, f: usize) -> f64 {
    match f {
        0 => -q.x,
        1 => q.x - 1.0,
        2 => -q.y,
        3 => q.y - 1.0,
        4 => -q.z,
        _ => q.z - 1.0,
    }
}

/// The refined crossing between `t_out` (parameters `q_out`, beyond face `f`) and `t_in`
/// (parameters `q_in`, inside): the zero of face `f`'s violation interpolated linearly, if it
/// lies strictly in the bracket.
#[inline]
fn interpolate_crossing(t_out: f64, q_out: DVec3, t_in: f64, q_in: DVec3, f: usize) -> Option<f64> {
    let (go, gi) = (face_violation(q_out, f), face_violation(q_in, f));
    if !(go > 0.0 && gi <= 0.0) {
        return None;
    }
    let t = t_out + (t_in - t_out) * (go / (go - gi));
    let (lo, hi) = (t_out.min(t_in), t_out.max(t_in));
    (t.is_finite() && t >= lo && t <= hi).then_some(t)
}

impl Boundary<'_> {
    /// For a boundary search: the cell holding the point at `stretch.t` if it lies in the mesh,
    /// where `stretch.t_inside` is in `cell` at about `guess` (which warm-starts Newton). `cell` is
    /// tested first. With complete face neighbours the search then goes on locally: across the
    /// face the point lies farthest beyond (by `cell`'s parametric coordinates) that has a
    /// neighbour, until a cell holds it or it lies beyond boundary faces only. That answer,
    /// outside, is then confirmed: by the boundary surface where it proves it (see
    /// [`Boundary::proven_outside`]), else by the structure. Without neighbours, or where the
    /// local search is undecided (a degenerate face, a budget of [`MAX_BOUNDARY_WALK`] cells,
    /// an inverse that fails), the structure answers. Every test is counted in `hex_tests` and
    /// `boundary_refinements`.
    ///
    /// A point outside the box of the mesh's points is outside the mesh (every cell lies in the
    /// convex hull of its corners) and needs no search: the ray's end on the (padded) clip box,
    /// typically, past a last sample in a cell whose face lies on the box.
    pub(crate) fn locate(
        &self,
        stretch: Stretch<'_>,
        cell: u32,
        guess: DVec3,
        work: &mut Work,
    ) -> Option<(u32, DVec3)> {
        let mut in_start = None;
        self.locate_from(stretch, cell, guess, true, &mut in_start, work)
    }

    /// [`Boundary::locate`], also giving the parametric coordinates of the point in `cell`
    /// where the search computed them (inside the cell or not) in `in_start`; an answer
    /// outside by the local search is confirmed only where `confirm`.
    fn locate_from(
        &self,
        stretch: Stretch<'_>,
        cell: u32,
        guess: DVec3,
        confirm: bool,
        in_start: &mut Option<DVec3>,
        work: &mut Work,
    ) -> Option<(u32, DVec3)> {
        let before = work.counters.hex_tests;
        let p = stretch.ray.at(stretch.t);
        if p.is_finite() && !self.bounds.contains(p) {
            return None;
        }
        let found = match self.local_locate(p, cell, guess, in_start, &mut work.counters) {
            Local::Inside(c, q) => Some((c, q)),
            Local::Outside(_) if !confirm => None,
            Local::Outside(face) | Local::Beyond(face)
                if self.proven_outside(stretch, face, work) =>
            {
                None
            }
            _ => self.accel.locate(self.cells.mesh, p, &mut work.counters),
        };
        work.stats.boundary_refinements += work.counters.hex_tests - before;
        found
    }

    /// The local part of [`Boundary::locate`]: the walk from `cell` over the cells' parametric
    /// coordinates.
    pub(crate) fn local_locate(
        &self,
        p: DVec3,
        cell: u32,
        guess: DVec3,
        in_start: &mut Option<DVec3>,
        counters: &mut Counters,
    ) -> Local {
        let mesh = self.cells.mesh;
        let neighbours = self.cells.neighbours;
        let cells = mesh.cells();
        if !neighbours.complete() {
            counters.hex_tests += 1;
            return match locate_in_cell(&mesh.cell_corners(cell as usize), p, Some(guess)) {
                Some(q) => Local::Inside(cell, q),
                None => Local::Undecided,
            };
        }
        let mut visited = [u32::MAX; MAX_BOUNDARY_WALK];
        let mut c = cell;
        let mut guess = Some(guess);
        for slot in 0..MAX_BOUNDARY_WALK {
            let Some(ids) = cells.get(c as usize) else {
                return Local::Undecided;
            };
            visited[slot] = c;
            let corners = mesh.cell_corners(c as usize);
            // Far beyond the cell the extended map says little (and Newton may not converge).
            let b = cell_bounds(&corners);
            if !b.padded(b.diagonal()).contains(p) {
                return Local::Undecided;
            }
            counters.hex_tests += 1;
            let Some(q) = invert(&corners, p, guess).param() else {
                // No parameters (the point lies many of this thin cell's thicknesses away):
                // go on across the face whose plane it lies farthest beyond, where there is a
                // cell not yet visited. The planes only choose the way; a decision still
                // needs parameters.
                let (f, dist) = farthest_face(&corners, p);
                let n = neighbours.neighbours(c)[f];
                if dist > 0.0 && n != u32::MAX && !visited.contains(&n) {
                    c = n;
                    guess = None;
                    continue;
                }
                return if dist > 0.0 && n == u32::MAX {
                    Local::Beyond((c, f as u8))
                } else {
                    Local::Undecided
                };
            };
            if slot == 0 {
                *in_start = Some(q);
            }
            if param_inside(q) {
                return Local::Inside(c, q);
            }
            let nb = neighbours.neighbours(c);
            let mut next: Option<(f64, u32)> = None;
            let mut beyond: Option<(f64, u8)> = None;
            for (f, &n) in nb.iter().enumerate() {
                let v = face_violation(q, f);
                if v <= CONTAINMENT_TOLERANCE {
                    continue;
                }
                if n == u32::MAX {
                    // A boundary face, unless it is degenerate (a collapsed edge or point of a
                    // wedge or pyramid: no area, never a neighbour, the mesh may go on there).
                    if FaceKey::of_cell(ids, f).is_degenerate() {
                        return Local::Undecided;
                    }
                    if beyond.map_or(true, |(bv, _)| v > bv) {
                        beyond = Some((v, f as u8));
                    }
                    continue;
                }
                if visited.contains(&n) {
                    continue;
                }
                if next.map_or(true, |(bv, _)| v > bv) {
                    next = Some((v, n));
                }
            }
            match next {
                Some((_, n)) => {
                    c = n;
                    guess = None;
                }
                None => {
                    // Beyond boundary faces only, or back towards cells already tested.
                    let beyond_visited = nb.iter().enumerate().any(|(f, &n)| {
                        n != u32::MAX
                            && face_violation(q, f) > CONTAINMENT_TOLERANCE
                            && visited.contains(&n)
                    });
                    return match beyond {
                        Some((_, f)) if !beyond_visited => Local::Outside((c, f)),
                        _ => Local::Undecided,
                    };
                }
            }
        }
        Local::Undecided
    }

    /// Whether the point at `t` of the ray is in the mesh, by a boundary search from the
    /// bracket's inside end; the bracket's end on the same side moves to `t`.
    fn probe(&self, ray: &Ray, t: f64, b: &mut Bracket, work: &mut Work) -> bool {
        let guess = match b.outside_q {
            Some(qo) => {
                b.inside.1 + (qo - b.inside.1) * ((t - b.t_inside) / (b.t_outside - b.t_inside))
            }
            None => b.inside.1,
        };
        let mut in_start = None;
        let stretch = Stretch {
            ray,
            t_inside: b.t_inside,
            t,
            inside_cell: b.inside.0,
        };
        match self.locate_from(stretch, b.inside.0, guess, false, &mut in_start, work) {
            Some(f) => {
                if f.0 != b.inside.0 {
                    b.outside_q = None;
                }
                b.t_inside = t;
                b.inside = f;
                true
            }
            None => {
                b.t_outside = t;
                b.outside_q = in_start;
                false
            }
        }
    }

    /// Where the ray crosses the mesh boundary between `t_outside` (a point outside the mesh)
    /// and `t_inside` (a point in cell `inside.0` at parameters `inside.1`): exactly where the
    /// neighbours are complete and the crossing can be told (see the module documentation),
    /// else to a bracket of `1/2^BISECTIONS` of the starting one, then one interpolation of
    /// the violated parametric coordinate.
    ///
    /// The bracket is first narrowed around an estimate: where the march from the inside end
    /// leaves the mesh by face planes ([`boundary_plane_crossing`]). The points half a final
    /// bracket to either side of it are tested; where the first is inside and the second
    /// outside, the bracket is final after two tests. Otherwise (a curved boundary face, a
    /// march that gave up) bisection finishes from whatever bracket the tests left.
    pub(crate) fn crossing(
        &self,
        ray: &Ray,
        t_outside: f64,
        t_inside: f64,
        inside: (u32, DVec3),
        work: &mut Work,
    ) -> f64 {
        let mesh = self.cells.mesh;
        if self.cells.neighbours.complete() {
            // The boundary surface solves only for the boundary faces near the segment; the
            // walk across the cells from the inside end, for each of their faces, where the
            // surface cannot tell.
            if let Some(surface) = self.surface {
                let mut c = Counters::default();
                let first = surface.first_face_crossing(ray, mesh, t_inside, t_outside, &mut c);
                work.surface(&c);
                if let Some(Some((t, _))) = first {
                    return t;
                }
            }
            if let Some(t) = boundary_face_crossing(&self.cells, inside.0, ray, t_inside, t_outside)
            {
                return t;
            }
        }
        let final_width = (t_outside - t_inside).abs() / f64::from(1u32 << BISECTIONS);
        let mut b = Bracket {
            t_outside,
            t_inside,
            inside,
            outside_q: None,
        };
        let estimate = boundary_plane_crossing(&self.cells, inside.0, ray, t_inside, t_outside);
        if let Some(t_est) = estimate {
            let toward_out = (t_outside - t_inside).signum() * 0.5 * final_width;
            let (lo, hi) = (t_est - toward_out, t_est + toward_out);
            let strictly_within = |t: f64, b: &Bracket| {
                t > b.t_inside.min(b.t_outside) && t < b.t_inside.max(b.t_outside)
            };
            if strictly_within(lo, &b)
                && self.probe(ray, lo, &mut b, work)
                && strictly_within(hi, &b)
            {
                self.probe(ray, hi, &mut b, work);
            }
        }
        // At most BISECTIONS halvings (the bound also ends the loop should rounding stall it).
        for _ in 0..BISECTIONS {
            if (b.t_outside - b.t_inside).abs() <= final_width * (1.0 + 1e-9) {
                break;
            }
            let mid = 0.5 * (b.t_outside + b.t_inside);
            self.probe(ray, mid, &mut b, work);
        }
        let q_out = match b.outside_q {
            Some(q) => Some(q),
            None => {
                let corners = mesh.cell_corners(b.inside.0 as usize);
                work.counters.hex_tests += 1;
                work.stats.boundary_refinements += 1;
                invert(&corners, ray.at(b.t_outside), Some(b.inside.1)).param()
            }
        };
        if let Some(q_out) = q_out {
            if let Some(t) = interpolate_crossing(
                b.t_outside,
                q_out,
                b.t_inside,
                b.inside.1,
                violated_face(q_out),
            ) {
                return t;
            }
        }
        0.5 * (b.t_outside + b.t_inside)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn linear_crossing() {
        let t = interpolate_crossing(
            0.0,
            DVec3::new(-0.2, 0.5, 0.5),
            1.0,
            DVec3::new(0.6, 0.5, 0.5),
            0,
        );
        assert!((t.unwrap() - 0.25).abs() < 1e-15);
        assert!(interpolate_crossing(0.0, DVec3::splat(0.5), 1.0, DVec3::splat(0.6), 0).is_none());
    }

    #[test]
    fn face_violation_is_the_distance_beyond_each_face() {
        let q = DVec3::new(1.25, -0.5, 0.5);
        assert_eq!(face_violation(q, 0), -1.25);
        assert_eq!(face_violation(q, 1), 0.25);
        assert_eq!(face_violation(q, 2), 0.5);
        assert_eq!(face_violation(q, 3), -1.5);
        assert_eq!(face_violation(q, 4), -0.5);
        assert_eq!(face_violation(q, 5), -0.5);
    }
}
