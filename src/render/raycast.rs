//! The ray caster: the `paper` and `fast` paths, front-to-back compositing, early termination,
//! depth in and out, and the parallel loop over image tiles.
//!
//! # Sampling
//! A ray (origin `o`, unit direction `d`) is clipped to the mesh's bounding box (padded by
//! `1e-9` of its diagonal so samples on the boundary are kept) and to `t ≥ 0` (a camera inside
//! the mesh starts at the eye), then to the clipping planes if any
//! ([`RenderOptions::clip_planes`]), then to the opaque-geometry depth if one is given. Samples
//! lie at `t_k = t_in + (k + ½)·step`, `k = 0, 1, …` while `t_k < t_out`; each stands for a
//! segment of length `step` (midpoint rule), so the transfer table's opacities are corrected to
//! `step`.
//!
//! # Boundary-aware segments
//! Where a located sample follows an unlocated one (or the ray's start), or an unlocated one
//! follows it (or the ray's end), the ray crossed the mesh boundary in between: the crossing
//! is found exactly where the face neighbours are complete (the first boundary face the ray
//! crosses), else by bisection on exact mesh containment refined once (see
//! [`super::boundary`]), and the boundary sample stands for the in-mesh part of the ray from
//! the crossing to the middle between it and its located neighbour — its own segment cut at
//! the crossing, or extended to it over the outside neighbour's segment. Its opacity is that
//! of its length, `1 − (1 − α_step)^(length/step)`. The in-mesh length of a ray is thus exact
//! up to the crossing estimate instead of a step per crossing, which makes the error of an
//! image fall with the square of the step (midpoint rule) rather than linearly. The tests of a
//! crossing search count in [`RenderStats::hex_tests`] and
//! [`RenderStats::boundary_refinements`], not in the sample counts; a point outside the box of
//! the mesh's points (the ray's end on the clip box, typically) is outside with no search.
//! Where a clipping plane starts a ray inside the mesh, the first sample stands for the ray
//! from the plane (its step starts there); where one ends it inside the mesh, the last sample
//! ends at the plane, as at a boundary crossing. Where the opaque-geometry depth stops a ray
//! inside the mesh, the last sample keeps its full step.
//!
//! # Chords and gaps
//! The samples alone miss a piece of the ray in the mesh shorter than a step between two
//! samples outside it (a *chord*: a ray grazing the silhouette, a thin plate, a coarse mesh's
//! corner), and count as mesh a piece outside it between two samples in it (a *gap*: a thin
//! blade crossed). With a boundary surface ([`Neighbours::surface`], complete neighbours),
//! wherever the ray may cross the boundary between two positions (the fast path's exits from
//! the mesh and entries into it, samples past a possible crossing, the ray's ends; on the paper
//! path every pair the surface's bound does not rule out), every crossing in between is found
//! exactly ([`BoundarySurface::crossings_between`]) and sorted by [`super::chords`]: the
//! earlier sample's exit, the later one's entry, and the chords between, each sampled once at
//! its middle for its own length ([`RenderStats::chord_samples`]; a gap's ends cut the two
//! samples' segments, [`RenderStats::gaps`]). A constant medium's transmittance is then
//! exact for every ray, whatever its stretches' lengths (`tests/render.rs`). Where a crossing
//! cannot be told robustly (a ray through a boundary face's edge) or without the surface, the
//! samples alone decide, as above; a piece between a clipping plane or the eye and the
//! boundary is a chord like any other.
//!
//! # Interpolation and gradient opacity
//! A located sample's scalar is the trilinear interpolant of its cell's corner values, or with
//! [`Interpolation::Nearest`] the value of the nearest corner (cell data: the cell's value).
//! Its colour and step-corrected opacity come from the transfer table; with
//! [`RenderOptions::gradient_opacity`] set, the opacity per unit distance is multiplied by the
//! factor of the gradient magnitude before the step correction (see
//! [`super::transfer`]). The gradient (of the trilinear interpolant) is evaluated only when
//! shading or gradient opacity is on, and only for samples the transfer function does not
//! make transparent ([`RenderStats::gradient_evaluations`]).
//!
//! # Compositing and depth
//! Front to back: `C += T α c`, `T *= 1 − α` with `α` the step-corrected opacity and `c` the
//! (shaded) colour; the ray stops once `1 − T ≥ early_termination` (default 0.99). The depth
//! output of a pixel is the `t` of the first sample at which the accumulated opacity `1 − T`
//! reaches [`RenderOptions::depth_opacity`] (default 0.5), `+∞` if it never does. A depth
//! image given as input (same convention: distance along the ray from the eye or its plane)
//! stops each ray there, as opaque geometry would. With [`RenderOptions::blend`] set to a
//! maximum- or minimum-intensity projection the samples are not composited: the ray keeps its
//! extreme scalar and its pixel is that scalar's colour and opacity ([`Blend`]).
//!
//! # The two paths
//! - **paper**: every sample is located from scratch through the structure
//!   ([`Accel::locate`]) and interpolated trilinearly — what the talk measured.
//! - **fast**: the ray marches from cell to cell through exit faces ([`super::march`]), so a
//!   sample is proposed to the cell the ray is in at its `t` and tested there alone (Newton
//!   warm-started in the previous sample's cell, the cell's inverse-map set-up reused), with a
//!   walk over face neighbours ([`super::walk`]; from a [`Neighbours`] source, [`NoNeighbours`]
//!   without one) where that test fails, and the structure only where both give up or the ray
//!   has just entered the mesh. A sample more than [`RenderOptions::march_reach`] cells ahead
//!   (about: the distance past the current cell's exit in the ray's typical chord,
//!   [`super::march::March::cells_ahead`]) is located through the structure instead of by
//!   crossing every cell on the way, where the boundary surface proves the ray stays in the
//!   mesh from the previous sample up to it ([`RenderStats::far_locates`]); at large steps
//!   the crossings, not the samples, are most of a frame's work. Space outside the mesh is
//!   skipped: with a boundary surface ([`Neighbours::surface`], see [`super::surface`]),
//!   from every point known to be outside up to where the ray may first cross a boundary
//!   face; without one, by the structure's bounds ([`super::skip`]). Where the march leaves the mesh by the plane of a face
//!   without a neighbour, the next sample is proved outside by parity where it can be: the
//!   segment from the last sample inside crosses that face exactly once (a robust count of a
//!   line's crossings of a bilinear patch, [`crate::geometry::patch`]) and no other boundary
//!   face (the surface's bound, then the same count), so no cell is tested and the structure
//!   is not asked, and the exit's crossing is that face's; the same proof confirms the
//!   boundary searches' "outside" at the ray's ends. Where the rays have a projection
//!   ([`super::camera::RaySource::project`]), the surface's queries scan a list per ray of
//!   the faces whose boxes it meets, made once a frame by projecting the faces to the image
//!   ([`super::ray_faces`]), instead of traversing the surface's BVH. A sample whose cell's scalar range the
//!   transfer function maps to zero opacity everywhere is skipped without interpolation (it
//!   would add nothing); with a BVH, the ray then jumps to the next bound of a piece of a cell
//!   that is not so ([`super::skip::Skipper::next_visible`] over the nodes that hold one,
//!   [`Renderer::visible_nodes`]), passing over the samples before it, which lie in such
//!   cells or outside the mesh, and locates the next sample from that cell; with a grid, to
//!   the next grid cell that references such a cell
//!   ([`super::skip::Skipper::next_kept_in_grid`] over [`Renderer::visible_grid_cells`]).
//!   An intensity projection does the same on a BVH with the cells whose scalar range cannot
//!   beat the ray's extreme so far ([`Blend::may_replace_in`]), through each node's scalar
//!   range
//!   ([`Renderer::extreme_nodes`]). Where the table
//!   is transparent everywhere ([`TransferTable::transparent_everywhere`]) nothing could be
//!   seen: no ray takes a sample, and no transparency table is made. With the same
//!   neighbours, the image equals the paper path's up to the
//!   choice between two cells on a shared face (both valid, values equal to the inverse map's
//!   tolerance, `~1e-9` relative); the paper path without neighbours (as the CLI runs it)
//!   finds boundary crossings by bisection, to within `step / 2^(BISECTIONS + 1)` of the
//!   exact ones.
//!
//! Both count their work in [`RenderStats`].
//!
//! # Threads
//! The image is cut into square tiles ([`RenderOptions::tile`], default 16) rendered in
//! parallel with rayon; every pixel is computed alone, and the counters are integer sums, so
//! image and counters are identical whatever the number of threads.

use std::borrow::Cow;
use std::cell::Cell;
use std::ops::AddAssign;

use glam::DVec3;
use rayon::prelude::*;
use serde::Serialize;

use super::boundary::{face_violation, interpolate_crossing, partial_opacity, BISECTIONS};
use super::camera::{Camera, RayGenerator, RaySource};
use super::chords::{classify, side_unknown, Between, Chord, End};
use super::clip::ClipPlanes;
use super::image::Image;
use super::march::{boundary_face_crossing, boundary_plane_crossing, March};
use super::ray_faces::{FaceBins, RayFaces, TileFaces};
use super::shading::Shading;
use super::skip::Skipper;
use super::surface::{face_corners, BoundarySurface};
use super::transfer::{GradientOpacity, TransferFunction, TransferTable, DEFAULT_TABLE_SIZE};
use super::transparency::TransparentCells;
use super::walk::{
    farthest_face, violated_face, walk_within, WalkEnd, WalkWork, MAX_ENTRY_PLANE_STEPS,
};
use crate::accel::bvh::{NodeMask, NodeRanges};
use crate::accel::grid::GridMask;
use crate::accel::{Accel, Counters, Structure};
use crate::error::show_number;
use crate::geometry::bounds::{cell_bounds, Aabb};
use crate::geometry::containment::{locate_in_cell, param_inside, CONTAINMENT_TOLERANCE};
use crate::geometry::inverse::invert;
use crate::geometry::patch::{segment_crossings, Crossings};
use crate::geometry::trilinear::{index, interpolate, physical_gradient};
use crate::mesh::topology::FaceKey;
use crate::mesh::Association;
use crate::{Error, Mesh};

/// Which sampling path.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum RenderPath {
    /// Every sample located from scratch through the structure.
    Paper,
    /// Previous cell, face neighbours, then the structure; transparent cells skipped.
    Fast,
}

impl RenderPath {
    /// `paper` or `fast`.
    pub fn name(self) -> &'static str {
        match self {
            RenderPath::Paper => "paper",
            RenderPath::Fast => "fast",
        }
    }
}

impl std::str::FromStr for RenderPath {
    type Err = Error;
    fn from_str(s: &str) -> Result<Self, Error> {
        match s {
            "paper" => Ok(RenderPath::Paper),
            "fast" => Ok(RenderPath::Fast),
            _ => Err(Error::Invalid(format!(
                "unknown path '{s}' (expected paper or fast)"
            ))),
        }
    }
}

/// The face neighbours of a cell, for the fast path: six cell ids, `u32::MAX` for none.
/// Closures `Fn(u32) -> [u32; 6]` implement it.
///
/// A face without a neighbour is taken for the mesh's boundary by the boundary crossing
/// searches (see [`super::boundary`]): the source must pair every shared face, θ-seam faces
/// of coincident but separate points included (as
/// [`crate::mesh::topology::FaceNeighbors::build_with_tolerance`] does), or say it does not
/// with [`Neighbours::complete`].
pub trait Neighbours: Sync {
    /// The cells across the six faces of `cell` (`u32::MAX` where there is none).
    fn neighbours(&self, cell: u32) -> [u32; 6];

    /// Whether every shared face has its neighbour, so that a face with none is on the mesh's
    /// boundary (default `true`).
    fn complete(&self) -> bool {
        true
    }

    /// The mesh's boundary faces (those without a neighbour), for skipping the space
    /// outside the mesh; `None` (the default) where the source has none.
    fn surface(&self) -> Option<&BoundarySurface> {
        None
    }

    /// Starts loading the neighbours of `cell` into the cache (a hint; by default nothing).
    fn prefetch(&self, _cell: u32) {}
}

impl<F: Fn(u32) -> [u32; 6] + Sync> Neighbours for F {
    fn neighbours(&self, cell: u32) -> [u32; 6] {
        self(cell)
    }
}

impl Neighbours for crate::mesh::topology::FaceNeighbors {
    fn neighbours(&self, cell: u32) -> [u32; 6] {
        self.neighbors(cell)
    }

    /// Only once [`crate::mesh::topology::FaceNeighbors::check_boundary`] has found no
    /// hanging face.
    fn complete(&self) -> bool {
        self.is_closed()
    }
}

/// No neighbours known: the fast path goes from the previous cell straight to the structure.
#[derive(Clone, Copy, Debug, Default)]
pub struct NoNeighbours;

impl Neighbours for NoNeighbours {
    fn neighbours(&self, _cell: u32) -> [u32; 6] {
        [u32::MAX; 6]
    }

    fn complete(&self) -> bool {
        false
    }
}

/// How a sample's scalar is taken from its cell's corner values (point data; a cell value is
/// the same either way).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum Interpolation {
    /// Trilinear in the cell's parametric coordinates (VTK's `VTK_LINEAR_INTERPOLATION`).
    #[default]
    Linear,
    /// The value of the corner nearest in parametric coordinates (VTK's
    /// `VTK_NEAREST_INTERPOLATION`); a coordinate of exactly ½ goes to the lower corner.
    /// Gradients (shading, gradient opacity) are still those of the trilinear interpolant.
    Nearest,
}

impl Interpolation {
    /// `linear` or `nearest`.
    pub fn name(self) -> &'static str {
        match self {
            Interpolation::Linear => "linear",
            Interpolation::Nearest => "nearest",
        }
    }

    /// The scalar at parametric coordinates `p` (in `[0, 1]³`) from the corner values.
    ///
    /// ```
    /// use cylvol::render::Interpolation;
    /// use glam::DVec3;
    /// let f = [0.0, 1.0, 1.0, 0.0, 0.0, 1.0, 1.0, 0.0]; // f = u at the corners
    /// let p = DVec3::new(0.7, 0.2, 0.9);
    /// assert!((Interpolation::Linear.sample(&f, p) - 0.7).abs() < 1e-15);
    /// assert_eq!(Interpolation::Nearest.sample(&f, p), 1.0);
    /// ```
    #[inline]
    pub fn sample(self, values: &[f64; 8], p: DVec3) -> f64 {
        match self {
            Interpolation::Linear => interpolate(values, p),
            Interpolation::Nearest => {
                let corner = index(
                    (p.x > 0.5) as usize,
                    (p.y > 0.5) as usize,
                    (p.z > 0.5) as usize,
                );
                values[corner]
            }
        }
    }
}

impl std::str::FromStr for Interpolation {
    type Err = Error;
    fn from_str(s: &str) -> Result<Self, Error> {
        match s {
            "linear" => Ok(Interpolation::Linear),
            "nearest" => Ok(Interpolation::Nearest),
            _ => Err(Error::Invalid(format!(
                "unknown interpolation '{s}' (expected linear or nearest)"
            ))),
        }
    }
}

/// How a ray's samples make its pixel (VTK's volume mappers' `BlendMode`).
///
/// With [`Blend::Maximum`] or [`Blend::Minimum`] a ray keeps the largest (smallest) scalar
/// interpolated at its samples in the mesh, and its pixel is that scalar's colour with that
/// scalar's opacity per unit distance ([`TransferTable::unit_opacity`], not corrected to the
/// step), premultiplied — the colour and opacity VTK's maximum- and minimum-intensity
/// projections give the extreme scalar. Shading, gradient opacity, early termination,
/// boundary segments and the fast path's skipping of transparent cells belong to compositing
/// and are not used (a transparent cell may hold the extreme); the depth output is the
/// extreme sample's `t` where its opacity reaches `depth_opacity`. Instead the fast path
/// passes over the samples in cells whose scalar range cannot beat the ray's extreme so far
/// ([`Blend::may_replace_in`]; [`RenderStats::extreme_skips`]): no inverse map where the
/// cell's face planes settle that the sample lies in it, and no interpolation; with a BVH it
/// jumps over such cells to the next that may ([`RenderStats::extreme_jumps`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum Blend {
    /// Front-to-back emission-absorption compositing (VTK's `COMPOSITE_BLEND`).
    #[default]
    Composite,
    /// Maximum-intensity projection (VTK's `MAXIMUM_INTENSITY_BLEND`).
    Maximum,
    /// Minimum-intensity projection (VTK's `MINIMUM_INTENSITY_BLEND`).
    Minimum,
}

impl Blend {
    /// All three, in the order of their names.
    pub const ALL: [Blend; 3] = [Blend::Composite, Blend::Maximum, Blend::Minimum];

    /// `composite`, `max` or `min` (what [`str::parse`] reads).
    pub fn name(self) -> &'static str {
        match self {
            Blend::Composite => "composite",
            Blend::Maximum => "max",
            Blend::Minimum => "min",
        }
    }

    /// Whether `s` replaces `best` as the ray's extreme (never for compositing or a NaN `s`).
    ///
    /// ```
    /// use cylvol::render::Blend;
    /// assert!(Blend::Maximum.replaces(2.0, Some(1.0)));
    /// assert!(!Blend::Minimum.replaces(2.0, Some(1.0)));
    /// assert!(Blend::Minimum.replaces(2.0, None));
    /// assert!(!Blend::Maximum.replaces(f64::NAN, None));
    /// ```
    #[inline]
    pub fn replaces(self, s: f64, best: Option<f64>) -> bool {
        match (self, best) {
            (Blend::Composite, _) => false,
            (_, None) => !s.is_nan(),
            (Blend::Maximum, Some(b)) => s > b,
            (Blend::Minimum, Some(b)) => s < b,
        }
    }

    /// Whether a cell whose scalar lies in `range` (`[min, max]`) may hold a sample that
    /// replaces `best` as the ray's extreme: an interpolated scalar lies within its cell's
    /// corner values, so a cell whose maximum is not above the ray's maximum (whose minimum
    /// is not below its minimum) holds none. `true` for compositing, with no extreme yet, and
    /// for a NaN bound.
    ///
    /// ```
    /// use cylvol::render::Blend;
    /// assert!(!Blend::Maximum.may_replace_in([0.0, 1.0], Some(1.0)));
    /// assert!(Blend::Maximum.may_replace_in([0.0, 1.5], Some(1.0)));
    /// assert!(!Blend::Minimum.may_replace_in([0.5, 1.5], Some(0.5)));
    /// assert!(Blend::Minimum.may_replace_in([0.5, 1.5], None));
    /// ```
    #[inline]
    pub fn may_replace_in(self, range: [f64; 2], best: Option<f64>) -> bool {
        match (self, best) {
            (Blend::Composite, _) | (_, None) => true,
            (Blend::Maximum, Some(b)) => range[1] > b || range[1].is_nan(),
            (Blend::Minimum, Some(b)) => range[0] < b || range[0].is_nan(),
        }
    }
}

impl std::str::FromStr for Blend {
    type Err = Error;
    fn from_str(s: &str) -> Result<Self, Error> {
        crate::error::by_name(&Blend::ALL, Blend::name, s, "blend mode")
    }
}

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
    }
}

impl RenderStats {
    fn add_counters(&mut self, c: &Counters) {
        self.hex_tests += c.hex_tests;
        self.internal_visits += c.internal_visits;
        self.leaf_visits += c.leaf_visits;
    }
}

/// How to render.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RenderOptions {
    /// Image width in pixels.
    pub width: u32,
    /// Image height in pixels.
    pub height: u32,
    /// Distance between samples along a ray, in world units.
    pub step: f64,
    /// Paper or fast path.
    pub path: RenderPath,
    /// Shading, or `None` for none (then no gradient is evaluated).
    pub shading: Option<Shading>,
    /// Rays stop once their accumulated opacity reaches this (default 0.99; 1 or more never).
    pub early_termination: f64,
    /// The depth output is where the accumulated opacity first reaches this (default 0.5).
    pub depth_opacity: f64,
    /// Tile side in pixels for the parallel loop (default 16).
    pub tile: u32,
    /// Entries of the transfer-function table (default 1024).
    pub table_size: usize,
    /// Whether a sample next to a boundary crossing stands for the in-mesh part of its segment
    /// only, the crossing found by bisection (default: on). Off, every sample stands for a whole
    /// step: cheaper, but the error is then first order in the step (see `cylvol accuracy`).
    pub boundary_segments: bool,
    /// How the scalar is interpolated in a cell (default linear).
    pub interpolation: Interpolation,
    /// Gradient opacity (VTK's): a factor of the gradient magnitude on the scalar opacity per
    /// unit distance; `None` (the default) for none, and then no gradient is evaluated unless
    /// shading is on.
    pub gradient_opacity: Option<GradientOpacity>,
    /// How the samples make the pixel (default compositing; see [`Blend`]).
    pub blend: Blend,
    /// Clipping planes (default none): each ray is rendered only where every plane keeps it
    /// (see [`super::clip`]); where a plane cuts the mesh the volume ends there, as at its
    /// boundary.
    pub clip_planes: ClipPlanes,
    /// The fast path's reach by marching (default [`DEFAULT_MARCH_REACH`]): a sample about
    /// more than this many cells ahead of the previous one ([`super::march::March::cells_ahead`]),
    /// times the cells a look-up through the structure tests on average
    /// ([`Accel::lookup_tests`]: about 1 on a BVH of well-shaped cells, 7–19 on a grid), is
    /// located through the structure instead of by crossing every cell on the way, where
    /// the boundary surface proves the ray stays in the mesh up to it (so no exit and
    /// re-entry between the two is passed over; counted in [`RenderStats::far_locates`]).
    /// The image is the same either way: both find the cell holding the sample.
    /// `f64::INFINITY` always marches.
    pub march_reach: f64,
}

/// The default [`RenderOptions::march_reach`]: a look-up that tests one cell costs about as
/// much as crossing this many cells by their planes (measured on the refined mixer, whose
/// cylindrical BVH's look-ups test 1.02 cells, `cargo bench --bench render -- MESH 512 3
/// cyl-bvh fast --vtk-scene --step-factor=F --march-reach=R`).
pub const DEFAULT_MARCH_REACH: f64 = 6.0;

impl RenderOptions {
    /// Defaults for a `width × height` image with the given step: fast path, no shading,
    /// early termination at 0.99, depth at 0.5, 16-pixel tiles, 1024 table entries, boundary
    /// segments on, linear interpolation, no gradient opacity, compositing, no clipping plane.
    pub fn new(width: u32, height: u32, step: f64) -> RenderOptions {
        RenderOptions {
            width,
            height,
            step,
            path: RenderPath::Fast,
            shading: None,
            early_termination: 0.99,
            depth_opacity: 0.5,
            tile: 16,
            table_size: DEFAULT_TABLE_SIZE,
            boundary_segments: true,
            interpolation: Interpolation::Linear,
            gradient_opacity: None,
            blend: Blend::Composite,
            clip_planes: ClipPlanes::NONE,
            march_reach: DEFAULT_MARCH_REACH,
        }
    }
}

/// The default step: half the mean cell size, the cell size being its box diagonal ÷ √3 (the
/// edge of a cube with that diagonal). Falls back to 1/1000 of the mesh diagonal if every cell
/// is flat.
pub fn default_step(mesh: &Mesh) -> f64 {
    let n = mesh.cell_count().max(1) as f64;
    // Summed in fixed chunks, then the chunks in order: the same bits whatever the threads
    // (a parallel `sum` groups the terms as the work was split).
    const CHUNK: usize = 4096;
    let chunk_sums: Vec<f64> = (0..mesh.cell_count().div_ceil(CHUNK))
        .into_par_iter()
        .map(|k| {
            (k * CHUNK..((k + 1) * CHUNK).min(mesh.cell_count()))
                .map(|c| cell_bounds(&mesh.cell_corners(c)).diagonal())
                .sum::<f64>()
        })
        .collect();
    let total: f64 = chunk_sums.iter().sum();
    let step = total / n / 3f64.sqrt() / 2.0;
    if step > 0.0 && step.is_finite() {
        step
    } else {
        let b = mesh.bounds();
        let d = DVec3::new(b[1] - b[0], b[3] - b[2], b[5] - b[4]).length();
        if d > 0.0 && d.is_finite() {
            d / 1000.0
        } else {
            1.0
        }
    }
}

/// The active scalar of a mesh gathered for rendering: its values, association and range,
/// each cell's scalar range, and the mesh's bounds. Gathered once by [`ScalarField::gather`]
/// and shared by every [`Volume`] over the same mesh and scalars (one per structure, or one
/// per frame), so a render does not gather it again.
#[derive(Clone, Debug, PartialEq)]
pub struct ScalarField {
    association: Association,
    scalars: Vec<f64>,
    cell_ranges: Vec<[f64; 2]>,
    range: [f64; 2],
    bounds: Aabb,
}

impl ScalarField {
    /// Gathers the active scalar of `mesh` (an error if it has none, or if any of its values
    /// is NaN or infinite: [`Mesh::drawn_scalars`]) and each cell's range.
    pub fn gather(mesh: &Mesh) -> Result<ScalarField, Error> {
        let (association, scalars) = mesh.drawn_scalars()?;
        let range = mesh
            .scalar_range()
            .ok_or_else(|| Error::Invalid("the mesh has no scalar array to render".into()))?;
        let cell_ranges = match association {
            Association::Point => mesh
                .cells()
                .par_iter()
                .map(|c| {
                    c.iter()
                        .fold([f64::INFINITY, f64::NEG_INFINITY], |[lo, hi], &i| {
                            let v = scalars[i as usize];
                            [lo.min(v), hi.max(v)]
                        })
                })
                .collect(),
            Association::Cell => scalars.iter().map(|&v| [v, v]).collect(),
        };
        let b = mesh.bounds();
        let bounds = Aabb::new(DVec3::new(b[0], b[2], b[4]), DVec3::new(b[1], b[3], b[5]));
        Ok(ScalarField {
            association,
            scalars,
            cell_ranges,
            range,
            bounds,
        })
    }

    /// `[min, max]` of the scalar.
    pub fn range(&self) -> [f64; 2] {
        self.range
    }

    /// Whether the field has the shape of `mesh`'s cells and points.
    fn fits(&self, mesh: &Mesh) -> bool {
        let values = match self.association {
            Association::Point => mesh.point_count(),
            Association::Cell => mesh.cell_count(),
        };
        self.cell_ranges.len() == mesh.cell_count() && self.scalars.len() == values
    }
}

/// A mesh with its structure and active scalar ([`ScalarField`]), ready to render.
#[derive(Clone, Debug)]
pub struct Volume<'a> {
    mesh: &'a Mesh,
    accel: &'a Accel,
    field: Cow<'a, ScalarField>,
}

impl<'a> Volume<'a> {
    /// Gathers the active scalar of `mesh` (an error if it has none) and each cell's range.
    pub fn new(mesh: &'a Mesh, accel: &'a Accel) -> Result<Volume<'a>, Error> {
        Ok(Volume {
            mesh,
            accel,
            field: Cow::Owned(ScalarField::gather(mesh)?),
        })
    }

    /// A volume over a field gathered before from the same mesh (an error if its sizes do
    /// not fit the mesh).
    ///
    /// ```
    /// use cylvol::accel::{Accel, AccelParams, StructureKind};
    /// use cylvol::axis::Axis;
    /// use cylvol::datasets::{generate, Dataset};
    /// use cylvol::render::{ScalarField, Volume};
    /// let a = generate(Dataset::PumpInlet, 2000).unwrap();
    /// let b = generate(Dataset::PumpInlet, 4000).unwrap();
    /// let params = AccelParams::default();
    /// let accel = Accel::build(&a, StructureKind::CartBvh, &Axis::Z, &params).unwrap();
    /// let field = ScalarField::gather(&a).unwrap();
    /// let v = Volume::with_field(&a, &accel, &field).unwrap();
    /// assert_eq!(v.scalar_range(), Volume::new(&a, &accel).unwrap().scalar_range());
    /// assert_eq!(v.cell_range(7), Volume::new(&a, &accel).unwrap().cell_range(7));
    /// assert!(Volume::with_field(&b, &accel, &field).is_err());
    /// ```
    pub fn with_field(
        mesh: &'a Mesh,
        accel: &'a Accel,
        field: &'a ScalarField,
    ) -> Result<Volume<'a>, Error> {
        if !field.fits(mesh) {
            return Err(Error::Invalid(
                "the scalar field was gathered from another mesh".into(),
            ));
        }
        Ok(Volume {
            mesh,
            accel,
            field: Cow::Borrowed(field),
        })
    }

    /// The mesh.
    pub fn mesh(&self) -> &Mesh {
        self.mesh
    }

    /// The structure.
    pub fn accel(&self) -> &Accel {
        self.accel
    }

    /// `[min, max]` of the active scalar.
    pub fn scalar_range(&self) -> [f64; 2] {
        self.field.range
    }

    /// `[min, max]` of the scalar over cell `c` (its corners' values for point data).
    pub fn cell_range(&self, c: u32) -> [f64; 2] {
        self.field.cell_ranges[c as usize]
    }
}

/// The result of one ray.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RayResult {
    /// Premultiplied colour and accumulated opacity.
    pub rgba: [f64; 4],
    /// The depth sample's `t` (see the module documentation), `+∞` if none.
    pub depth: f64,
}

/// A composited sample whose segment may still end at a boundary crossing.
struct Last {
    t: f64,
    /// The segment's start where it is not `t − step/2` (a boundary crossing).
    start: Option<f64>,
    rgb: [f64; 3],
    alpha_step: f64,
    transmittance_before: f64,
    color_before: [f64; 3],
    depth_before: f64,
    /// The sample's cell and (unclamped) parameters.
    inside: (u32, DVec3),
}

/// Front-to-back accumulation along one ray.
struct Accum {
    transmittance: f64,
    color: [f64; 3],
    depth: f64,
    last: Option<Last>,
}

impl Accum {
    /// Composites `l` over the segment from its start to `end`, from the state before it.
    fn composite(&mut self, l: &Last, end: f64, step: f64, depth_opacity: f64) {
        let a = match l.start {
            None => partial_opacity(l.alpha_step, 1.0),
            Some(s) => partial_opacity(l.alpha_step, ((end - s) / step).max(0.0)),
        };
        self.transmittance = l.transmittance_before;
        self.color = l.color_before;
        self.depth = l.depth_before;
        let w = self.transmittance * a;
        for ch in 0..3 {
            self.color[ch] += w * l.rgb[ch];
        }
        self.transmittance *= 1.0 - a;
        if self.depth.is_infinite() && 1.0 - self.transmittance >= depth_opacity {
            self.depth = l.t;
        }
    }

    /// Recomposites `l`, whose segment ends at the boundary crossing `exit`.
    fn exit(&mut self, mut l: Last, exit: f64, step: f64, depth_opacity: f64) {
        let start = l.start.unwrap_or(l.t - 0.5 * step);
        l.start = Some(start);
        self.composite(&l, exit, step, depth_opacity);
    }
}

/// What a renderer derives from its transfer table and volume before its rays: the cells the
/// table makes wholly transparent, the structure's nodes that hold a visible cell, and (for an
/// intensity projection) the scalar range below each node ([`Renderer::into_derived`]). A
/// later renderer of the same volume (same mesh, structure and scalars) takes them over where
/// its table is the same ([`Renderer::with_derived`]), as a mapper's next frame does, instead
/// of making them again.
#[derive(Debug)]
pub struct Derived {
    table: TransferTable,
    transparent: TransparentCells,
    visible: Option<Option<NodeMask>>,
    visible_grid: Option<Option<GridMask>>,
    extreme_nodes: Option<Option<NodeRanges>>,
}

/// A volume with a transfer table and options: casts rays and renders images.
pub struct Renderer<'a> {
    volume: &'a Volume<'a>,
    table: TransferTable,
    options: RenderOptions,
    neighbours: &'a dyn Neighbours,
    clip_box: Aabb,
    /// The cells the table makes wholly transparent, for the fast path; made before a render's
    /// rays are cast (or on a single ray's first use).
    transparent: std::sync::OnceLock<TransparentCells>,
    /// The structure's nodes holding a piece of a cell that is not wholly transparent, for
    /// the fast path's jumps over transparent space (`None` for a grid); made with the
    /// transparent cells.
    visible: std::sync::OnceLock<Option<NodeMask>>,
    /// The grid cells referencing a cell that is not wholly transparent, for the fast path's
    /// jumps over transparent space on a grid (`None` for a BVH); made with the transparent
    /// cells.
    visible_grid: std::sync::OnceLock<Option<GridMask>>,
    /// The scalar range below each of the structure's nodes, for an intensity projection's
    /// jumps over cells that cannot beat the extreme (`None` for a grid).
    extreme_nodes: std::sync::OnceLock<Option<NodeRanges>>,
}

/// A bracket of a boundary crossing: `t_outside` outside the mesh, `t_inside` in cell
/// `inside.0` at parameters `inside.1`, and the outside end's parameters in that cell where a
/// search computed them.
struct Bracket {
    t_outside: f64,
    t_inside: f64,
    inside: (u32, DVec3),
    outside_q: Option<DVec3>,
}

/// The distance from a segment's ends, relative to the cell's size, within which a crossing
/// of a boundary face does not count for a proof by parity (the fast path in the module documentation).
pub const PARITY_MARGIN: f64 = 1e-6;

/// Cells a boundary search tests locally before it asks the structure.
pub const MAX_BOUNDARY_WALK: usize = 6;

/// The part of a ray from a point known to be in the mesh (at `t_inside`) to a point tested
/// (at `t`), for confirming that the point is outside (see [`Renderer::proven_outside`]).
#[derive(Clone, Copy, Debug)]
struct Segment<'f> {
    origin: DVec3,
    dir: DVec3,
    /// The boundary faces the ray meets, where a list was made for it.
    faces: Option<RayFaces<'f>>,
    t_inside: f64,
    t: f64,
    /// The cell the inside end was located in.
    inside_cell: u32,
}

impl Segment<'_> {
    /// The ends' `t`, in increasing order.
    fn range(&self) -> (f64, f64) {
        (self.t_inside.min(self.t), self.t_inside.max(self.t))
    }
}

/// A proof by parity under way ([`Renderer::proven_outside`]): the boundary surface, and the
/// segment with the margin from its ends within which a crossing does not count, and where
/// it crosses the face it leaves the mesh by.
struct Parity<'r> {
    surface: &'r BoundarySurface,
    mesh: &'r Mesh,
    seg: Segment<'r>,
    margin: f64,
    crossing: f64,
}

impl Parity<'_> {
    /// Where the segment crosses the boundary face `(cell, face)`, where that is told
    /// robustly ([`segment_crossings`]).
    fn crossings(&self, (cell, face): (u32, u8)) -> Option<Crossings> {
        let (lo, hi) = self.seg.range();
        let patch = face_corners(self.mesh, cell, face);
        segment_crossings(&patch, self.seg.origin, self.seg.dir, lo, hi, self.margin)
    }
}

/// A sample past an exit from the mesh proved outside ([`Renderer::proven_outside_until`]).
#[derive(Clone, Copy, Debug)]
struct ProvedExit {
    /// Where the ray crosses the boundary face it leaves by (exactly: the bilinear face).
    crossing: f64,
    /// The next possible boundary crossing: its `t` and the cell of its face (none: the
    /// ray's end).
    next: (f64, Option<u32>),
}

/// Where the fast path's sample past an exit from the mesh by the face planes is
/// ([`Renderer::exit_locate`]).
enum Exit {
    /// In this cell, at these parameters.
    Inside(u32, DVec3),
    /// Outside the mesh, proved.
    Outside(ProvedExit),
    /// The structure must say.
    Undecided,
}

/// A local boundary search's answer.
enum Local {
    /// In this cell, at these parameters.
    Inside(u32, DVec3),
    /// Beyond boundary faces only, farthest beyond this one (`(cell, face)`).
    Outside((u32, u8)),
    /// No parameters, beyond the plane of this boundary face (`(cell, face)`): outside where
    /// that is proved ([`Renderer::proven_outside`]), else the structure must say.
    Beyond((u32, u8)),
    /// The structure must say.
    Undecided,
}

/// `Some(expr)` with `b` bound to the structure's BVH (of boxes or of sectors), `None` for a
/// grid: what the renderer derives per node, written once for both kinds of BVH.
macro_rules! on_bvh {
    ($structure:expr, $b:ident => $e:expr) => {
        match $structure {
            Structure::CartBvh($b) => Some($e),
            Structure::CylBvh($b) => Some($e),
            Structure::Grid(_) => None,
        }
    };
}

/// Samples per ray beyond which a render is refused (a step far too small for the mesh).
pub const MAX_SAMPLES_PER_RAY: f64 = 1e7;

impl<'a> Renderer<'a> {
    /// Samples `transfer` over the volume's scalar range for `options.step`; fails on a bad
    /// transfer function, step, or one so small that a ray would take more than
    /// [`MAX_SAMPLES_PER_RAY`] samples across the mesh.
    pub fn new(
        volume: &'a Volume<'a>,
        transfer: &TransferFunction,
        options: &RenderOptions,
    ) -> Result<Renderer<'a>, Error> {
        if options.march_reach.is_nan() || options.march_reach < 0.0 {
            return Err(Error::Invalid(format!(
                "march reach {} must be a number of cells, 0 or more (inf to always march)",
                show_number(options.march_reach)
            )));
        }
        let [lo, hi] = volume.field.range;
        let table = transfer.table(lo, hi, options.step, options.table_size)?;
        let diag = volume.field.bounds.diagonal();
        if diag / options.step > MAX_SAMPLES_PER_RAY {
            return Err(Error::Invalid(format!(
                "step {} is too small for a mesh of diagonal {}",
                show_number(options.step),
                show_number(diag)
            )));
        }
        let mag = volume
            .field
            .bounds
            .min
            .abs()
            .max(volume.field.bounds.max.abs())
            .max_element();
        let clip_box = volume
            .field
            .bounds
            .padded(1e-9 * diag + 8.0 * f64::EPSILON * mag);
        Ok(Renderer {
            volume,
            table,
            options: *options,
            neighbours: &NoNeighbours,
            clip_box,
            transparent: std::sync::OnceLock::new(),
            visible: std::sync::OnceLock::new(),
            visible_grid: std::sync::OnceLock::new(),
            extreme_nodes: std::sync::OnceLock::new(),
        })
    }

    /// Uses `neighbours` for the fast path's second test.
    pub fn with_neighbours(mut self, neighbours: &'a dyn Neighbours) -> Renderer<'a> {
        self.neighbours = neighbours;
        self
    }

    /// What this renderer derived before its rays (`None` if it made nothing yet), for a later
    /// renderer of the same volume ([`Renderer::with_derived`]).
    pub fn into_derived(self) -> Option<Derived> {
        let transparent = self.transparent.into_inner()?;
        Some(Derived {
            table: self.table,
            transparent,
            visible: self.visible.into_inner(),
            visible_grid: self.visible_grid.into_inner(),
            extreme_nodes: self.extreme_nodes.into_inner(),
        })
    }

    /// Takes over what an earlier renderer of the same volume derived, if its transfer table
    /// is this renderer's (else `derived` is dropped and this renderer makes its own). The
    /// caller answers for the volume being the same: the same mesh, structure and scalars.
    pub fn with_derived(self, derived: Derived) -> Renderer<'a> {
        if derived.table == self.table {
            let _ = self.transparent.set(derived.transparent);
            if let Some(visible) = derived.visible {
                let _ = self.visible.set(visible);
            }
            if let Some(visible) = derived.visible_grid {
                let _ = self.visible_grid.set(visible);
            }
            if let Some(ranges) = derived.extreme_nodes {
                let _ = self.extreme_nodes.set(ranges);
            }
        }
        self
    }

    /// The options.
    pub fn options(&self) -> &RenderOptions {
        &self.options
    }

    /// The transfer table in use.
    pub fn table(&self) -> &TransferTable {
        &self.table
    }

    /// Whether the fast path can skip every ray: the table is transparent everywhere, so no
    /// sample adds anything (the paper path, a measurement, samples all the same).
    #[inline]
    fn nothing_visible(&self) -> bool {
        self.options.path == RenderPath::Fast && self.table.transparent_everywhere()
    }

    /// The cells the transfer table makes wholly transparent (made on first use, on the
    /// calling thread; [`Renderer::render_rays`] makes it in parallel before casting).
    pub fn transparent_cells(&self) -> &TransparentCells {
        self.transparent.get_or_init(|| {
            TransparentCells::new_sequential(&self.volume.field.cell_ranges, &self.table)
        })
    }

    /// The nodes of the structure holding a piece of a cell that the table does not make
    /// wholly transparent (`None` for a grid, see [`Renderer::visible_grid_cells`]):
    /// made on first use, on the calling thread, like [`Renderer::transparent_cells`].
    pub fn visible_nodes(&self) -> Option<&NodeMask> {
        self.visible
            .get_or_init(|| self.make_visible_nodes(false))
            .as_ref()
    }

    /// The grid cells referencing a cell that the table does not make wholly transparent
    /// (`None` for a BVH): what the fast path's jumps over transparent space walk through on
    /// a grid ([`Skipper::next_kept_in_grid`]). Made on first use, on the calling thread, like
    /// [`Renderer::transparent_cells`].
    pub fn visible_grid_cells(&self) -> Option<&GridMask> {
        self.visible_grid
            .get_or_init(|| self.make_visible_grid_cells(false))
            .as_ref()
    }

    fn make_visible_grid_cells(&self, parallel: bool) -> Option<GridMask> {
        let Structure::Grid(g) = self.volume.accel.structure() else {
            return None;
        };
        let transparent = self.transparent_cells();
        let visible = |c: u32| !transparent.contains(c);
        Some(if parallel {
            g.cells_holding(visible)
        } else {
            g.cells_holding_sequential(visible)
        })
    }

    /// The scalar range of the cells below each of the structure's nodes (`None` for a
    /// grid), for an intensity projection's jumps over the cells that cannot beat a ray's
    /// extreme: made on first use, on the calling thread, like [`Renderer::visible_nodes`]
    /// ([`Renderer::render_rays`] makes it in parallel for a projection's fast path).
    pub fn extreme_nodes(&self) -> Option<&NodeRanges> {
        self.extreme_nodes
            .get_or_init(|| self.make_extreme_nodes(false))
            .as_ref()
    }

    fn make_extreme_nodes(&self, parallel: bool) -> Option<NodeRanges> {
        let range = |c: u32| self.volume.cell_range(c);
        on_bvh!(self.volume.accel.structure(), b => if parallel {
            b.node_ranges(range)
        } else {
            b.node_ranges_sequential(range)
        })
    }

    fn make_visible_nodes(&self, parallel: bool) -> Option<NodeMask> {
        let transparent = self.transparent_cells();
        let visible = |c: u32| !transparent.contains(c);
        on_bvh!(self.volume.accel.structure(), b => if parallel {
            b.nodes_holding(visible)
        } else {
            b.nodes_holding_sequential(visible)
        })
    }

    /// The ray's `[t_in, t_out]` within the mesh's (padded) box, `t ≥ 0` and the clipping
    /// planes, if not empty.
    pub fn clip(&self, origin: DVec3, dir: DVec3) -> Option<(f64, f64)> {
        let span = self.box_span(origin, dir)?;
        self.options.clip_planes.clip_span(origin, dir, span)
    }

    /// The ray's `[t_in, t_out]` within the mesh's (padded) box and `t ≥ 0`, if not empty.
    fn box_span(&self, origin: DVec3, dir: DVec3) -> Option<(f64, f64)> {
        let (mut t_in, mut t_out) = (0.0f64, f64::INFINITY);
        for a in 0..3 {
            let (o, d) = (origin[a], dir[a]);
            let (lo, hi) = (self.clip_box.min[a], self.clip_box.max[a]);
            if d == 0.0 {
                // Parallel to this slab: inside it or missing the box.
                if !(o >= lo && o <= hi) {
                    return None;
                }
                continue;
            }
            let (t0, t1) = ((lo - o) / d, (hi - o) / d);
            t_in = t_in.max(t0.min(t1));
            t_out = t_out.min(t0.max(t1));
        }
        if !(t_in.is_finite() && t_out.is_finite()) {
            return None;
        }
        (t_in < t_out).then_some((t_in, t_out))
    }

    /// Casts one ray (unit `dir`), stopping at `t_stop` (opaque geometry; `+∞` for none).
    pub fn cast(
        &self,
        origin: DVec3,
        dir: DVec3,
        t_stop: f64,
        stats: &mut RenderStats,
    ) -> RayResult {
        let mut hint = None;
        self.cast_with_hint(origin, dir, t_stop, &mut hint, None, stats)
    }

    /// The fast path's location of the sample at `t` on the ray with no previous cell: a march
    /// along the ray from `surface_cell` (the cell of the boundary face the ray may enter
    /// through), or else a walk from `hint` (the first cell of the previous ray, usually near);
    /// the structure where they fail.
    #[allow(clippy::too_many_arguments)]
    fn locate_entry(
        &self,
        origin: DVec3,
        dir: DVec3,
        t: f64,
        surface_cell: Option<u32>,
        hint: Option<u32>,
        march: &mut March,
        counters: &mut Counters,
        stats: &mut RenderStats,
    ) -> Option<(u32, DVec3)> {
        let mesh = self.volume.mesh;
        let p = origin + dir * t;
        let mut work = WalkWork::default();
        let end = match (surface_cell, hint) {
            (Some(c), _) => {
                march.move_to(mesh, c, origin, dir);
                let never = |_| false;
                Some(march.locate(
                    mesh,
                    self.neighbours,
                    origin,
                    dir,
                    t,
                    None,
                    &never,
                    &mut work,
                ))
            }
            (None, Some(h)) => Some(walk_within(
                mesh,
                self.neighbours,
                h,
                None,
                p,
                MAX_ENTRY_PLANE_STEPS,
                &mut work,
            )),
            (None, None) => None,
        };
        counters.hex_tests += work.tests;
        stats.walk_steps += work.plane_steps;
        if let Some(WalkEnd::Found(c, q)) = end {
            stats.entry_walk_hits += 1;
            return Some((c, q));
        }
        stats.structure_locates += 1;
        self.volume.accel.locate(mesh, p, counters)
    }

    /// For a boundary search: the cell holding the point at `seg.t` if it lies in the mesh,
    /// where `seg.t_inside` is in `cell` at about `guess` (which warm-starts Newton). `cell` is
    /// tested first. With complete face neighbours the search then goes on locally: across the
    /// face the point lies farthest beyond (by `cell`'s parametric coordinates) that has a
    /// neighbour, until a cell holds it or it lies beyond boundary faces only. That answer,
    /// outside, is then confirmed: by the boundary surface where it proves it (see
    /// [`Renderer::proven_outside`]), else by the structure. Without neighbours, or where the
    /// local search is undecided (a degenerate face, a budget of [`MAX_BOUNDARY_WALK`] cells,
    /// an inverse that fails), the structure answers. Every test is counted in `hex_tests` and
    /// `boundary_refinements`.
    ///
    /// A point outside the box of the mesh's points is outside the mesh (every cell lies in the
    /// convex hull of its corners) and needs no search: the ray's end on the (padded) clip box,
    /// typically, past a last sample in a cell whose face lies on the box.
    fn boundary_locate(
        &self,
        seg: Segment<'_>,
        cell: u32,
        guess: DVec3,
        counters: &mut Counters,
        stats: &mut RenderStats,
    ) -> Option<(u32, DVec3)> {
        let mut in_start = None;
        self.boundary_locate_from(seg, cell, guess, true, &mut in_start, counters, stats)
    }

    /// Whether the point at `seg.t` is outside the mesh, proved by parity from the point at
    /// `seg.t_inside`, which is in it. Along the segment between them the ray passes between
    /// the mesh and the space outside only where it crosses a boundary face. It is proved
    /// where the segment crosses the boundary face `face` (`(cell, face)`) exactly once,
    /// transversally, away from the face's edges and from both ends
    /// ([`crate::geometry::patch::segment_crossings`], with a margin of [`PARITY_MARGIN`] of
    /// the size of `seg.inside_cell`, far above the containment tolerance by which the inside
    /// end may lie outside it), and may cross no other: by the boundary surface's
    /// conservative bound ([`BoundarySurface::may_cross_other`]), then for the faces that
    /// bound leaves, by their count of crossings (zero, told robustly). Fast path only (the
    /// paper path asks the structure); the surface's node visits are counted in
    /// `surface_visits`.
    fn proven_outside(&self, seg: Segment<'_>, face: (u32, u8), stats: &mut RenderStats) -> bool {
        let Some(parity) = self.parity(seg, face) else {
            return false;
        };
        let mut c = Counters::default();
        let (lo, hi) = seg.range();
        let crosses = parity.surface.may_cross_other(
            seg.faces,
            seg.origin,
            seg.dir,
            lo,
            hi,
            face,
            &mut c,
            |f| parity.crossings(f).map_or(true, |c| c.count() > 0),
        );
        stats.surface_visits += c.internal_visits + c.leaf_visits;
        !crosses
    }

    /// [`Renderer::proven_outside`] for a segment ahead of its inside end, with where it
    /// crosses `face` (the exit from the mesh, exactly) and the next boundary crossing from
    /// `seg.t` on (up to `t_end`), found in the same traversal of the surface
    /// ([`BoundarySurface::sole_crossing_then_next`]). `None` where the point is not proved
    /// outside.
    fn proven_outside_until(
        &self,
        seg: Segment<'_>,
        face: (u32, u8),
        t_end: f64,
        stats: &mut RenderStats,
    ) -> Option<ProvedExit> {
        if seg.t <= seg.t_inside {
            return None;
        }
        let parity = self.parity(seg, face)?;
        let mut c = Counters::default();
        let next = parity.surface.sole_crossing_then_next(
            seg.faces,
            seg.origin,
            seg.dir,
            seg.t_inside,
            seg.t,
            t_end,
            face,
            &mut c,
            |f| parity.crossings(f).map_or(true, |c| c.count() > 0),
        );
        stats.surface_visits += c.internal_visits + c.leaf_visits;
        next.map(|n| ProvedExit {
            crossing: parity.crossing,
            next: n.map_or((t_end, None), |(t, cell)| (t, Some(cell))),
        })
    }

    /// The common part of the proofs by parity: where `face` is crossed exactly once by the
    /// segment (and the path is the fast one, with a boundary surface), what the rest of the
    /// proof needs.
    fn parity<'s>(&'s self, seg: Segment<'s>, face: (u32, u8)) -> Option<Parity<'s>> {
        if self.options.path != RenderPath::Fast {
            return None;
        }
        let surface = self.neighbours.surface()?;
        let mesh = self.volume.mesh;
        let n = mesh.cell_count();
        if seg.inside_cell as usize >= n || face.0 as usize >= n || face.1 >= 6 {
            return None;
        }
        let margin =
            PARITY_MARGIN * cell_bounds(&mesh.cell_corners(seg.inside_cell as usize)).diagonal();
        let mut parity = Parity {
            surface,
            mesh,
            seg,
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

    /// The fast path's location of the sample at `seg.t` where the march from the sample at
    /// `seg.t_inside` left the mesh by the plane of the boundary face `face` (`(cell, face)`):
    /// outside where that is proved by parity ([`Renderer::proven_outside_until`], no cell
    /// tested), with the next boundary crossing up to `t_end`; else a local boundary search
    /// from the cell (with `guess`, about the parameters there of the sample before) whose
    /// answer outside must be proved the same way.
    fn exit_locate(
        &self,
        seg: Segment<'_>,
        face: (u32, u8),
        guess: DVec3,
        t_end: f64,
        counters: &mut Counters,
        stats: &mut RenderStats,
    ) -> Exit {
        // The march also stops at a face that is its own cell's neighbour: not a boundary face.
        let boundary = self
            .neighbours
            .neighbours(face.0)
            .get(face.1 as usize)
            .is_some_and(|&n| n == u32::MAX);
        if !boundary {
            return Exit::Undecided;
        }
        if let Some(next) = self.proven_outside_until(seg, face, t_end, stats) {
            return Exit::Outside(next);
        }
        let p = seg.origin + seg.dir * seg.t;
        match self.local_boundary_locate(p, face.0, guess, &mut None, counters) {
            Local::Inside(c, q) => Exit::Inside(c, q),
            Local::Outside(f) | Local::Beyond(f) if f != face => self
                .proven_outside_until(seg, f, t_end, stats)
                .map_or(Exit::Undecided, Exit::Outside),
            _ => Exit::Undecided,
        }
    }

    /// [`Renderer::boundary_locate`], also giving the parametric coordinates of `p` in `cell`
    /// where the search computed them (inside the cell or not) in `in_start`.
    #[allow(clippy::too_many_arguments)]
    fn boundary_locate_from(
        &self,
        seg: Segment<'_>,
        cell: u32,
        guess: DVec3,
        confirm: bool,
        in_start: &mut Option<DVec3>,
        counters: &mut Counters,
        stats: &mut RenderStats,
    ) -> Option<(u32, DVec3)> {
        let mesh = self.volume.mesh;
        let before = counters.hex_tests;
        let p = seg.origin + seg.dir * seg.t;
        if p.is_finite() && !self.volume.field.bounds.contains(p) {
            return None;
        }
        let found = match self.local_boundary_locate(p, cell, guess, in_start, counters) {
            Local::Inside(c, q) => Some((c, q)),
            Local::Outside(_) if !confirm => None,
            Local::Outside(face) | Local::Beyond(face) if self.proven_outside(seg, face, stats) => {
                None
            }
            _ => self.volume.accel.locate(mesh, p, counters),
        };
        stats.boundary_refinements += counters.hex_tests - before;
        found
    }

    /// The local part of [`Renderer::boundary_locate`].
    fn local_boundary_locate(
        &self,
        p: DVec3,
        cell: u32,
        guess: DVec3,
        in_start: &mut Option<DVec3>,
        counters: &mut Counters,
    ) -> Local {
        let mesh = self.volume.mesh;
        let cells = mesh.cells();
        if !self.neighbours.complete() {
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
                let n = self.neighbours.neighbours(c)[f];
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
            let nb = self.neighbours.neighbours(c);
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
    #[allow(clippy::too_many_arguments)]
    fn probe(
        &self,
        faces: Option<RayFaces<'_>>,
        origin: DVec3,
        dir: DVec3,
        t: f64,
        b: &mut Bracket,
        counters: &mut Counters,
        stats: &mut RenderStats,
    ) -> bool {
        let guess = match b.outside_q {
            Some(qo) => {
                b.inside.1 + (qo - b.inside.1) * ((t - b.t_inside) / (b.t_outside - b.t_inside))
            }
            None => b.inside.1,
        };
        let mut in_start = None;
        let seg = Segment {
            origin,
            dir,
            faces,
            t_inside: b.t_inside,
            t,
            inside_cell: b.inside.0,
        };
        match self.boundary_locate_from(
            seg,
            b.inside.0,
            guess,
            false,
            &mut in_start,
            counters,
            stats,
        ) {
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
    /// and `t_inside` (a point in cell `inside.0` at parameters `inside.1`), to a bracket of
    /// `1/2^BISECTIONS` of the starting one, then one interpolation of the violated parametric
    /// coordinate (see [`super::boundary`]).
    ///
    /// The bracket is first narrowed around an estimate: where the march from the inside end
    /// leaves the mesh by face planes ([`boundary_plane_crossing`]). The points half a final
    /// bracket to either side of it are tested; where the first is inside and the second
    /// outside, the bracket is final after two tests. Otherwise (a curved boundary face, a
    /// march that gave up) bisection finishes from whatever bracket the tests left.
    #[allow(clippy::too_many_arguments)]
    fn crossing(
        &self,
        faces: Option<RayFaces<'_>>,
        origin: DVec3,
        dir: DVec3,
        t_outside: f64,
        t_inside: f64,
        inside: (u32, DVec3),
        counters: &mut Counters,
        stats: &mut RenderStats,
    ) -> f64 {
        if self.neighbours.complete() {
            // The boundary surface solves only for the boundary faces near the segment; the
            // walk across the cells from the inside end, for each of their faces, where the
            // surface cannot tell.
            if let Some(surface) = self.neighbours.surface() {
                let mut c = Counters::default();
                let first = surface.first_face_crossing(
                    faces,
                    self.volume.mesh,
                    origin,
                    dir,
                    t_inside,
                    t_outside,
                    &mut c,
                );
                stats.surface_visits += c.internal_visits + c.leaf_visits;
                if let Some(Some((t, _))) = first {
                    return t;
                }
            }
            if let Some(t) = boundary_face_crossing(
                self.volume.mesh,
                self.neighbours,
                inside.0,
                origin,
                dir,
                t_inside,
                t_outside,
            ) {
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
        let estimate = boundary_plane_crossing(
            self.volume.mesh,
            self.neighbours,
            inside.0,
            origin,
            dir,
            t_inside,
            t_outside,
        );
        if let Some(t_est) = estimate {
            let toward_out = (t_outside - t_inside).signum() * 0.5 * final_width;
            let (lo, hi) = (t_est - toward_out, t_est + toward_out);
            let strictly_within = |t: f64, b: &Bracket| {
                t > b.t_inside.min(b.t_outside) && t < b.t_inside.max(b.t_outside)
            };
            if strictly_within(lo, &b)
                && self.probe(faces, origin, dir, lo, &mut b, counters, stats)
                && strictly_within(hi, &b)
            {
                self.probe(faces, origin, dir, hi, &mut b, counters, stats);
            }
        }
        // At most BISECTIONS halvings (the bound also ends the loop should rounding stall it).
        for _ in 0..BISECTIONS {
            if (b.t_outside - b.t_inside).abs() <= final_width * (1.0 + 1e-9) {
                break;
            }
            let mid = 0.5 * (b.t_outside + b.t_inside);
            self.probe(faces, origin, dir, mid, &mut b, counters, stats);
        }
        let q_out = match b.outside_q {
            Some(q) => Some(q),
            None => {
                let corners = self.volume.mesh.cell_corners(b.inside.0 as usize);
                counters.hex_tests += 1;
                stats.boundary_refinements += 1;
                invert(&corners, origin + dir * b.t_outside, Some(b.inside.1)).param()
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

    /// The boundary crossings between the positions `a` and `b` of the ray (`a.0 < b.0`, no
    /// sample between them), sorted by what they mean for compositing ([`super::chords`]):
    /// the exit of `a`'s sample, the entry of `b`'s, the chords between. `None` without a
    /// boundary surface whose faces bound the mesh (complete neighbours), or where the
    /// crossings cannot all be told robustly or disagree with what is known of the ends (the
    /// caller then keeps to its samples). The surface's node visits are counted in
    /// `surface_visits`.
    fn between(
        &self,
        faces: Option<RayFaces<'_>>,
        origin: DVec3,
        dir: DVec3,
        a: (f64, End),
        b: (f64, End),
        stats: &mut RenderStats,
    ) -> Option<Between> {
        let surface = self.bounding_surface()?;
        let mut c = Counters::default();
        let crossings =
            surface.crossings_between(faces, self.volume.mesh, origin, dir, a.0, b.0, &mut c);
        stats.surface_visits += c.internal_visits + c.leaf_visits;
        let crossings = crossings?;
        let mut a = a;
        if side_unknown(a.1, b.1) {
            // Neither end's side known (a ray too short for a sample between the eye or
            // clipping planes): the middle of the stretch up to the first crossing tells it.
            let to = crossings.ts().first().map_or(b.0, |c| c.0);
            let p = origin + dir * (0.5 * (a.0 + to));
            let mut counters = Counters::default();
            let inside = self
                .volume
                .accel
                .locate(self.volume.mesh, p, &mut counters)
                .is_some();
            stats.add_counters(&counters);
            stats.boundary_refinements += counters.hex_tests;
            stats.structure_locates += 1;
            a.1 = match (a.1, inside) {
                (_, false) => End::Outside,
                (End::Passed, true) => End::Sample,
                (_, true) => End::In,
            };
        }
        classify(crossings.ts(), a, b)
    }

    /// The boundary surface whose crossings tell where a ray enters and leaves the mesh: only
    /// with boundary segments on and every face without a neighbour bounding the mesh.
    fn bounding_surface(&self) -> Option<&BoundarySurface> {
        if !self.options.boundary_segments || !self.neighbours.complete() {
            return None;
        }
        self.neighbours.surface()
    }

    /// Whether the ray may cross the mesh's boundary between `t0` and `t1`, by the boundary
    /// surface's conservative bound ([`BoundarySurface::next_crossing`]); `false` without a
    /// surface whose faces bound the mesh. For the paper path, which has no march to tell it
    /// a sample's neighbour lies across the boundary.
    fn may_cross_boundary(
        &self,
        faces: Option<RayFaces<'_>>,
        origin: DVec3,
        dir: DVec3,
        t0: f64,
        t1: f64,
        stats: &mut RenderStats,
    ) -> bool {
        let Some(surface) = self.bounding_surface() else {
            return false;
        };
        let mut c = Counters::default();
        let next = surface.next_crossing(faces, origin, dir, t0, t1, &mut c);
        stats.surface_visits += c.internal_visits + c.leaf_visits;
        next.is_some()
    }

    /// Samples each of `chords` (pieces of the ray in the mesh that hold no sample, front to
    /// back) once at its middle, standing for its own length, and composites it (or, for an
    /// intensity projection, offers its scalar to the extreme). The middle is located by a
    /// walk from the chord's face cell on the fast path, through the structure on the paper
    /// path (and where the walk gives up); a middle located nowhere (a chord too thin for the
    /// inverse map's tolerance) or in a transparent cell adds nothing. Counted in
    /// [`RenderStats::chord_samples`]. Returns whether the ray is now opaque enough to stop
    /// (early termination).
    #[allow(clippy::too_many_arguments)]
    fn composite_chords(
        &self,
        chords: &[Chord],
        origin: DVec3,
        dir: DVec3,
        acc: &mut Accum,
        extreme: &Cell<Option<(f64, f64)>>,
        transparent: Option<&TransparentCells>,
        counters: &mut Counters,
        stats: &mut RenderStats,
    ) -> bool {
        let mesh = self.volume.mesh;
        let opts = &self.options;
        for chord in chords {
            if chord.length().partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater) {
                continue;
            }
            let t = chord.middle();
            let p = origin + dir * t;
            let before = counters.hex_tests;
            let walked = match opts.path {
                RenderPath::Fast if (chord.cell as usize) < mesh.cell_count() => {
                    let mut work = WalkWork::default();
                    let end = walk_within(
                        mesh,
                        self.neighbours,
                        chord.cell,
                        None,
                        p,
                        MAX_ENTRY_PLANE_STEPS,
                        &mut work,
                    );
                    counters.hex_tests += work.tests;
                    stats.walk_steps += work.plane_steps;
                    match end {
                        WalkEnd::Found(c, q) => Some((c, q)),
                        _ => None,
                    }
                }
                _ => None,
            };
            let found = walked.or_else(|| {
                if opts.path == RenderPath::Fast {
                    stats.structure_locates += 1;
                }
                self.volume.accel.locate(mesh, p, counters)
            });
            stats.boundary_refinements += counters.hex_tests - before;
            let Some((cell, q)) = found else {
                continue;
            };
            stats.chord_samples += 1;
            if transparent.is_some_and(|m| m.contains(cell)) {
                continue;
            }
            let q = q.clamp(DVec3::ZERO, DVec3::ONE);
            let (s, values) = self.scalar_at(cell, q);
            if opts.blend != Blend::Composite {
                if opts.blend.replaces(s, extreme.get().map(|e| e.0)) {
                    extreme.set(Some((s, t)));
                }
                continue;
            }
            let Some((rgb, alpha_step)) = self.colour(s, values, cell, q, dir, stats) else {
                continue;
            };
            let piece = Last {
                t,
                start: Some(chord.start),
                rgb,
                alpha_step,
                transmittance_before: acc.transmittance,
                color_before: acc.color,
                depth_before: acc.depth,
                inside: (cell, q),
            };
            acc.composite(&piece, chord.end, opts.step, opts.depth_opacity);
        }
        1.0 - acc.transmittance >= opts.early_termination
    }

    /// The scalar at parameters `param` (in the cell's cube) of `cell`: the trilinear (or
    /// nearest-corner) interpolant of point data, with the corner values; a cell's value.
    #[inline]
    fn scalar_at(&self, cell: u32, param: DVec3) -> (f64, Option<[f64; 8]>) {
        let field = &self.volume.field;
        match field.association {
            Association::Point => {
                let values =
                    self.volume.mesh.cells()[cell as usize].map(|i| field.scalars[i as usize]);
                (
                    self.options.interpolation.sample(&values, param),
                    Some(values),
                )
            }
            Association::Cell => (field.scalars[cell as usize], None),
        }
    }

    /// The colour (shaded where shading is on) and the opacity over a step of a sample of
    /// scalar `s` at parameters `param` (in the cell's cube) of `cell`, with the corner
    /// `values` of point data; `None` where it adds nothing. The gradient is evaluated only
    /// where shading or gradient opacity needs it (a cell scalar has none to evaluate), and
    /// only once the transfer function gives the sample some opacity.
    #[inline]
    fn colour(
        &self,
        s: f64,
        values: Option<[f64; 8]>,
        cell: u32,
        param: DVec3,
        dir: DVec3,
        stats: &mut RenderStats,
    ) -> Option<([f64; 3], f64)> {
        let opts = &self.options;
        let [r, g, b, mut a] = self.table.lookup(s);
        if a <= 0.0 || a.is_nan() {
            return None;
        }
        let grad = match values {
            Some(values) if opts.shading.is_some() || opts.gradient_opacity.is_some() => {
                stats.gradient_evaluations += 1;
                physical_gradient(
                    &self.volume.mesh.cell_corners(cell as usize),
                    &values,
                    param,
                )
            }
            _ => None,
        };
        if let Some(go) = &opts.gradient_opacity {
            let f = go.at(grad.map_or(0.0, |g| g.length()));
            if f != 1.0 {
                a = self.table.step_opacity(self.table.unit_opacity(s) * f);
                if a <= 0.0 || a.is_nan() {
                    return None;
                }
            }
        }
        let c = match &opts.shading {
            Some(shading) => shading.shade([r, g, b], grad, dir),
            None => [r, g, b],
        };
        Some((c, a))
    }

    /// Whether the ray `origin + t dir`, in the mesh at `t_from` (a located sample), stays
    /// in it up to `t`: where no boundary face's bound lies on the way
    /// ([`BoundarySurface::next_crossing`]; conservative, so `true` is proved). `until` keeps
    /// the last answer: the ray is in the mesh from the sample it was found from up to there,
    /// so later samples before it need no query (the samples' `t` only grow). `false` without
    /// the boundary surface.
    #[allow(clippy::too_many_arguments)]
    fn in_mesh_until(
        &self,
        until: &mut f64,
        faces: Option<RayFaces<'_>>,
        origin: DVec3,
        dir: DVec3,
        t_from: f64,
        t: f64,
        t_end: f64,
        counters: &mut Counters,
    ) -> bool {
        let Some(surface) = self.neighbours.surface() else {
            return false;
        };
        if t >= *until {
            *until = surface
                .next_crossing(faces, origin, dir, t_from, t_end, counters)
                .map_or(f64::INFINITY, |(c, _)| c);
        }
        t < *until
    }

    /// [`Renderer::cast`] with the first cell of the previous ray as a starting point
    /// (updated to this ray's first cell).
    fn cast_with_hint(
        &self,
        origin: DVec3,
        dir: DVec3,
        t_stop: f64,
        hint: &mut Option<u32>,
        faces: Option<RayFaces<'_>>,
        stats: &mut RenderStats,
    ) -> RayResult {
        stats.rays += 1;
        let mut out = RayResult {
            rgba: [0.0; 4],
            depth: f64::INFINITY,
        };
        if self.nothing_visible() {
            return out;
        }
        let opts = &self.options;
        let Some(box_span) = self.box_span(origin, dir) else {
            return out;
        };
        let Some((t_in, t_out)) = opts.clip_planes.clip_span(origin, dir, box_span) else {
            return out;
        };
        // Whether a clipping plane moved the ray's start (which may then lie in the mesh) or
        // its end (where, in the mesh, the last sample's segment ends).
        let starts_on_plane = t_in > box_span.0;
        let (t_out, ends_on_plane) = if t_stop.is_nan() || t_stop >= t_out {
            (t_out, t_out < box_span.1)
        } else {
            (t_stop, false)
        };
        // What is known of the ray's start and end for its chords (see `super::chords`): on
        // the mesh's padded box they are outside; at the eye, on a clipping plane or at
        // opaque geometry, either side.
        let start_end = if t_in > 0.0 && !starts_on_plane {
            End::Outside
        } else {
            End::Unknown
        };
        let end_end = if t_out < box_span.1 {
            End::Unknown
        } else {
            End::Outside
        };
        let step = opts.step;
        let vol = self.volume;
        let mesh = vol.mesh;
        let fast = opts.path == RenderPath::Fast;
        let compositing = opts.blend == Blend::Composite;
        // Only the fast path skips transparent cells (the paper path samples every one), and
        // only when compositing (an extreme may lie in a transparent cell).
        let transparent = (fast && compositing).then(|| self.transparent_cells());
        let is_transparent = |cell: u32| transparent.is_some_and(|m| m.contains(cell));
        // How far the march goes before the structure is asked: the reach in cells, times
        // the cells a look-up through the structure tests.
        let march_reach = if fast && opts.march_reach.is_finite() {
            opts.march_reach * vol.accel.lookup_tests(mesh)
        } else {
            opts.march_reach
        };
        // The fast path jumps over transparent space through a BVH's visible nodes, or a
        // grid's visible cells.
        let (visible_nodes, visible_grid) = if fast && compositing {
            (self.visible_nodes(), self.visible_grid_cells())
        } else {
            (None, None)
        };
        // A projection's fast path jumps over cells that cannot beat the extreme through a
        // BVH's node ranges.
        let extreme_nodes = if fast && !compositing {
            self.extreme_nodes()
        } else {
            None
        };
        // The extreme scalar of a maximum- or minimum-intensity projection, and its `t`.
        let extreme: Cell<Option<(f64, f64)>> = Cell::new(None);
        // A projection's fast path passes over cells that cannot beat the extreme so far.
        let outranked = |cell: u32| {
            fast && !compositing
                && !opts
                    .blend
                    .may_replace_in(vol.cell_range(cell), extreme.get().map(|e| e.0))
        };
        // The cells where a sample needs no parametric coordinates.
        let no_parameters = |cell: u32| is_transparent(cell) || outranked(cell);
        let skipper = || Skipper::new(vol.accel);
        let mut counters = Counters::default();
        let mut acc = Accum {
            transmittance: 1.0,
            color: [0.0; 3],
            depth: f64::INFINITY,
            last: None,
        };
        // Whether the previous sample position was located in a cell.
        let mut prev_in = false;
        // The fast path's last located cell and parameters; `None` outside the mesh.
        let mut prev: Option<(u32, DVec3)> = None;
        // The ray parameter of the sample `prev` holds.
        let mut prev_t = f64::NAN;
        // Where a sample past an exit was proved outside: the crossing and the next one.
        let mut proved_exit: Option<ProvedExit> = None;
        // The fast path's march along the ray through `prev`'s cell.
        let mut march = March::new();
        let mut first_cell: Option<u32> = None;
        // The ray lies in a piece's bound up to here (from the last empty-space query).
        let mut bound_until = f64::NEG_INFINITY;
        // The ray may lie in a piece of a cell that adds something (visible, or able to beat
        // the extreme) up to here (from the last jump query).
        let mut adds_until = f64::NEG_INFINITY;
        // A jump passed over the position before the next sample (in the mesh or not), and
        // the cell of the visible piece it jumped to (where the next location starts).
        let mut jumped = false;
        let mut jumped_to: Option<u32> = None;
        let sample_t = |k: u64| t_in + (k as f64 + 0.5) * step;
        // The ray left the mesh before `t_outside`: the last composited sample ends at the
        // crossing (nothing to do without boundary segments, which keep no last sample).
        // With the crossing where it is known (an exit proved by parity from `l.t`).
        let close_at_exit = |acc: &mut Accum,
                             t_outside: f64,
                             known: Option<f64>,
                             counters: &mut Counters,
                             stats: &mut RenderStats| {
            if let Some(l) = acc.last.take() {
                let e = known.unwrap_or_else(|| {
                    self.crossing(
                        faces, origin, dir, t_outside, l.t, l.inside, counters, stats,
                    )
                });
                acc.exit(l, e, step, opts.depth_opacity);
            }
        };
        // The fast path's skipping over the boundary surface: the ray is outside the mesh
        // before `outside_until` (from the last point known to be outside), and the face it
        // may enter through is in `surface_cell`.
        let surface = if fast {
            self.neighbours.surface()
        } else {
            None
        };
        let mut surface_counters = Counters::default();
        // The ray is in the mesh from a located sample up to `in_mesh_until` (the next
        // possible boundary crossing), for locating far samples through the structure.
        let mut in_mesh_until = f64::NEG_INFINITY;
        let mut inside_counters = Counters::default();
        let mut next_surface_crossing = |t_outside: f64| -> (f64, Option<u32>) {
            match surface {
                Some(s) => {
                    match s.next_crossing(
                        faces,
                        origin,
                        dir,
                        t_outside,
                        t_out,
                        &mut surface_counters,
                    ) {
                        Some((t, c)) => (t, Some(c)),
                        None => (t_out, None),
                    }
                }
                None => (f64::NEG_INFINITY, None),
            }
        };
        // A ray starting on the (padded) box of the mesh starts outside it; one starting at
        // the eye or on a clipping plane may start inside.
        let (mut outside_until, mut surface_cell) = if t_in > 0.0 && !starts_on_plane {
            next_surface_crossing(t_in)
        } else {
            (f64::NEG_INFINITY, None)
        };
        // Passes over the samples before `until` (and the ray's end) as empty space.
        let skip_until = |k: &mut u64, stats: &mut RenderStats, until: f64| {
            while sample_t(*k) < until.min(t_out) {
                stats.samples += 1;
                stats.space_skips += 1;
                *k += 1;
            }
        };
        // The fast path's march left the mesh by a boundary face since the last located
        // sample (the ray may have left the mesh and come back: a gap).
        let mut crossed_boundary = false;
        // Whether the ray stopped at early termination.
        let mut terminated = false;
        // What is known of the position before sample `k` (the previous sample's, or the
        // ray's start): in the mesh (a located sample), outside, or passed over by a jump.
        let previous = |k: u64, was_in: bool, after_jump: bool| -> (f64, End) {
            if k == 0 {
                (t_in, start_end)
            } else if was_in {
                (sample_t(k - 1), End::Sample)
            } else if after_jump {
                (sample_t(k - 1), End::Passed)
            } else {
                (sample_t(k - 1), End::Outside)
            }
        };
        // Composites the chords between two positions (see `super::chords`); true where they
        // make the ray opaque enough to stop.
        macro_rules! composite_chords {
            ($chords:expr) => {
                self.composite_chords(
                    $chords,
                    origin,
                    dir,
                    &mut acc,
                    &extreme,
                    transparent,
                    &mut counters,
                    stats,
                )
            };
        }
        // The same in the sample loop, which stops the ray there (early termination).
        macro_rules! chords_or_stop {
            ($chords:expr) => {
                let chords: &[Chord] = $chords;
                if !chords.is_empty() && composite_chords!(chords) {
                    stats.early_terminations += 1;
                    terminated = true;
                    break;
                }
            };
        }
        let mut k = 0u64;
        'samples: loop {
            let t = sample_t(k);
            if t >= t_out || t.is_nan() {
                break;
            }
            let p = origin + dir * t;
            let found = if !fast {
                stats.samples += 1;
                k += 1;
                vol.accel.locate(mesh, p, &mut counters)
            } else {
                // With a previous cell, walk from it; a walk that leaves the mesh drops it.
                let mut walked = None;
                if let Some((c, _)) = prev {
                    // The march follows `prev` (set below after every located sample).
                    debug_assert_eq!(march.cell(), c);
                    // Far ahead, in the mesh all the way: locate through the structure.
                    if march.cells_ahead(t) > march_reach
                        && self.in_mesh_until(
                            &mut in_mesh_until,
                            faces,
                            origin,
                            dir,
                            prev_t,
                            t,
                            t_out,
                            &mut inside_counters,
                        )
                    {
                        if let Some(f) = vol.accel.locate(mesh, p, &mut counters) {
                            stats.far_locates += 1;
                            march.place(f.0, t);
                            walked = Some(Some(f));
                        }
                    }
                }
                if let (None, Some((c, q))) = (walked, prev) {
                    let mut work = WalkWork::default();
                    let end = march.locate(
                        mesh,
                        self.neighbours,
                        origin,
                        dir,
                        t,
                        Some((c, q)),
                        &no_parameters,
                        &mut work,
                    );
                    counters.hex_tests += work.tests;
                    stats.walk_steps += work.plane_steps;
                    stats.plane_certified += work.certified;
                    match end {
                        WalkEnd::Found(n, _) | WalkEnd::Certified(n) => {
                            if n == c {
                                stats.previous_cell_hits += 1;
                            } else {
                                stats.neighbour_hits += 1;
                            }
                            // A certified sample is in a transparent cell and skipped below:
                            // its coordinates, never computed, only seed the next Newton.
                            let q = match end {
                                WalkEnd::Found(_, q) => q,
                                _ => DVec3::splat(0.5),
                            };
                            walked = Some(Some((n, q)));
                        }
                        WalkEnd::Boundary => {
                            // Left the mesh by the planes: settled locally where the
                            // boundary surface proves the sample outside.
                            prev = None;
                            crossed_boundary = true;
                            let seg = Segment {
                                origin,
                                dir,
                                faces,
                                t_inside: prev_t,
                                t,
                                inside_cell: c,
                            };
                            let guess = if march.cell() == c {
                                q
                            } else {
                                DVec3::splat(0.5)
                            };
                            if let Some(face) = march.exit_face() {
                                let face = (march.cell(), face as u8);
                                match self.exit_locate(
                                    seg,
                                    face,
                                    guess,
                                    t_out,
                                    &mut counters,
                                    stats,
                                ) {
                                    Exit::Inside(c, q) => walked = Some(Some((c, q))),
                                    Exit::Outside(exit) => {
                                        walked = Some(None);
                                        proved_exit = Some(exit);
                                    }
                                    Exit::Undecided => {}
                                }
                            }
                        }
                        WalkEnd::GaveUp => {
                            // The march did not follow the ray there: it may have left the
                            // mesh on the way.
                            crossed_boundary = true;
                            stats.structure_locates += 1;
                            walked = Some(vol.accel.locate(mesh, p, &mut counters));
                        }
                    }
                }
                match walked {
                    Some(f) => {
                        stats.samples += 1;
                        k += 1;
                        f
                    }
                    None if t < outside_until => {
                        // Known to be outside the mesh up to a possible boundary crossing.
                        skip_until(&mut k, stats, outside_until);
                        continue 'samples;
                    }
                    None => {
                        // Outside the mesh or at the ray's start: skip the empty space.
                        // Within the span of a bound found for an earlier sample, the sample
                        // is in that bound: no need to ask the structure again.
                        // With the boundary surface, which skips from the points known to be
                        // outside, the structure's bounds cost more to traverse than they
                        // save: they are not asked.
                        let span = if t <= bound_until {
                            Some((t, bound_until))
                        } else if surface.is_some() {
                            Some((t, t))
                        } else {
                            skipper().next_span(origin, dir, t, t_out, &mut counters)
                        };
                        let Some((te, tx)) = span else {
                            close_at_exit(&mut acc, t, None, &mut counters, stats);
                            skip_until(&mut k, stats, t_out);
                            break 'samples;
                        };
                        bound_until = tx;
                        if te > t {
                            prev_in = false;
                            close_at_exit(&mut acc, t, None, &mut counters, stats);
                            skip_until(&mut k, stats, te);
                            continue 'samples;
                        }
                        stats.samples += 1;
                        k += 1;
                        if !Skipper::new(vol.accel).may_hold(p, &mut counters) {
                            // In no piece's bound: outside the mesh, as a sample located
                            // nowhere is (below).
                            stats.space_skips += 1;
                            None
                        } else {
                            // After a jump, the visible cell jumped to is the hint. The
                            // previous ray's first cell is a hint for this ray's first entry
                            // only: later, it lies far behind.
                            let h = jumped_to.take().or(if first_cell.is_none() {
                                *hint
                            } else {
                                None
                            });
                            self.locate_entry(
                                origin,
                                dir,
                                t,
                                surface_cell.take(),
                                h,
                                &mut march,
                                &mut counters,
                                stats,
                            )
                        }
                    }
                }
            };
            if fast {
                prev = found;
                prev_t = t;
                // The march follows `prev` (and is not used while there is none).
                if let Some((c, _)) = found {
                    if march.cell() != c {
                        march.move_to(mesh, c, origin, dir);
                    }
                }
            }
            // Whether the position before this sample was jumped over (unknown: in the mesh
            // or not).
            let after_jump = std::mem::take(&mut jumped);
            let Some((cell, param)) = found else {
                let was_in = std::mem::replace(&mut prev_in, false);
                crossed_boundary = false;
                // Located nowhere: outside the mesh, exactly.
                let proved = proved_exit.take();
                // Where the exit was not proved by parity (its crossing then the only one),
                // the crossings since the previous position: its sample's exit, and the
                // chords after it (or between two positions outside).
                let between = match proved {
                    Some(_) => None,
                    None => self.between(
                        faces,
                        origin,
                        dir,
                        previous(k - 1, was_in, after_jump),
                        (t, End::Outside),
                        stats,
                    ),
                };
                close_at_exit(
                    &mut acc,
                    t,
                    proved.map(|p| p.crossing).or(between.and_then(|b| b.exit)),
                    &mut counters,
                    stats,
                );
                chords_or_stop!(between.as_ref().map_or(&[][..], |b| b.chords()));
                (outside_until, surface_cell) =
                    proved.map_or_else(|| next_surface_crossing(t), |p| p.next);
                continue;
            };
            let was_in = std::mem::replace(&mut prev_in, true);
            // The crossings since the previous position where the ray may have crossed the
            // boundary: from outside (the entry, and chords before it), or from a sample in
            // the mesh where the march left it, or the paper path's surface bound says it may
            // (a gap). The previous sample's exit closes it; the entry starts this one.
            let crossed = std::mem::take(&mut crossed_boundary)
                || (!fast
                    && was_in
                    && self.may_cross_boundary(
                        faces,
                        origin,
                        dir,
                        previous(k - 1, was_in, after_jump).0,
                        t,
                        stats,
                    ));
            let between = (!was_in || crossed)
                .then(|| {
                    self.between(
                        faces,
                        origin,
                        dir,
                        previous(k - 1, was_in, after_jump),
                        (t, End::Sample),
                        stats,
                    )
                })
                .flatten();
            let entry = between.map(|b| b.entry);
            if let Some(b) = &between {
                if b.exit.is_some() && b.entry.is_some() {
                    stats.gaps += 1;
                }
                if let (Some(e), Some(l)) = (b.exit, acc.last.take()) {
                    acc.exit(l, e, step, opts.depth_opacity);
                }
            }
            chords_or_stop!(between.as_ref().map_or(&[][..], |b| b.chords()));
            // The previous composited sample (if any) keeps its full end (or the exit just
            // found): this one is inside.
            acc.last = None;
            let raw_param = param;
            stats.samples_located += 1;
            if first_cell.is_none() {
                first_cell = Some(cell);
            }
            // (Only the fast path passes over cells: the paper path samples every one.)
            let transparent_here = is_transparent(cell);
            if transparent_here || outranked(cell) {
                // A sample in a transparent cell (compositing), or in a cell that cannot beat
                // the extreme (a projection), adds nothing; a certified one's coordinates were
                // never computed. Up to the next bound of a piece of a cell that may add
                // something the ray meets only such cells or the space outside the mesh (the
                // last composited sample, if any, was closed by this one): jump there when
                // the next sample lies before it, and locate afresh.
                if transparent_here {
                    stats.samples_skipped += 1;
                } else {
                    stats.extreme_skips += 1;
                }
                let t_next = sample_t(k);
                let best = extreme.get().map(|e| e.0);
                let next = match (visible_nodes, extreme_nodes, visible_grid) {
                    _ if t_next <= adds_until => None,
                    (Some(nodes), _, _) => Some(
                        skipper()
                            .next_visible(
                                origin,
                                dir,
                                t_next,
                                t_out,
                                nodes,
                                |c| !is_transparent(c),
                                &mut counters,
                            )
                            .map(|(te, tx, c)| (te, tx, Some(c))),
                    ),
                    (None, None, Some(cells)) => Some(skipper().next_kept_in_grid(
                        origin,
                        dir,
                        t_next,
                        t_out,
                        cells,
                        |c| !is_transparent(c),
                        &mut counters,
                    )),
                    (None, Some(ranges), _) => Some(
                        skipper()
                            .next_kept(
                                origin,
                                dir,
                                t_next,
                                t_out,
                                ranges.len(),
                                |i| {
                                    ranges
                                        .get(i)
                                        .is_some_and(|r| opts.blend.may_replace_in(r, best))
                                },
                                |c| !outranked(c),
                                &mut counters,
                            )
                            .map(|(te, tx, c)| (te, tx, Some(c))),
                    ),
                    (None, None, None) => None,
                };
                if let Some(next) = next {
                    let until = match next {
                        Some((te, tx, _)) if te <= t_next => {
                            adds_until = tx;
                            continue;
                        }
                        Some((te, _, c)) => {
                            jumped_to = c;
                            te
                        }
                        None => t_out,
                    };
                    if transparent_here {
                        stats.transparent_jumps += 1;
                    } else {
                        stats.extreme_jumps += 1;
                    }
                    skip_until(&mut k, stats, until);
                    prev = None;
                    prev_in = false;
                    jumped = true;
                    proved_exit = None;
                    (outside_until, surface_cell) = (f64::NEG_INFINITY, None);
                }
                continue;
            }
            let param = param.clamp(DVec3::ZERO, DVec3::ONE);
            let (s, values) = self.scalar_at(cell, param);
            if !compositing {
                if opts.blend.replaces(s, extreme.get().map(|e| e.0)) {
                    extreme.set(Some((s, t)));
                }
                continue;
            }
            let Some((c, a)) = self.colour(s, values, cell, param, dir, stats) else {
                continue;
            };
            // Where the previous position was outside the mesh, the segment starts at the
            // crossing (the ray's start counts as outside unless it is in the mesh).
            let start = if let Some(e) = entry {
                e
            } else if was_in || !opts.boundary_segments {
                None
            } else {
                let t_prev = if k >= 2 { sample_t(k - 2) } else { t_in };
                // An earlier sample not located is outside; one jumped over or the ray's
                // start may be either.
                let outside = (k >= 2 && !after_jump)
                    || self
                        .boundary_locate(
                            Segment {
                                origin,
                                dir,
                                faces,
                                t_inside: t,
                                t: t_prev,
                                inside_cell: cell,
                            },
                            cell,
                            raw_param,
                            &mut counters,
                            stats,
                        )
                        .is_none();
                outside.then(|| {
                    self.crossing(
                        faces,
                        origin,
                        dir,
                        t_prev,
                        t,
                        (cell, raw_param),
                        &mut counters,
                        stats,
                    )
                })
            };
            let last = Last {
                t,
                start,
                rgb: c,
                alpha_step: a,
                transmittance_before: acc.transmittance,
                color_before: acc.color,
                depth_before: acc.depth,
                inside: (cell, raw_param),
            };
            acc.composite(&last, t + 0.5 * step, step, opts.depth_opacity);
            // Without boundary segments no sample is ever cut at an exit crossing.
            acc.last = opts.boundary_segments.then_some(last);
            if 1.0 - acc.transmittance >= opts.early_termination {
                // Before stopping, see whether the ray leaves the mesh before the next sample.
                if let Some(l) = acc.last.take() {
                    let t_next = sample_t(k).min(t_out);
                    let seg = Segment {
                        origin,
                        dir,
                        faces,
                        t_inside: t,
                        t: t_next,
                        inside_cell: cell,
                    };
                    if self
                        .boundary_locate(seg, cell, raw_param, &mut counters, stats)
                        .is_none()
                    {
                        let e = self.crossing(
                            faces,
                            origin,
                            dir,
                            t_next,
                            t,
                            l.inside,
                            &mut counters,
                            stats,
                        );
                        acc.exit(l, e, step, opts.depth_opacity);
                    }
                }
                if 1.0 - acc.transmittance >= opts.early_termination {
                    stats.early_terminations += 1;
                    terminated = true;
                    break;
                }
            }
        }
        // The ray's end: where it is outside the mesh, the last sample ends at the crossing;
        // where it is in the mesh on a clipping plane, at the plane. Where the boundary
        // surface tells the crossings since the last position, the pieces of the ray in the
        // mesh after it are chords (the whole ray's, where it is too short for a sample); on
        // the fast path, not where the surface proved the ray outside up to its end.
        let (t_last, last_end) = previous(k, prev_in, jumped);
        let may_cross = !(surface.is_some() && last_end == End::Outside && outside_until >= t_out);
        let between = (!terminated && may_cross && t_out.is_finite() && t_last < t_out)
            .then(|| {
                self.between(
                    faces,
                    origin,
                    dir,
                    (t_last, last_end),
                    (t_out, end_end),
                    stats,
                )
            })
            .flatten();
        if let Some(b) = between {
            if let Some(l) = acc.last.take() {
                match b.exit {
                    Some(e) => acc.exit(l, e, step, opts.depth_opacity),
                    None if ends_on_plane => acc.exit(l, t_out, step, opts.depth_opacity),
                    None => {}
                }
            }
            // The ray ends here, so whether the chords make it opaque changes nothing.
            composite_chords!(b.chords());
        } else if let Some(l) = acc.last.take() {
            let seg = Segment {
                origin,
                dir,
                faces,
                t_inside: l.t,
                t: t_out,
                inside_cell: l.inside.0,
            };
            if t_out.is_finite() {
                if self
                    .boundary_locate(seg, l.inside.0, l.inside.1, &mut counters, stats)
                    .is_none()
                {
                    let e = self.crossing(
                        faces,
                        origin,
                        dir,
                        t_out,
                        l.t,
                        l.inside,
                        &mut counters,
                        stats,
                    );
                    acc.exit(l, e, step, opts.depth_opacity);
                } else if ends_on_plane {
                    acc.exit(l, t_out, step, opts.depth_opacity);
                }
            }
        }
        if first_cell.is_some() {
            *hint = first_cell;
        }
        stats.add_counters(&counters);
        stats.surface_visits += surface_counters.internal_visits
            + surface_counters.leaf_visits
            + inside_counters.internal_visits
            + inside_counters.leaf_visits;
        if let Some((s, t)) = extreme.get() {
            let [r, g, b, _] = self.table.lookup(s);
            let a = self.table.unit_opacity(s).clamp(0.0, 1.0);
            out.rgba = [r * a, g * a, b * a, a];
            if a > 0.0 && a >= opts.depth_opacity {
                out.depth = t;
            }
            return out;
        }
        out.depth = acc.depth;
        out.rgba = [
            acc.color[0],
            acc.color[1],
            acc.color[2],
            1.0 - acc.transmittance,
        ];
        out
    }

    /// Renders the image seen by `camera`; `depth_in` (one distance per pixel, rows top to
    /// bottom, the ray-distance convention of the module documentation) stops rays at opaque
    /// geometry.
    pub fn render(
        &self,
        camera: &Camera,
        depth_in: Option<&[f32]>,
    ) -> Result<(Image, RenderStats), Error> {
        let rays = RayGenerator::new(camera, self.options.width, self.options.height)?;
        self.render_rays(&rays, depth_in)
    }

    /// Renders the image of any [`RaySource`] (its size must be the options' size); `depth_in`
    /// gives, per pixel (rows top to bottom), the distance along the pixel's ray at which
    /// opaque geometry stops it.
    pub fn render_rays<R: RaySource + ?Sized>(
        &self,
        rays: &R,
        depth_in: Option<&[f32]>,
    ) -> Result<(Image, RenderStats), Error> {
        let (w, h) = (self.options.width, self.options.height);
        if rays.size() != (w, h) {
            return Err(Error::Invalid(format!(
                "rays for a {}x{} image, options for {w}x{h}",
                rays.size().0,
                rays.size().1
            )));
        }
        let n = w as usize * h as usize;
        if let Some(d) = depth_in {
            if d.len() != n {
                return Err(Error::Invalid(format!(
                    "depth image has {} values for a {w}x{h} image",
                    d.len()
                )));
            }
        }
        // The fast path's transparency mask and visible nodes, and the structure's node arcs
        // (kept with the structure: made by its first render), made in parallel here rather
        // than by the first ray (which would make them alone, sequentially, while the other
        // threads wait).
        if self.options.path == RenderPath::Fast && !self.nothing_visible() {
            if self.options.blend != Blend::Composite && self.extreme_nodes.get().is_none() {
                let _ = self.extreme_nodes.set(self.make_extreme_nodes(true));
            }
            if self.transparent.get().is_none() {
                let mask = TransparentCells::new(&self.volume.field.cell_ranges, &self.table);
                let _ = self.transparent.set(mask);
            }
            if self.visible.get().is_none() {
                let _ = self.visible.set(self.make_visible_nodes(true));
            }
            if self.visible_grid.get().is_none() {
                let _ = self.visible_grid.set(self.make_visible_grid_cells(true));
            }
        }
        self.volume.accel.make_node_ray_tests();
        if self.options.path == RenderPath::Fast && self.options.march_reach.is_finite() {
            // Measured here once per structure, not by the first ray's thread alone.
            self.volume.accel.lookup_tests(self.volume.mesh);
        }
        let tile = self.options.tile.max(1);
        let (tx, ty) = (w.div_ceil(tile), h.div_ceil(tile));
        let tiles: Vec<(u32, u32)> = (0..ty).flat_map(|y| (0..tx).map(move |x| (x, y))).collect();
        // The fast path's boundary faces sorted to the image once, for lists per ray in
        // place of the surface's traversals (see `ray_faces`).
        let surface = (self.options.path == RenderPath::Fast && !self.nothing_visible())
            .then(|| self.neighbours.surface())
            .flatten();
        let bins = surface.and_then(|s| FaceBins::new(s, rays, tile).map(|b| (s, b)));
        let rendered: Vec<(Vec<RayResult>, RenderStats)> = tiles
            .par_iter()
            .map(|&(x, y)| {
                let mut stats = RenderStats::default();
                let (i_end, j_end) = (((x + 1) * tile).min(w), ((y + 1) * tile).min(h));
                let tile_width = i_end - x * tile;
                let tile_rays: Vec<(DVec3, DVec3)> = (y * tile..j_end)
                    .flat_map(|j| (x * tile..i_end).map(move |i| rays.ray(i, j)))
                    .collect();
                let lists = bins
                    .as_ref()
                    .map(|(s, b)| TileFaces::new(s, b, (x, y), &tile_rays, tile_width));
                let mut px = Vec::with_capacity(tile_rays.len());
                let mut hint = None;
                for (k, &(o, d)) in tile_rays.iter().enumerate() {
                    let (i, j) = (
                        x * tile + k as u32 % tile_width,
                        y * tile + k as u32 / tile_width,
                    );
                    let stop = depth_in
                        .map(|dd| dd[j as usize * w as usize + i as usize] as f64)
                        .unwrap_or(f64::INFINITY);
                    let faces = lists.as_ref().and_then(|l| l.of(k, o, d));
                    px.push(self.cast_with_hint(o, d, stop, &mut hint, faces, &mut stats));
                }
                (px, stats)
            })
            .collect();
        let mut image = Image::new(w, h);
        let mut stats = RenderStats::default();
        for (&(x, y), (px, s)) in tiles.iter().zip(rendered) {
            stats += s;
            let mut it = px.into_iter();
            for j in y * tile..((y + 1) * tile).min(h) {
                for i in x * tile..((x + 1) * tile).min(w) {
                    if let Some(r) = it.next() {
                        let at = j as usize * w as usize + i as usize;
                        image.rgba[at] = r.rgba.map(|v| v as f32);
                        image.depth[at] = r.depth as f32;
                    }
                }
            }
        }
        Ok((image, stats))
    }
}
