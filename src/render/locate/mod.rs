//! Where the next sample of a ray lies ([`Locate`]): in a cell (with its parametric
//! coordinates), outside the mesh, or past a stretch the locator knows holds nothing to
//! sample. Two locators stand behind the one contract, chosen once per render:
//!
//! - [`lookup::SampleLookup`] (the `paper` path): every sample is located from scratch
//!   through the structure ([`crate::accel::Accel::locate`]) — what the talk measured.
//! - [`cell_walk::CellWalk`] (the `fast` path): the ray marches from cell to cell through
//!   exit faces, so a sample is proposed to the cell the ray is in at its `t` and tested
//!   there alone; it skips the space outside the mesh (by the boundary surface, or the
//!   structure's bounds) and jumps over the cells that add nothing (by the structure's ray
//!   contract, [`crate::accel::skip`]).
//!
//! Both answer with the same cells up to the choice between two cells on a shared face.

pub(crate) mod cell_walk;
pub(crate) mod lookup;

use glam::DVec3;

use super::accumulate::Accumulate;
use super::boundary::chords::Chord;
use super::boundary::proof::ProvedExit;
use super::frame::Frame;
use super::ray::Ray;
use super::stats::Work;

/// Where the next sample lies ([`Locate::locate`]).
#[derive(Clone, Copy, Debug)]
pub(crate) enum Next {
    /// In `cell` at the (unclamped) parameters `param`; `crossed`: the ray may have left the
    /// mesh since the previous position (its crossings there must be looked at).
    Inside {
        /// The cell.
        cell: u32,
        /// The parameters.
        param: DVec3,
        /// Whether the ray may have crossed the boundary since the previous position.
        crossed: bool,
    },
    /// Outside the mesh; with the exit proved by parity where it was (its crossing and the
    /// next possible one).
    Outside(Option<ProvedExit>),
    /// The samples before this `t` lie outside the mesh, known from the last point outside:
    /// pass over them.
    OutsideUntil(f64),
    /// The ray lies in no piece's bound of the structure from the sample up to this `t`: the
    /// samples before it are outside the mesh (and the last sample's segment ends at the
    /// crossing before the sample).
    LeftBounds(f64),
    /// The ray lies in no piece's bound from the sample to its end.
    NoBounds,
}

/// A kind of locator, chosen once per render (its per-ray state is `Locator<'f>`).
pub(crate) trait LocatorKind {
    /// The locator of one ray.
    type Locator<'f>: Locate<'f>;
}

/// Every sample through the structure (the `paper` path).
pub(crate) enum LookupEach {}

impl LocatorKind for LookupEach {
    type Locator<'f> = lookup::SampleLookup<'f>;
}

/// From cell to cell along the ray (the `fast` path).
pub(crate) enum WalkCells {}

impl LocatorKind for WalkCells {
    type Locator<'f> = cell_walk::CellWalk<'f>;
}

/// Finds where the samples of one ray lie, from front to back.
pub(crate) trait Locate<'f>: Sized {
    /// The locator of `ray`, with `hint` (the first cell of the previous ray, usually near
    /// this ray's first).
    fn start(frame: &'f Frame<'f>, ray: &'f Ray<'f>, hint: Option<u32>, work: &mut Work) -> Self;

    /// Where the sample at `t` lies (`t` after the previous sample's); `acc` says which
    /// cells add nothing (a sample there needs no parametric coordinates).
    fn locate(&mut self, t: f64, acc: &impl Accumulate, work: &mut Work) -> Next;

    /// The sample at `t` was outside the mesh (and the loop is done with it): where the ray
    /// may next enter the mesh, from the proved exit or the boundary surface.
    fn passed_outside(&mut self, t: f64, proved: Option<ProvedExit>, work: &mut Work);

    /// A sample in a cell that adds nothing: where the next sample that may add something
    /// lies, from `t_next` (the next sample's `t`) on, where the locator can jump there —
    /// the samples before it lie in cells that add nothing or outside the mesh; `None` where
    /// it samples on.
    fn jump(&mut self, t_next: f64, acc: &impl Accumulate, work: &mut Work) -> Option<f64>;

    /// The cell holding the middle of `chord` (a piece of the ray in the mesh that holds no
    /// sample), if any.
    fn locate_chord(&mut self, chord: &Chord, work: &mut Work) -> Option<(u32, DVec3)>;

    /// Whether the ray is known to be outside the mesh from the last position up to `t`.
    fn outside_through(&self, t: f64) -> bool;
}
