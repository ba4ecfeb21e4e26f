//! The renderer: a volume with a transfer table and options, which casts the rays of an
//! image in parallel tiles ([`Renderer::render_rays`]) or one at a time ([`Renderer::cast`]).
//!
//! # Sampling
//! A ray (origin `o`, unit direction `d`) is clipped to the mesh's bounding box (padded by
//! `1e-9` of its diagonal so samples on the boundary are kept) and to `t ≥ 0` (a camera inside
//! the mesh starts at the eye), then to the clipping planes if any
//! ([`RenderOptions::clip_planes`]), then to the opaque-geometry depth if one is given. Samples
//! lie at `t_k = t_in + (k + ½)·step`, `k = 0, 1, …` while `t_k < t_out`; each stands for a
//! segment of length `step` (midpoint rule), so the transfer table's opacities are corrected
//! to `step`. A sample next to a boundary crossing stands for the in-mesh part of its segment
//! only ([`RenderOptions::boundary_segments`]), and with the boundary surface of
//! [`face_neighbours`](super::face_neighbours) the pieces of the ray in the mesh too short to
//! hold a sample (chords) are sampled at their middles ([`RenderStats::chord_samples`]).
//!
//! # Interpolation and gradient opacity
//! A located sample's scalar is the trilinear interpolant of its cell's corner values, or with
//! [`Interpolation::Nearest`] the value of the nearest corner (cell data: the cell's value).
//! Its colour and step-corrected opacity come from the transfer table; with
//! [`RenderOptions::gradient_opacity`] set, the opacity per unit distance is multiplied by the
//! factor of the gradient magnitude before the step correction. The gradient is evaluated only
//! when shading or gradient opacity is on, and only for samples the transfer function does not
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
//! - **paper** ([`RenderPath::Paper`]): every sample is located from scratch through the
//!   structure ([`Accel::locate`]) — what the talk measured.
//! - **fast** ([`RenderPath::Fast`]): the ray marches from cell to cell through exit faces,
//!   with the face neighbours ([`Renderer::with_neighbours`], [`Renderer::with_topology`]);
//!   the space outside the mesh is skipped (by the boundary surface, or the structure's
//!   bounds), and so are the cells the transfer function makes transparent (an intensity
//!   projection: the cells that cannot beat the ray's extreme), jumping over them through
//!   the structure. Where the table is transparent everywhere nothing could be seen: no ray
//!   takes a sample. With the same neighbours, the image equals the paper path's up to the
//!   choice between two cells on a shared face (both valid, values equal to the inverse map's
//!   tolerance, `~1e-9` relative); the paper path without neighbours (as the CLI runs it)
//!   finds boundary crossings by bisection, to within `step / 2^(BISECTIONS + 1)` of the
//!   exact ones ([`super::BISECTIONS`]).
//!
//! Both count their work in [`RenderStats`].
//!
//! # Threads
//! The image is cut into square tiles ([`RenderOptions::tile`], default 16) rendered in
//! parallel with rayon; every pixel is computed alone, and the counters are integer sums, so
//! image and counters are identical whatever the number of threads.

use std::sync::OnceLock;

use glam::DVec3;
use rayon::prelude::*;

use super::accumulate::integrate::guard::Guard;
use super::accumulate::integrate::table::Extinction;
use super::accumulate::integrate::{Bounded, GUARD_SHARE, TERMINATION_SHARE};
use super::accumulate::{
    Accumulate, AccumulatorKind, FrontToBack, Integrating, Projection, RayResult,
};
use super::boundary::ray_faces::{FaceBins, TileFaces};
use super::boundary::surface::BoundarySurface;
use super::boundary::Boundary;
use super::camera::{Camera, RayGenerator, RaySource};
use super::cast::{cast, cast_into};
use super::faces::Topology;
use super::field::Volume;
use super::frame::Frame;
use super::image::Image;
use super::locate::{LocatorKind, LookupEach, WalkCells};
use super::options::{Blend, RenderOptions, RenderPath, MAX_SAMPLES_PER_RAY};
use super::periodic::{Copies, Piece};
use super::ray::{box_span, End, Ray, RayFace};
use super::stats::{RenderStats, Work};
use super::transfer::{TransferFunction, TransferTable};
use super::transparency::TransparentCells;
use super::walk::{Cells, Neighbours, NoNeighbours};
use crate::accel::bvh::NodeRanges;
use crate::accel::skip::CellMarks;
use crate::accel::Accel;
use crate::error::show_number;
use crate::geometry::bounds::Aabb;
use crate::Error;

#[cfg(doc)]
use super::options::Interpolation;

/// What a renderer derives from its transfer table and volume before its rays: the cells the
/// table makes wholly transparent, where the structure holds the others, and (for an
/// intensity projection) the scalar range below each node ([`Renderer::into_derived`]). A
/// later renderer of the same volume (same mesh, structure and scalars) takes them over where
/// its table is the same ([`Renderer::with_derived`]), as a mapper's next frame does, instead
/// of making them again.
#[derive(Debug)]
pub struct Derived {
    table: TransferTable,
    transparent: TransparentCells,
    visible: Option<CellMarks>,
    ranges: Option<Option<NodeRanges>>,
    /// The active cells of an error-bounded render, with the error they were made for.
    guard: Option<(f64, Guard)>,
}

/// A volume with a transfer table and options: casts rays and renders images.
pub struct Renderer<'a> {
    volume: &'a Volume<'a>,
    table: TransferTable,
    options: RenderOptions,
    neighbours: &'a dyn Neighbours,
    surface: Option<&'a BoundarySurface>,
    clip_box: Aabb,
    /// The periodic copies of the sector to draw instead of the sector alone, with the box
    /// their rays are clipped to.
    copies: Option<(Copies, Aabb)>,
    /// The volume as it reads in each copy drawn (from the first), where what it draws is a
    /// vector's component that turns with the copies; empty otherwise.
    turned: Vec<Volume<'a>>,
    /// Each cell's scalar range over every copy drawn, where they differ (see `turned`).
    wheel_ranges: Option<Vec<[f64; 2]>>,
    /// The transfer function, sampled again over the copies' range where it differs.
    transfer: TransferFunction,
    /// The cells the table makes wholly transparent, for the fast path; made before a render's
    /// rays are cast (or on a single ray's first use).
    transparent: OnceLock<TransparentCells>,
    /// Where the structure holds a cell that is not wholly transparent (its nodes or its grid
    /// cells), for the fast path's jumps over transparent space; made with the transparent
    /// cells.
    visible: OnceLock<CellMarks>,
    /// The scalar range below each of a BVH's nodes, for an intensity projection's jumps over
    /// cells that cannot beat the extreme (`None` for a grid).
    ranges: OnceLock<Option<NodeRanges>>,
    /// The transfer table read as extinction, for an error-bounded render.
    extinction: Option<Extinction>,
    /// The cells whose steps an error-bounded render caps, made like the transparent cells.
    guard: OnceLock<Guard>,
}

impl<'a> Renderer<'a> {
    /// Samples `transfer` over the volume's scalar range for `options.step`; fails on a bad
    /// transfer function, step, error, or a step so small that a ray would take more than
    /// [`MAX_SAMPLES_PER_RAY`] samples across the mesh. For an error-bounded render
    /// ([`RenderOptions::error_bounded`]) the early termination is raised to leave out no more
    /// than its share of the error ([`Renderer::options`] tells the one used).
    pub fn new(
        volume: &'a Volume<'a>,
        transfer: &TransferFunction,
        options: &RenderOptions,
    ) -> Result<Renderer<'a>, Error> {
        if let Some(e) = options.max_error {
            if !(e > 0.0 && e.is_finite()) {
                return Err(Error::Invalid(format!(
                    "max error {} must be a positive number of 1/255",
                    show_number(e)
                )));
            }
        }
        if options.march_reach.is_nan() || options.march_reach < 0.0 {
            return Err(Error::Invalid(format!(
                "march reach {} must be a number of cells, 0 or more (inf to always march)",
                show_number(options.march_reach)
            )));
        }
        let [lo, hi] = volume.scalar_range();
        let table = transfer.table(lo, hi, options.step, options.table_size)?;
        let bounds = volume.bounds();
        let diag = bounds.diagonal();
        if diag / options.step > MAX_SAMPLES_PER_RAY {
            return Err(Error::Invalid(format!(
                "step {} is too small for a mesh of diagonal {}",
                show_number(options.step),
                show_number(diag)
            )));
        }
        let clip_box = clip_box(bounds);
        let mut options = *options;
        let extinction = match options.max_error {
            Some(e) if options.error_bounded() => {
                let left_out = 1.0 - TERMINATION_SHARE * e / 255.0;
                options.early_termination = options.early_termination.max(left_out);
                Some(Extinction::new(&table, options.step))
            }
            _ => None,
        };
        Ok(Renderer {
            volume,
            table,
            options,
            neighbours: &NoNeighbours,
            surface: None,
            clip_box,
            copies: None,
            turned: Vec::new(),
            wheel_ranges: None,
            transfer: transfer.clone(),
            transparent: OnceLock::new(),
            visible: OnceLock::new(),
            ranges: OnceLock::new(),
            extinction,
            guard: OnceLock::new(),
        })
    }

    /// Walks `neighbours` on the fast path (with no boundary surface: the space outside the
    /// mesh is skipped by the structure's bounds, and no chord is sampled).
    pub fn with_neighbours(mut self, neighbours: &'a dyn Neighbours) -> Renderer<'a> {
        self.neighbours = neighbours;
        self.surface = None;
        self
    }

    /// Walks the face neighbours of `topology` on the fast path, with its boundary surface:
    /// the space outside the mesh is skipped from the points known to be outside, boundary
    /// crossings are found exactly, and the pieces of rays in the mesh too short for a sample
    /// are sampled.
    pub fn with_topology(mut self, topology: &'a Topology) -> Renderer<'a> {
        self.neighbours = topology.faces();
        self.surface = Some(topology.surface());
        self
    }

    /// Draws `copies` of the volume, a rotationally periodic sector, about their axis instead
    /// of the sector alone: each ray is cast piece by piece through the copies' wedges, each
    /// piece turned back into the sector (see [`super::periodic`]). Give it the topology of
    /// the wheel ([`Topology::with_periodic_sides`]) on the fast path, so that no boundary is
    /// met where the copies meet.
    ///
    /// Where the volume draws a component of a vector array, each copy draws the component
    /// of the vector turned with it (as the Angular Periodic Filter rotates vectors): the
    /// renderer holds that component per copy drawn (8 bytes a point or cell value and 16 a
    /// cell's range, per copy), and samples the transfer function over the copies' range
    /// ([`Copies::scalar_range`]). Scalars and magnitudes are the sector's in every copy. An
    /// error for a tensor's component, or a turned value that is not finite.
    pub fn with_copies(mut self, copies: Copies) -> Result<Renderer<'a>, Error> {
        let wheel = clip_box(copies.wheel_box());
        let (first, end) = copies.range();
        let mut turned = Vec::new();
        for copy in first..end {
            match self.volume.turned(copies.turn_of(copy))? {
                Some(volume) => turned.push(volume),
                None => break,
            }
        }
        if !turned.is_empty() {
            let ranges = wheel_cell_ranges(&turned);
            let [lo, hi] = copies.scalar_range(self.volume)?;
            let o = &self.options;
            self.table = self.transfer.table(lo, hi, o.step, o.table_size)?;
            self.wheel_ranges = Some(ranges);
            self.transparent = OnceLock::new();
            self.visible = OnceLock::new();
            self.ranges = OnceLock::new();
        }
        self.turned = turned;
        self.copies = Some((copies, wheel));
        Ok(self)
    }

    /// Every cell's `[min, max]` of the scalar over what the renderer draws: the volume's, or
    /// over every copy drawn where they differ.
    fn cell_ranges(&self) -> &[[f64; 2]] {
        self.wheel_ranges
            .as_deref()
            .unwrap_or_else(|| self.volume.cell_ranges())
    }

    /// What this renderer derived before its rays (`None` if it made nothing yet), for a later
    /// renderer of the same volume ([`Renderer::with_derived`]).
    pub fn into_derived(self) -> Option<Derived> {
        let transparent = self.transparent.into_inner()?;
        let error = self.options.max_error.unwrap_or(f64::NAN);
        Some(Derived {
            table: self.table,
            transparent,
            visible: self.visible.into_inner(),
            ranges: self.ranges.into_inner(),
            guard: self.guard.into_inner().map(|g| (error, g)),
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
            if let Some(ranges) = derived.ranges {
                let _ = self.ranges.set(ranges);
            }
            if let Some((error, guard)) = derived.guard {
                if Some(error) == self.options.max_error {
                    let _ = self.guard.set(guard);
                }
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
    fn transparent_cells(&self) -> &TransparentCells {
        self.transparent
            .get_or_init(|| TransparentCells::new_sequential(self.cell_ranges(), &self.table))
    }

    /// Where the structure holds a cell the table does not make wholly transparent: made on
    /// first use, on the calling thread, like [`Renderer::transparent_cells`].
    fn visible_cells(&self) -> &CellMarks {
        self.visible.get_or_init(|| self.make_visible_cells(false))
    }

    fn make_visible_cells(&self, parallel: bool) -> CellMarks {
        let transparent = self.transparent_cells();
        let visible = |c: u32| !transparent.contains(c);
        self.volume.accel().mark_cells(visible, parallel)
    }

    /// The scalar range of the cells below each of a BVH's nodes (`None` for a grid), for an
    /// intensity projection's jumps over the cells that cannot beat a ray's extreme: made on
    /// first use, on the calling thread, like [`Renderer::transparent_cells`].
    fn node_ranges(&self) -> Option<&NodeRanges> {
        self.ranges
            .get_or_init(|| self.make_node_ranges(false))
            .as_ref()
    }

    fn make_node_ranges(&self, parallel: bool) -> Option<NodeRanges> {
        let ranges = self.cell_ranges();
        let range = |c: u32| ranges[c as usize];
        self.volume.accel().node_ranges(range, parallel)
    }

    /// The active cells of an error-bounded render (made on first use, on the calling
    /// thread, like [`Renderer::transparent_cells`]); `None` for the others.
    fn guard(&self) -> Option<&Guard> {
        let table = self.extinction.as_ref()?;
        Some(self.guard.get_or_init(|| self.make_guard(table)))
    }

    fn make_guard(&self, table: &Extinction) -> Guard {
        let error = self.options.max_error.unwrap_or(0.0) / 255.0;
        let ranges = self.volume.cell_ranges();
        Guard::new(self.volume.mesh(), ranges, table, GUARD_SHARE * error)
    }

    /// The ray's `[t_in, t_out]` within the mesh's (padded) box, `t ≥ 0` and the clipping
    /// planes, if not empty.
    pub fn clip(&self, origin: DVec3, dir: DVec3) -> Option<(f64, f64)> {
        let span = box_span(self.world_box(), origin, dir)?;
        self.options.clip_planes.clip_span(origin, dir, span)
    }

    /// The box the rays are clipped to: the mesh's, padded, or the wheel's of its copies.
    fn world_box(&self) -> &Aabb {
        self.copies.as_ref().map_or(&self.clip_box, |(_, b)| b)
    }

    /// What the rays of a render share.
    fn frame(&self) -> Frame<'_> {
        let options = &self.options;
        let (mesh, accel) = (self.volume.mesh(), self.volume.accel());
        let fast = options.path == RenderPath::Fast;
        // Only the fast path passes over cells that add nothing, and that needs what the
        // table makes transparent (compositing) or the nodes' ranges (a projection).
        let skipping = fast && !self.nothing_visible();
        let compositing = options.blend == Blend::Composite;
        // How far the march goes before the structure is asked: the reach in cells, times
        // the cells a look-up through the structure tests.
        let march_reach = if fast && options.march_reach.is_finite() {
            options.march_reach * accel.lookup_tests(mesh)
        } else {
            options.march_reach
        };
        Frame {
            volume: self.volume,
            options,
            table: &self.table,
            boundary: Boundary {
                cells: Cells {
                    mesh,
                    neighbours: self.neighbours,
                },
                accel,
                bounds: self.volume.bounds(),
                surface: self.surface,
                fast,
                segments: options.boundary_segments,
            },
            surface: if fast { self.surface } else { None },
            march_reach,
            transparent: (skipping && compositing).then(|| self.transparent_cells()),
            visible: (skipping && compositing).then(|| self.visible_cells()),
            ranges: if skipping && !compositing {
                self.node_ranges()
            } else {
                None
            },
            cell_ranges: self.cell_ranges(),
            bounded: self.extinction.as_ref().and_then(|table| {
                Some(Bounded {
                    table,
                    guard: self.guard()?,
                    error: options.max_error? / 255.0,
                    step: options.step,
                })
            }),
        }
    }

    /// Runs `parts` with the locator, accumulator and stepping policy this render's options
    /// choose.
    fn with_parts<P: Parts>(&self, parts: P) -> P::Output {
        let bounded = self.extinction.is_some();
        match (self.options.path, self.options.blend, bounded) {
            (RenderPath::Paper, Blend::Composite, false) => parts.run::<LookupEach, FrontToBack>(),
            (RenderPath::Paper, Blend::Composite, true) => parts.run::<LookupEach, Integrating>(),
            (RenderPath::Paper, _, _) => parts.run::<LookupEach, Projection>(),
            (RenderPath::Fast, Blend::Composite, false) => parts.run::<WalkCells, FrontToBack>(),
            (RenderPath::Fast, Blend::Composite, true) => parts.run::<WalkCells, Integrating>(),
            (RenderPath::Fast, _, _) => parts.run::<WalkCells, Projection>(),
        }
    }

    /// Casts one ray (unit `dir`), stopping at `t_stop` (opaque geometry; `+∞` for none).
    pub fn cast(
        &self,
        origin: DVec3,
        dir: DVec3,
        t_stop: f64,
        stats: &mut RenderStats,
    ) -> RayResult {
        let frame = self.frame();
        self.with_parts(OneRay {
            renderer: self,
            frame: &frame,
            ray: (origin, dir, t_stop),
            stats,
        })
    }

    /// Casts the ray `(origin, dir)` up to `t_stop`, with the list of the boundary faces its
    /// line meets where one was made, from `hint` (the previous ray's first cell, updated).
    fn cast_ray<L: LocatorKind, A: AccumulatorKind>(
        &self,
        frame: &Frame,
        (origin, dir, t_stop, faces): (DVec3, DVec3, f64, Option<&[RayFace]>),
        hint: &mut Option<u32>,
        stats: &mut RenderStats,
    ) -> RayResult {
        stats.rays += 1;
        if self.nothing_visible() {
            return RayResult::NONE;
        }
        let planes = &self.options.clip_planes;
        let Some(ray) = Ray::clipped(origin, dir, self.world_box(), planes, t_stop) else {
            return RayResult::NONE;
        };
        match &self.copies {
            None => cast::<L, A>(frame, &ray.with_faces(faces), hint, stats),
            Some((copies, _)) => self.cast_copies::<L, A>(frame, copies, &ray, hint, stats),
        }
    }

    /// Casts `ray` through the periodic `copies`: piece by piece, each in its copy's frame,
    /// into one accumulator.
    fn cast_copies<L: LocatorKind, A: AccumulatorKind>(
        &self,
        frame: &Frame,
        copies: &Copies,
        ray: &Ray,
        hint: &mut Option<u32>,
        stats: &mut RenderStats,
    ) -> RayResult {
        let mut acc = A::start(frame);
        acc.span(ray.t_out - ray.t_in);
        let mut pieces = Vec::new();
        copies.pieces(ray.origin, ray.dir, (ray.t_in, ray.t_out), &mut pieces);
        for piece in &pieces {
            let Some(sub) = self.piece_ray(copies, ray, piece, stats) else {
                continue;
            };
            // A copy whose vectors turn reads its own component (its transparent cells are
            // among the frame's, made from every copy's ranges).
            let turned = self.turned.get((piece.copy - copies.range().0) as usize);
            let copy_frame = Frame {
                volume: turned.unwrap_or(frame.volume),
                ..*frame
            };
            let (a, stopped) = cast_into::<L, _>(&copy_frame, &sub, hint, acc, stats);
            acc = a;
            if stopped {
                break;
            }
        }
        acc.finish()
    }

    /// The part of `ray` in `piece`, turned back into the sector and clipped to its box: its
    /// ends on the wedges' half-planes are on the side of the mesh that locating them in the
    /// sector finds, and the segment of its last sample ends there; `None` where the piece
    /// misses the sector's box.
    fn piece_ray<'r>(
        &self,
        copies: &Copies,
        ray: &Ray,
        piece: &Piece,
        stats: &mut RenderStats,
    ) -> Option<Ray<'r>> {
        let origin = copies.point_in_sector(piece.copy, ray.origin);
        let dir = copies.dir_in_sector(piece.copy, ray.dir);
        let (b0, b1) = box_span(&self.clip_box, origin, dir)?;
        let (t_in, t_out) = (piece.t0.max(b0), piece.t1.min(b1));
        if t_in >= t_out {
            return None;
        }
        let mut work = Work::new(stats);
        let mut side = |t: f64, known: End| match known {
            End::Outside => End::Outside,
            _ => {
                let p = origin + dir * t;
                let mesh = self.volume.mesh();
                match self.volume.accel().locate(mesh, p, &mut work.counters) {
                    Some(_) => End::In,
                    None => End::Outside,
                }
            }
        };
        // On the sector's box, outside; on the ray's own ends, what is known there; on a
        // half-plane between copies, where the mesh is.
        let start = match (t_in > piece.t0, piece.t0 == ray.t_in) {
            (true, _) => End::Outside,
            (false, true) => side(t_in, ray.start),
            (false, false) => side(t_in, End::Unknown),
        };
        let end = match (t_out < piece.t1, piece.t1 == ray.t_out) {
            (true, _) => End::Outside,
            (false, true) => side(t_out, ray.end),
            (false, false) => side(t_out, End::Unknown),
        };
        work.finish();
        let on_half_plane = t_out == piece.t1 && piece.t1 < ray.t_out;
        Some(Ray {
            origin,
            dir,
            faces: None,
            t_in,
            t_out,
            start,
            end,
            ends_on_plane: on_half_plane || (t_out == ray.t_out && ray.ends_on_plane),
        })
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
        if let Some(d) = depth_in {
            if d.len() != w as usize * h as usize {
                return Err(Error::Invalid(format!(
                    "depth image has {} values for a {w}x{h} image",
                    d.len()
                )));
            }
        }
        self.prepare();
        let frame = self.frame();
        let tiles = Tiles {
            rays,
            depth_in,
            tile: self.options.tile.max(1),
            bins: self.face_bins(rays),
        };
        let rendered = self.with_parts(AllTiles {
            renderer: self,
            frame: &frame,
            tiles: &tiles,
        });
        Ok(tiles.assemble(w, h, rendered))
    }

    /// Makes what the rays need before they are cast, in parallel rather than by the first
    /// ray (which would make it alone, sequentially, while the other threads wait): the fast
    /// path's transparency mask, where the structure holds visible cells and the nodes'
    /// ranges; the structure's node tests (kept with the structure: made by its first
    /// render); the cells a look-up through the structure tests.
    fn prepare(&self) {
        if self.options.path == RenderPath::Fast && !self.nothing_visible() {
            if self.options.blend != Blend::Composite && self.ranges.get().is_none() {
                let _ = self.ranges.set(self.make_node_ranges(true));
            }
            if self.transparent.get().is_none() {
                let mask = TransparentCells::new(self.cell_ranges(), &self.table);
                let _ = self.transparent.set(mask);
            }
            if self.visible.get().is_none() {
                let _ = self.visible.set(self.make_visible_cells(true));
            }
        }
        if let Some(table) = &self.extinction {
            if self.guard.get().is_none() {
                let _ = self.guard.set(self.make_guard(table));
            }
        }
        let accel: &Accel = self.volume.accel();
        accel.make_node_shapes();
        if self.options.path == RenderPath::Fast && self.options.march_reach.is_finite() {
            // Measured here once per structure, not by the first ray's thread alone.
            accel.lookup_tests(self.volume.mesh());
        }
    }

    /// The fast path's boundary faces sorted to the image once, for lists per ray in place of
    /// the surface's traversals (see [`super::boundary::ray_faces`]).
    fn face_bins<'s, R: RaySource + ?Sized>(
        &'s self,
        rays: &R,
    ) -> Option<(&'s BoundarySurface, FaceBins)> {
        if self.options.path != RenderPath::Fast || self.nothing_visible() || self.copies.is_some()
        {
            return None;
        }
        let surface = self.surface?;
        FaceBins::new(surface, rays, self.options.tile.max(1)).map(|b| (surface, b))
    }

    /// Casts every ray of `tiles`, tile by tile in parallel, with a locator of kind `L` and an
    /// accumulator of kind `A`: each tile's pixels (row-major) and counters.
    fn render_tiles<L: LocatorKind, A: AccumulatorKind, R: RaySource + ?Sized>(
        &self,
        frame: &Frame,
        tiles: &Tiles<'_, R>,
    ) -> Vec<(Vec<RayResult>, RenderStats)> {
        tiles
            .corners()
            .par_iter()
            .map(|&(x, y)| {
                let mut stats = RenderStats::default();
                let tile = tiles.rays_of(x, y);
                let lists = tiles
                    .bins
                    .as_ref()
                    .map(|(s, b)| TileFaces::new(s, b, (x, y), &tile.rays, tile.width));
                let mut hint = None;
                let pixels = tile.rays.iter().enumerate().map(|(k, &(o, d))| {
                    let stop = tiles.stop(tile.pixel(k));
                    let faces = lists.as_ref().and_then(|l| l.of(k));
                    self.cast_ray::<L, A>(frame, (o, d, stop, faces), &mut hint, &mut stats)
                });
                (pixels.collect(), stats)
            })
            .collect()
    }
}

/// What runs with the parts a render chose ([`Renderer::with_parts`]).
trait Parts {
    /// What it gives.
    type Output;
    /// Runs with a locator of kind `L`, an accumulator of kind `A`.
    fn run<L: LocatorKind, A: AccumulatorKind>(self) -> Self::Output;
}

/// One ray cast alone: its origin, direction and stop.
struct OneRay<'r, 'f> {
    renderer: &'r Renderer<'r>,
    frame: &'r Frame<'f>,
    ray: (DVec3, DVec3, f64),
    stats: &'r mut RenderStats,
}

impl Parts for OneRay<'_, '_> {
    type Output = RayResult;
    fn run<L: LocatorKind, A: AccumulatorKind>(self) -> RayResult {
        let (origin, dir, t_stop) = self.ray;
        let mut hint = None;
        let ray = (origin, dir, t_stop, None);
        self.renderer
            .cast_ray::<L, A>(self.frame, ray, &mut hint, self.stats)
    }
}

/// Every ray of an image's tiles.
struct AllTiles<'r, 'f, 't, R: ?Sized> {
    renderer: &'r Renderer<'r>,
    frame: &'r Frame<'f>,
    tiles: &'r Tiles<'t, R>,
}

impl<R: RaySource + ?Sized> Parts for AllTiles<'_, '_, '_, R> {
    type Output = Vec<(Vec<RayResult>, RenderStats)>;
    fn run<L: LocatorKind, A: AccumulatorKind>(self) -> Self::Output {
        self.renderer
            .render_tiles::<L, A, R>(self.frame, self.tiles)
    }
}

/// The box rays are clipped to for a mesh of box `bounds`: padded by `1e-9` of its diagonal
/// (and what `f64` resolves at its coordinates), so that samples on the boundary are kept.
fn clip_box(bounds: &Aabb) -> Aabb {
    let diag = bounds.diagonal();
    let mag = bounds.min.abs().max(bounds.max.abs()).max_element();
    bounds.padded(1e-9 * diag + 8.0 * f64::EPSILON * mag)
}

/// An image's rays cut into square tiles, with the opaque geometry's depth and the boundary
/// faces sorted to the tiles.
struct Tiles<'r, R: ?Sized> {
    rays: &'r R,
    depth_in: Option<&'r [f32]>,
    tile: u32,
    bins: Option<(&'r BoundarySurface, FaceBins)>,
}

/// One tile's rays, row-major over its pixels.
struct TileRays {
    /// Its first pixel.
    corner: (u32, u32),
    /// Its width in pixels (narrower at the image's right edge).
    width: u32,
    rays: Vec<(DVec3, DVec3)>,
}

impl TileRays {
    /// The pixel of the tile's ray `k`.
    fn pixel(&self, k: usize) -> (u32, u32) {
        (
            self.corner.0 + k as u32 % self.width,
            self.corner.1 + k as u32 / self.width,
        )
    }
}

impl<R: RaySource + ?Sized> Tiles<'_, R> {
    /// The tiles' positions in tiles, row by row.
    fn corners(&self) -> Vec<(u32, u32)> {
        let (w, h) = self.rays.size();
        let (tx, ty) = (w.div_ceil(self.tile), h.div_ceil(self.tile));
        (0..ty).flat_map(|y| (0..tx).map(move |x| (x, y))).collect()
    }

    /// The rays of tile `(x, y)`.
    fn rays_of(&self, x: u32, y: u32) -> TileRays {
        let (w, h) = self.rays.size();
        let tile = self.tile;
        let (i_end, j_end) = (((x + 1) * tile).min(w), ((y + 1) * tile).min(h));
        let rays = (y * tile..j_end)
            .flat_map(|j| (x * tile..i_end).map(move |i| self.rays.ray(i, j)))
            .collect();
        TileRays {
            corner: (x * tile, y * tile),
            width: i_end - x * tile,
            rays,
        }
    }

    /// Where opaque geometry stops the ray of pixel `(i, j)`.
    fn stop(&self, (i, j): (u32, u32)) -> f64 {
        let w = self.rays.size().0;
        self.depth_in
            .map(|dd| dd[j as usize * w as usize + i as usize] as f64)
            .unwrap_or(f64::INFINITY)
    }

    /// The image of the tiles' pixels.
    fn assemble(
        &self,
        w: u32,
        h: u32,
        rendered: Vec<(Vec<RayResult>, RenderStats)>,
    ) -> (Image, RenderStats) {
        let tile = self.tile;
        let mut image = Image::new(w, h);
        let mut stats = RenderStats::default();
        for (&(x, y), (px, s)) in self.corners().iter().zip(rendered) {
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
        (image, stats)
    }
}

/// Every cell's `[min, max]` of the scalar over the volumes of `copies`.
fn wheel_cell_ranges(copies: &[Volume]) -> Vec<[f64; 2]> {
    let first = copies[0].cell_ranges().to_vec();
    copies[1..].iter().fold(first, |mut all, v| {
        for (a, b) in all.iter_mut().zip(v.cell_ranges()) {
            *a = [a[0].min(b[0]), a[1].max(b[1])];
        }
        all
    })
}
