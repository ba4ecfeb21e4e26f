//! Where a ray crosses the mesh's boundary, asked by the cast loop: the boundary surface
//! ([`surface`]) and the faces each ray of an image meets ([`ray_faces`]); the exact
//! crossings between two positions of a ray and what they mean for compositing ([`chords`]:
//! the exit of a sample, the entry of the next, the chords and gaps between); the search for
//! a crossing bracketed by a point inside and a point outside ([`search`]); and the proofs
//! by parity that a point past an exit lies outside ([`proof`]).
//!
//! A sample at `t_k` stands for `[t_k − step/2, t_k + step/2]`. Where its neighbour sample
//! (before or after) lies outside the mesh, the ray crossed the mesh boundary between the two;
//! the sample then stands for its segment cut at (or extended to) that crossing, so that the
//! in-mesh length of the ray is counted exactly rather than to a step. The boundary part
//! answers where; the accumulator cuts the segment.

pub(crate) mod chords;
pub(crate) mod proof;
pub(crate) mod ray_faces;
pub(crate) mod search;
pub(crate) mod surface;

use chords::{classify, side_unknown, Between};
use surface::BoundarySurface;

use crate::accel::{Accel, Counters};
use crate::geometry::bounds::Aabb;
use crate::render::ray::{End, Ray};
use crate::render::stats::Work;
use crate::render::walk::Cells;

/// The part of a ray from a point known to be in the mesh (at `t_inside`) to a point tested
/// (at `t`).
#[derive(Clone, Copy, Debug)]
pub(crate) struct Stretch<'r> {
    /// The ray.
    pub(crate) ray: &'r Ray<'r>,
    /// Where it is in the mesh.
    pub(crate) t_inside: f64,
    /// The point tested.
    pub(crate) t: f64,
    /// The cell the inside end was located in.
    pub(crate) inside_cell: u32,
}

impl Stretch<'_> {
    /// The ends' `t`, in increasing order.
    pub(crate) fn range(&self) -> (f64, f64) {
        (self.t_inside.min(self.t), self.t_inside.max(self.t))
    }
}

/// What the boundary questions of a render need: the mesh's cells and face neighbours, the
/// structure, the box of the mesh's points, the boundary surface (where the neighbours came
/// with one), and whether the render takes the fast path and cuts samples' segments at the
/// boundary.
#[derive(Clone, Copy)]
pub(crate) struct Boundary<'a> {
    /// The cells and their face neighbours.
    pub(crate) cells: Cells<'a>,
    /// The structure, for the points a local search cannot settle.
    pub(crate) accel: &'a Accel,
    /// The box of the mesh's points: a point outside it is outside the mesh.
    pub(crate) bounds: &'a Aabb,
    /// The faces without a neighbour, in a BVH.
    pub(crate) surface: Option<&'a BoundarySurface>,
    /// Whether the render takes the fast path (the proofs by parity are its own).
    pub(crate) fast: bool,
    /// Whether samples' segments are cut at the boundary (and chords sampled).
    pub(crate) segments: bool,
}

impl Boundary<'_> {
    /// The boundary surface whose crossings tell where a ray enters and leaves the mesh: only
    /// with boundary segments on and every face without a neighbour bounding the mesh.
    fn bounding_surface(&self) -> Option<&BoundarySurface> {
        if !self.segments || !self.cells.neighbours.complete() {
            return None;
        }
        self.surface
    }

    /// The boundary crossings between the positions `a` and `b` of the ray (`a.0 < b.0`, no
    /// sample between them), sorted by what they mean for compositing ([`chords`]): the exit
    /// of `a`'s sample, the entry of `b`'s, the chords between. `None` without a boundary
    /// surface whose faces bound the mesh (complete neighbours), or where the crossings cannot
    /// all be told robustly or disagree with what is known of the ends (the caller then keeps
    /// to its samples). The surface's node visits are counted in `surface_visits`.
    pub(crate) fn between(
        &self,
        ray: &Ray,
        a: (f64, End),
        b: (f64, End),
        work: &mut Work,
    ) -> Option<Between> {
        let surface = self.bounding_surface()?;
        let mesh = self.cells.mesh;
        let mut c = Counters::default();
        let crossings = surface.crossings_between(ray, mesh, a.0, b.0, &mut c);
        work.surface(&c);
        let crossings = crossings?;
        let mut a = a;
        if side_unknown(a.1, b.1) {
            // Neither end's side known (a ray too short for a sample between the eye or
            // clipping planes): the middle of the stretch up to the first crossing tells it.
            let to = crossings.ts().first().map_or(b.0, |c| c.0);
            let p = ray.at(0.5 * (a.0 + to));
            let mut counters = Counters::default();
            let inside = self.accel.locate(mesh, p, &mut counters).is_some();
            work.stats.add_counters(&counters);
            work.stats.boundary_refinements += counters.hex_tests;
            work.stats.structure_locates += 1;
            a.1 = match (a.1, inside) {
                (_, false) => End::Outside,
                (End::Passed, true) => End::Sample,
                (_, true) => End::In,
            };
        }
        classify(crossings.ts(), a, b)
    }

    /// Whether the ray may cross the mesh's boundary between `t0` and `t1`, by the boundary
    /// surface's conservative bound ([`BoundarySurface::next_crossing`]); `false` without a
    /// surface whose faces bound the mesh. For the paper path, which has no march to tell it
    /// a sample's neighbour lies across the boundary.
    pub(crate) fn may_cross(&self, ray: &Ray, t0: f64, t1: f64, work: &mut Work) -> bool {
        let Some(surface) = self.bounding_surface() else {
            return false;
        };
        let mut c = Counters::default();
        let next = surface.next_crossing(ray, t0, t1, &mut c);
        work.surface(&c);
        next.is_some()
    }
}
