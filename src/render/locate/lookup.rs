//! The `paper` path's locator: every sample located from scratch through the structure.

use glam::DVec3;

use super::{Locate, Next};
use crate::render::accumulate::Accumulate;
use crate::render::boundary::chords::Chord;
use crate::render::boundary::proof::ProvedExit;
use crate::render::frame::Frame;
use crate::render::ray::Ray;
use crate::render::stats::Work;

/// Locates every sample through the structure ([`crate::accel::Accel::locate`]). With no
/// march to tell it that a sample's neighbour lies across the boundary, it asks the boundary
/// surface's bound whether the ray may have crossed it between two samples in the mesh.
pub(crate) struct SampleLookup<'f> {
    frame: &'f Frame<'f>,
    ray: &'f Ray<'f>,
    /// The previous sample's `t`, where it was in the mesh.
    previous_inside: Option<f64>,
}

impl<'f> Locate<'f> for SampleLookup<'f> {
    fn start(frame: &'f Frame<'f>, ray: &'f Ray<'f>, _hint: Option<u32>, _: &mut Work) -> Self {
        SampleLookup {
            frame,
            ray,
            previous_inside: None,
        }
    }

    fn locate(&mut self, t: f64, _acc: &impl Accumulate, work: &mut Work) -> Next {
        let volume = self.frame.volume;
        let found = volume
            .accel()
            .locate(volume.mesh(), self.ray.at(t), &mut work.counters);
        let previous = std::mem::replace(&mut self.previous_inside, found.map(|_| t));
        match found {
            Some((cell, param)) => Next::Inside {
                cell,
                param,
                crossed: previous
                    .is_some_and(|tp| self.frame.boundary.may_cross(self.ray, tp, t, work)),
            },
            None => Next::Outside(None),
        }
    }

    fn passed_outside(&mut self, _t: f64, _proved: Option<ProvedExit>, _work: &mut Work) {}

    fn jump(&mut self, _t_next: f64, _acc: &impl Accumulate, _work: &mut Work) -> Option<f64> {
        None
    }

    fn locate_chord(&mut self, chord: &Chord, work: &mut Work) -> Option<(u32, DVec3)> {
        let volume = self.frame.volume;
        let p = self.ray.at(chord.middle());
        volume.accel().locate(volume.mesh(), p, &mut work.counters)
    }

    fn outside_through(&self, _t: f64) -> bool {
        false
    }
}
