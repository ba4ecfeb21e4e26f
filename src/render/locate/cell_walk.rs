//! The `fast` path's locator: the ray marches from cell to cell through exit faces
//! ([`crate::render::walk::march`]), so a sample is proposed to the cell the ray is in at its
//! `t` and tested there alone (Newton warm-started in the previous sample's cell, the cell's
//! inverse-map set-up reused), with a walk over face neighbours where that test fails, and
//! the structure only where both give up or the ray has just entered the mesh.
//!
//! - **Far samples.** A sample more than the march's reach ahead (about: the distance past
//!   the current cell's exit in the ray's typical chord, [`March::cells_ahead`], against the
//!   options' reach times the cells a structure look-up tests) is located through the
//!   structure instead of by crossing every cell on the way, where the boundary surface
//!   proves the ray stays in the mesh from the previous sample up to it
//!   ([`crate::render::RenderStats::far_locates`]).
//! - **Exits.** Where the march leaves the mesh by the plane of a face without a neighbour,
//!   the next sample is proved outside by parity where it can be
//!   ([`crate::render::boundary::proof`]); else a local search or the structure says.
//! - **Outside space.** With a boundary surface, the samples from a point known to be outside
//!   up to where the ray may first cross a boundary face are passed over; without one, those
//!   outside every piece's bound of the structure ([`crate::accel::skip`]).
//! - **Entries.** A sample with no previous cell is found by a march from the cell of the
//!   boundary face the ray may enter through, or by a walk from the previous ray's first cell
//!   (or the visible cell a jump landed by), or through the structure.
//! - **Jumps.** A sample in a cell that adds nothing is passed over without interpolation; the
//!   ray then jumps to the next stretch where the structure may hold a cell that adds
//!   something, passing over the samples before it.

use glam::DVec3;

use super::{Locate, Next};
use crate::accel::RaySpan;
use crate::render::accumulate::Accumulate;
use crate::render::boundary::chords::Chord;
use crate::render::boundary::proof::{Exit, ProvedExit};
use crate::render::boundary::Stretch;
use crate::render::frame::Frame;
use crate::render::ray::{End, Ray};
use crate::render::stats::Work;
use crate::render::walk::march::March;
use crate::render::walk::point::{walk_within, WalkEnd, WalkWork, MAX_ENTRY_PLANE_STEPS};
use crate::render::walk::Cells;

/// Marches a ray from cell to cell (see the module documentation).
pub(crate) struct CellWalk<'f> {
    frame: &'f Frame<'f>,
    ray: &'f Ray<'f>,
    cells: Cells<'f>,
    /// The previous ray's first cell (a start for this ray's first entry).
    hint: Option<u32>,
    /// Whether a sample of this ray was found in a cell.
    located: bool,
    /// The last located cell and parameters; `None` outside the mesh.
    prev: Option<(u32, DVec3)>,
    /// The `t` of the sample `prev` holds.
    prev_t: f64,
    /// The march along the ray through `prev`'s cell.
    march: March,
    /// The ray lies in a piece's bound up to here (from the last empty-space query).
    bound_until: f64,
    /// The ray may lie in a piece of a cell that adds something up to here (from the last
    /// jump query).
    adds_until: f64,
    /// The cell of the piece a jump landed by (where the next location starts).
    jumped_to: Option<u32>,
    /// The ray is outside the mesh before here (from the last point known to be outside),
    /// and may enter it through a face of `surface_cell`.
    outside_until: f64,
    surface_cell: Option<u32>,
    /// The ray is in the mesh from a located sample up to here (the next possible boundary
    /// crossing), for locating far samples through the structure.
    in_mesh_until: f64,
    /// Where the sample past an exit was proved outside.
    proved: Option<ProvedExit>,
    /// The march left the mesh since the last located sample (the ray may have come back).
    crossed: bool,
}

impl<'f> CellWalk<'f> {
    /// Where the ray may next cross the boundary from `t_outside` (a point outside) up to its
    /// end, and the cell of that face; `(−∞, None)` without a boundary surface.
    fn next_surface_crossing(&self, t_outside: f64, work: &mut Work) -> (f64, Option<u32>) {
        let Some(surface) = self.frame.surface else {
            return (f64::NEG_INFINITY, None);
        };
        let mut c = crate::accel::Counters::default();
        let next = surface.next_crossing(self.ray, t_outside, self.ray.t_out, &mut c);
        work.surface(&c);
        match next {
            Some((t, c)) => (t, Some(c)),
            None => (self.ray.t_out, None),
        }
    }

    /// Whether the ray, in the mesh at `self.prev_t`, stays in it up to `t`: where no boundary
    /// face's bound lies on the way ([`crate::render::boundary::surface::BoundarySurface::next_crossing`];
    /// conservative, so `true` is proved). `in_mesh_until` keeps the last answer: the samples'
    /// `t` only grow. `false` without the boundary surface.
    fn in_mesh_until(&mut self, t: f64, work: &mut Work) -> bool {
        let Some(surface) = self.frame.boundary.surface else {
            return false;
        };
        if t >= self.in_mesh_until {
            let mut c = crate::accel::Counters::default();
            self.in_mesh_until = surface
                .next_crossing(self.ray, self.prev_t, self.ray.t_out, &mut c)
                .map_or(f64::INFINITY, |(c, _)| c);
            work.surface(&c);
        }
        t < self.in_mesh_until
    }

    /// From the previous sample's cell: the sample at `t` located far ahead through the
    /// structure, or by the march (and the walk, and the boundary searches past an exit).
    /// `None` where there is no previous cell or the march left the mesh undecided; inside
    /// it, `None` for a sample outside the mesh.
    fn march_on(
        &mut self,
        t: f64,
        acc: &impl Accumulate,
        work: &mut Work,
    ) -> Option<Option<(u32, DVec3)>> {
        let (c, q) = self.prev?;
        let volume = self.frame.volume;
        // The march follows `prev` (set after every located sample).
        debug_assert_eq!(self.march.cell(), c);
        let p = self.ray.at(t);
        // Far ahead, in the mesh all the way: locate through the structure.
        if self.march.cells_ahead(t) > self.frame.march_reach && self.in_mesh_until(t, work) {
            if let Some(f) = volume.accel().locate(volume.mesh(), p, &mut work.counters) {
                work.stats.far_locates += 1;
                self.march.place(f.0, t);
                return Some(Some(f));
            }
        }
        let mut walk = WalkWork::default();
        let no_parameters = |cell| acc.adds_nothing(cell);
        let end = self.march.locate(
            &self.cells,
            self.ray,
            t,
            Some((c, q)),
            no_parameters,
            &mut walk,
        );
        work.counters.hex_tests += walk.tests;
        work.stats.walk_steps += walk.plane_steps;
        work.stats.plane_certified += walk.certified;
        match end {
            WalkEnd::Found(n, _) | WalkEnd::Certified(n) => {
                if n == c {
                    work.stats.previous_cell_hits += 1;
                } else {
                    work.stats.neighbour_hits += 1;
                }
                // A certified sample is in a cell that adds nothing and is passed over: its
                // coordinates, never computed, only seed the next Newton.
                let q = match end {
                    WalkEnd::Found(_, q) => q,
                    _ => DVec3::splat(0.5),
                };
                Some(Some((n, q)))
            }
            WalkEnd::Boundary => self.past_exit(t, (c, q), work),
            WalkEnd::GaveUp => {
                // The march did not follow the ray there: it may have left the mesh on the way.
                self.crossed = true;
                work.stats.structure_locates += 1;
                Some(volume.accel().locate(volume.mesh(), p, &mut work.counters))
            }
        }
    }

    /// The march left the mesh by the planes since the sample in `(c, q)`: the sample at `t`
    /// settled locally where the boundary part proves it outside or finds its cell.
    fn past_exit(
        &mut self,
        t: f64,
        (c, q): (u32, DVec3),
        work: &mut Work,
    ) -> Option<Option<(u32, DVec3)>> {
        self.prev = None;
        self.crossed = true;
        let stretch = Stretch {
            ray: self.ray,
            t_inside: self.prev_t,
            t,
            inside_cell: c,
        };
        let guess = if self.march.cell() == c {
            q
        } else {
            DVec3::splat(0.5)
        };
        let face = (self.march.cell(), self.march.exit_face()? as u8);
        match self
            .frame
            .boundary
            .past_exit(stretch, face, guess, self.ray.t_out, work)
        {
            Exit::Inside(c, q) => Some(Some((c, q))),
            Exit::Outside(exit) => {
                self.proved = Some(exit);
                Some(None)
            }
            Exit::Undecided => None,
        }
    }

    /// The sample at `t` with no previous cell, past the space known to be outside: where
    /// the ray lies in no piece's bound, the stretch to pass over; else the sample's cell, if
    /// any (`Err` carries the answer for the loop).
    fn enter(&mut self, t: f64, work: &mut Work) -> Result<Option<(u32, DVec3)>, Next> {
        let accel = self.frame.volume.accel();
        // Within the span of a bound found for an earlier sample, the sample is in that bound:
        // no need to ask the structure again. With the boundary surface, which skips from the
        // points known to be outside, the structure's bounds cost more to traverse than they
        // save: they are not asked.
        let span = if t <= self.bound_until {
            Some((t, self.bound_until))
        } else if self.frame.surface.is_some() {
            Some((t, t))
        } else {
            let span = RaySpan {
                origin: self.ray.origin,
                dir: self.ray.dir,
                t0: t,
                t1: self.ray.t_out,
            };
            accel.next_bound(span, &mut work.counters)
        };
        let Some((te, tx)) = span else {
            return Err(Next::NoBounds);
        };
        self.bound_until = tx;
        if te > t {
            return Err(Next::LeftBounds(te));
        }
        if !accel.may_hold(self.ray.at(t), &mut work.counters) {
            // In no piece's bound: outside the mesh, as a sample located nowhere is.
            work.stats.space_skips += 1;
            return Ok(None);
        }
        // After a jump, the cell jumped to is the hint. The previous ray's first cell is a
        // hint for this ray's first entry only: later, it lies far behind.
        let hint = self
            .jumped_to
            .take()
            .or(if self.located { None } else { self.hint });
        let surface_cell = self.surface_cell.take();
        Ok(self.locate_entry(t, surface_cell, hint, work))
    }

    /// The location of the sample at `t` with no previous cell: a march along the ray from
    /// `surface_cell` (the cell of the boundary face the ray may enter through), or else a
    /// walk from `hint`; the structure where they fail.
    fn locate_entry(
        &mut self,
        t: f64,
        surface_cell: Option<u32>,
        hint: Option<u32>,
        work: &mut Work,
    ) -> Option<(u32, DVec3)> {
        let mesh = self.cells.mesh;
        let p = self.ray.at(t);
        let mut walk = WalkWork::default();
        let end = match (surface_cell, hint) {
            (Some(c), _) => {
                self.march.move_to(mesh, c, self.ray);
                let never = |_| false;
                Some(
                    self.march
                        .locate(&self.cells, self.ray, t, None, never, &mut walk),
                )
            }
            (None, Some(h)) => Some(walk_within(
                &self.cells,
                h,
                None,
                p,
                MAX_ENTRY_PLANE_STEPS,
                &mut walk,
            )),
            (None, None) => None,
        };
        work.counters.hex_tests += walk.tests;
        work.stats.walk_steps += walk.plane_steps;
        if let Some(WalkEnd::Found(c, q)) = end {
            work.stats.entry_walk_hits += 1;
            return Some((c, q));
        }
        work.stats.structure_locates += 1;
        self.frame
            .volume
            .accel()
            .locate(mesh, p, &mut work.counters)
    }
}

impl<'f> Locate<'f> for CellWalk<'f> {
    fn start(frame: &'f Frame<'f>, ray: &'f Ray<'f>, hint: Option<u32>, work: &mut Work) -> Self {
        let mut walk = CellWalk {
            frame,
            ray,
            cells: frame.boundary.cells,
            hint,
            located: false,
            prev: None,
            prev_t: f64::NAN,
            march: March::new(),
            bound_until: f64::NEG_INFINITY,
            adds_until: f64::NEG_INFINITY,
            jumped_to: None,
            outside_until: f64::NEG_INFINITY,
            surface_cell: None,
            in_mesh_until: f64::NEG_INFINITY,
            proved: None,
            crossed: false,
        };
        // A ray starting on the (padded) box of the mesh starts outside it; one starting at
        // the eye or on a clipping plane may start inside.
        if ray.start == End::Outside {
            (walk.outside_until, walk.surface_cell) = walk.next_surface_crossing(ray.t_in, work);
        }
        walk
    }

    fn locate(&mut self, t: f64, acc: &impl Accumulate, work: &mut Work) -> Next {
        let found = match self.march_on(t, acc, work) {
            Some(found) => found,
            // Known to be outside the mesh up to a possible boundary crossing.
            None if t < self.outside_until => return Next::OutsideUntil(self.outside_until),
            // Outside the mesh or at the ray's start: skip the empty space.
            None => match self.enter(t, work) {
                Ok(found) => found,
                Err(next) => return next,
            },
        };
        self.prev = found;
        self.prev_t = t;
        match found {
            Some((cell, param)) => {
                // The march follows `prev` (and is not used while there is none).
                if self.march.cell() != cell {
                    self.march.move_to(self.cells.mesh, cell, self.ray);
                }
                self.located = true;
                Next::Inside {
                    cell,
                    param,
                    crossed: std::mem::take(&mut self.crossed),
                }
            }
            None => {
                self.crossed = false;
                Next::Outside(self.proved.take())
            }
        }
    }

    fn passed_outside(&mut self, t: f64, proved: Option<ProvedExit>, work: &mut Work) {
        (self.outside_until, self.surface_cell) = match proved {
            Some(p) => p.next,
            None => self.next_surface_crossing(t, work),
        };
    }

    fn jump(&mut self, t_next: f64, acc: &impl Accumulate, work: &mut Work) -> Option<f64> {
        if t_next <= self.adds_until {
            return None;
        }
        let span = RaySpan {
            origin: self.ray.origin,
            dir: self.ray.dir,
            t0: t_next,
            t1: self.ray.t_out,
        };
        let next = acc.next_adding(self.frame.volume.accel(), span, &mut work.counters)?;
        let until = match next {
            Some((te, tx, _)) if te <= t_next => {
                self.adds_until = tx;
                return None;
            }
            Some((te, _, c)) => {
                self.jumped_to = c;
                te
            }
            None => self.ray.t_out,
        };
        self.prev = None;
        self.proved = None;
        (self.outside_until, self.surface_cell) = (f64::NEG_INFINITY, None);
        Some(until)
    }

    fn locate_chord(&mut self, chord: &Chord, work: &mut Work) -> Option<(u32, DVec3)> {
        let p = self.ray.at(chord.middle());
        let mesh = self.cells.mesh;
        if (chord.cell as usize) < mesh.cell_count() {
            let mut walk = WalkWork::default();
            let end = walk_within(
                &self.cells,
                chord.cell,
                None,
                p,
                MAX_ENTRY_PLANE_STEPS,
                &mut walk,
            );
            work.counters.hex_tests += walk.tests;
            work.stats.walk_steps += walk.plane_steps;
            if let WalkEnd::Found(c, q) = end {
                return Some((c, q));
            }
        }
        work.stats.structure_locates += 1;
        self.frame
            .volume
            .accel()
            .locate(mesh, p, &mut work.counters)
    }

    fn outside_through(&self, t: f64) -> bool {
        self.frame.surface.is_some() && self.outside_until >= t
    }
}
