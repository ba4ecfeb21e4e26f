//! The work counters of a render ([`RenderStats`]).

use std::ops::AddAssign;

use serde::Serialize;

use crate::accel::Counters;

/// The work of a render.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize)]
pub struct RenderStats {
    /// Rays cast (pixels).
    pub rays: u64,
    /// Sample positions taken along the rays (inside the mesh's box, before termination).
    pub samples: u64,
    /// Samples found in a cell.
    pub samples_located: u64,
    /// Samples skipped because their cell is transparent (fast path).
    pub samples_skipped: u64,
    /// Samples found in the previous sample's cell (fast path).
    pub previous_cell_hits: u64,
    /// Samples found in a face neighbour of the previous sample's cell (fast path).
    pub neighbour_hits: u64,
    /// Cells tested with the inverse map.
    pub hex_tests: u64,
    /// Internal nodes (grids: top-level cells) visited.
    pub internal_visits: u64,
    /// Leaf nodes (grids: second-level cells) visited.
    pub leaf_visits: u64,
    /// Gradients evaluated (only with shading or gradient opacity on).
    pub gradient_evaluations: u64,
    /// Rays stopped by early termination.
    pub early_terminations: u64,
    /// Cells the fast path's walks stepped across by face planes, without an inverse map.
    pub walk_steps: u64,
    /// Samples the fast path passed over without point location: outside every piece's
    /// bound of the structure, or outside the mesh by its boundary surface (empty-space
    /// skipping), or in transparent space jumped over (see `transparent_jumps`).
    pub space_skips: u64,
    /// Samples the fast path located through the structure from scratch.
    pub structure_locates: u64,
    /// Samples the fast path located through the structure rather than by marching to them:
    /// more than [`RenderOptions::march_reach`] cells ahead, with the boundary surface
    /// proving the ray stays in the mesh up to them. Not counted in `structure_locates`; the
    /// structure's work is in `hex_tests`, `internal_visits` and `leaf_visits`, the surface's
    /// in `surface_visits`.
    pub far_locates: u64,
    /// Samples with no previous cell that the fast path found by a walk from the previous
    /// ray's first cell.
    pub entry_walk_hits: u64,
    /// Containment tests (and inverse maps) made to find where rays cross the mesh boundary
    /// between two samples (see [`super::boundary`]), and to locate the middles of chords
    /// (see `chord_samples`); also counted in `hex_tests`.
    pub boundary_refinements: u64,
    /// Samples the fast path found in a cell by the cell's face planes alone, with no inverse
    /// map: in a transparent cell, or in an intensity projection's cell that cannot beat the
    /// ray's extreme (the sample adds nothing, so needs no coordinates), behind each face
    /// plane by more than that face's deviation from it. Counted in `samples_located` and in
    /// `samples_skipped` (resp. `extreme_skips`), not in `hex_tests`.
    pub plane_certified: u64,
    /// Nodes of the boundary surface's BVH visited to skip the space outside the mesh, or
    /// faces offered from a ray's list where the rays have one (fast path, see
    /// [`super::surface`] and [`super::ray_faces`]).
    pub surface_visits: u64,
    /// Samples of an intensity projection that the fast path passed over, found in a cell
    /// whose scalar range cannot beat the ray's extreme so far ([`Blend::may_replace_in`]):
    /// not interpolated, and placed in their cell by its face planes alone where those settle
    /// it (then also counted in `plane_certified`, with no inverse map). Counted in
    /// `samples_located`.
    pub extreme_skips: u64,
    /// Jumps of an intensity projection's fast path over cells that cannot beat the ray's
    /// extreme so far: from a sample in such a cell to the next bound of a piece of a cell
    /// that may (BVH structures only, through [`Renderer::extreme_nodes`]; the samples passed
    /// over are counted in `space_skips`, the node visits in `internal_visits` and
    /// `leaf_visits`).
    pub extreme_jumps: u64,
    /// Jumps of the fast path over transparent space: from a sample in a transparent cell to
    /// the next bound of a piece of a cell that is not (BVHs), or to the next grid cell that
    /// references such a cell (grids); the samples passed over are counted in `space_skips`,
    /// the node or grid cell visits in `internal_visits` and `leaf_visits`.
    pub transparent_jumps: u64,
    /// Pieces of the rays in the mesh that held no sample (shorter than a step: a ray
    /// grazing the mesh, a thin part), each sampled once at its middle for its own length
    /// (see [`super::chords`]; only with a boundary surface). Not counted in `samples` or
    /// `samples_located`; locating their middles is counted in `hex_tests`.
    pub chord_samples: u64,
    /// Stretches of the rays outside the mesh between two samples in it (shorter than a
    /// step: a thin blade or gap crossed), found by the boundary surface and left out of the
    /// samples' segments (see [`super::chords`]).
    pub gaps: u64,
    /// Samples an error-bounded render added between two others where the stretch between
    /// them was too long for the error allowed, or crossed an active cell (see
    /// [`RenderOptions::max_error`]); also counted in `samples` and `samples_located`.
    pub refined_samples: u64,
    /// The scalar's gradients taken for its slope along the ray at the samples of an
    /// error-bounded render (shading and gradient opacity use the same gradient).
    pub slopes: u64,
    /// Stretches of rays an error-bounded render integrated through the transfer function,
    /// between two samples or from a sample to a crossing.
    pub integrated_stretches: u64,
}

impl AddAssign for RenderStats {
    fn add_assign(&mut self, o: RenderStats) {
        self.rays += o.rays;
        self.samples += o.samples;
        self.samples_located += o.samples_located;
        self.samples_skipped += o.samples_skipped;
        self.previous_cell_hits += o.previous_cell_hits;
        self.neighbour_hits += o.neighbour_hits;
        self.hex_tests += o.hex_tests;
        self.internal_visits += o.internal_visits;
        self.leaf_visits += o.leaf_visits;
        self.gradient_evaluations += o.gradient_evaluations;
        self.early_terminations += o.early_terminations;
        self.walk_steps += o.walk_steps;
        self.space_skips += o.space_skips;
        self.structure_locates += o.structure_locates;
        self.far_locates += o.far_locates;
        self.entry_walk_hits += o.entry_walk_hits;
        self.boundary_refinements += o.boundary_refinements;
        self.surface_visits += o.surface_visits;
        self.plane_certified += o.plane_certified;
        self.transparent_jumps += o.transparent_jumps;
        self.extreme_skips += o.extreme_skips;
        self.extreme_jumps += o.extreme_jumps;
        self.chord_samples += o.chord_samples;
        self.gaps += o.gaps;
        self.refined_samples += o.refined_samples;
        self.slopes += o.slopes;
        self.integrated_stretches += o.integrated_stretches;
    }
}

impl RenderStats {
    /// Adds the structure's work: hexahedra tested, internal and leaf visits.
    pub(crate) fn add_counters(&mut self, c: &Counters) {
        self.hex_tests += c.hex_tests;
        self.internal_visits += c.internal_visits;
        self.leaf_visits += c.leaf_visits;
    }
}

/// The work of one ray as it is done: the structure's (hexahedra tested, nodes visited, in
/// [`Counters`], added to the render's counters at the ray's end) and the rest of the
/// render's counters.
pub(crate) struct Work<'s> {
    /// The structure's work on this ray so far.
    pub(crate) counters: Counters,
    /// The render's counters.
    pub(crate) stats: &'s mut RenderStats,
}

impl<'s> Work<'s> {
    /// A ray's work, counted into `stats`.
    pub(crate) fn new(stats: &'s mut RenderStats) -> Work<'s> {
        Work {
            counters: Counters::default(),
            stats,
        }
    }

    /// Counts a traversal of the boundary surface (its nodes visited, or the faces offered
    /// from a ray's list) in [`RenderStats::surface_visits`].
    #[inline]
    pub(crate) fn surface(&mut self, c: &Counters) {
        self.stats.surface_visits += c.internal_visits + c.leaf_visits;
    }

    /// Adds the structure's work to the render's counters, at the ray's end.
    pub(crate) fn finish(self) {
        self.stats.add_counters(&self.counters);
    }
}
