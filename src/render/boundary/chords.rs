//! Pieces of a ray inside the mesh that hold no sample: what the mesh-boundary crossings
//! between two consecutive positions of a ray mean for compositing.
//!
//! Samples lie a step apart, so a piece of the ray inside the mesh shorter than a step may
//! hold none: a ray grazing the mesh's silhouette, crossing a thin plate or a coarse mesh's
//! corner, or the fluid between two blades at a long step. Without a sample such a *chord* is
//! not seen at all (a single opaque cell at half its size for a step lost a fifth of its
//! pixels). Likewise a *gap* shorter than a step (the ray leaving the mesh through a thin
//! blade and coming back) would be counted as mesh. Where the boundary surface gives every
//! crossing between two positions exactly
//! ([`super::surface::BoundarySurface::crossings_between`]), [`classify`] sorts them: the
//! first is the exit of the earlier position's sample where that one is in the mesh, the last
//! the entry of the later one's, and every pair between bounds a chord, which the ray caster
//! samples once at its middle for its own length (the midpoint rule, as for every sample).
//!
//! The ends' sides must agree with the parity of the crossings; where an end's side is
//! unknown (the ray's start with the camera in the mesh, its end on a clipping plane, a
//! sample position jumped over) the parity tells it. Anything inconsistent gives `None`, and
//! the ray caster keeps to its samples there.

use super::surface::MAX_CROSSINGS;
use crate::render::ray::End;

/// A piece of the ray in the mesh, from `start` to `end`, that holds no sample; `cell` is the
/// cell of a boundary face at one of its ends, near which it lies (a start for locating its
/// middle), `u32::MAX` where neither end is on the boundary.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(crate) struct Chord {
    /// Where the piece starts.
    pub(crate) start: f64,
    /// Where it ends.
    pub(crate) end: f64,
    /// The cell of a boundary face at one of its ends (`u32::MAX`: none).
    pub(crate) cell: u32,
}

impl Chord {
    /// Its middle, where it is sampled.
    pub(crate) fn middle(&self) -> f64 {
        0.5 * (self.start + self.end)
    }

    /// Its length.
    pub(crate) fn length(&self) -> f64 {
        self.end - self.start
    }
}

/// The most chords between two positions: every pair of crossings, and a piece at each end.
pub(crate) const MAX_CHORDS: usize = MAX_CROSSINGS / 2 + 2;

/// The crossings between two positions of a ray, sorted by what they mean ([`classify`]).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(crate) struct Between {
    /// Where the earlier position's sample (an [`End::Sample`]) leaves the mesh.
    pub(crate) exit: Option<f64>,
    /// Where the later position's sample (an [`End::Sample`]) enters it.
    pub(crate) entry: Option<f64>,
    chords: [Chord; MAX_CHORDS],
    n: usize,
}

impl Between {
    /// The chords, front to back.
    pub(crate) fn chords(&self) -> &[Chord] {
        &self.chords[..self.n]
    }

    fn push(&mut self, chord: Chord) -> Option<()> {
        *self.chords.get_mut(self.n)? = chord;
        self.n += 1;
        Some(())
    }
}

/// Sorts `crossings` (the `t` and face cell of every boundary crossing strictly between the
/// positions `a` and `b` of the ray, `a.0 < b.0`, in increasing order) by what they mean for
/// the ends `a.1` and `b.1` (see the module documentation); `None` where the crossings and
/// what is known of the ends disagree, or neither end's side is known (the caller locates
/// one first: [`side_unknown`]).
pub(crate) fn classify(crossings: &[(f64, u32)], a: (f64, End), b: (f64, End)) -> Option<Between> {
    let odd = crossings.len() % 2 == 1;
    let inside = |e: End| match e {
        End::Sample | End::In => Some(true),
        End::Outside => Some(false),
        End::Unknown | End::Passed => None,
    };
    let (in_a, in_b) = match (inside(a.1), inside(b.1)) {
        (Some(x), Some(y)) if (x != y) == odd => (x, y),
        (Some(x), None) => (x, x != odd),
        (None, Some(y)) => (y != odd, y),
        _ => return None,
    };
    // A position passed over is a sample where it is in the mesh.
    let settle = |e: End, inside: bool| match e {
        End::Passed if inside => End::Sample,
        e => e,
    };
    let (a, b) = ((a.0, settle(a.1, in_a)), (b.0, settle(b.1, in_b)));
    let mut out = Between::default();
    let sample = |e: End| e == End::Sample;
    if crossings.is_empty() && in_a && !sample(a.1) && !sample(b.1) {
        // In the mesh from end to end, and no sample: one chord, near no face known.
        out.push(Chord {
            start: a.0,
            end: b.0,
            cell: u32::MAX,
        })?;
        return Some(out);
    }
    let (mut lo, mut hi) = (0, crossings.len());
    if in_a {
        if let Some(&(t, cell)) = crossings.first() {
            lo = 1;
            match a.1 {
                End::Sample => out.exit = Some(t),
                _ => out.push(Chord {
                    start: a.0,
                    end: t,
                    cell,
                })?,
            }
        }
    }
    let mut trail = None;
    if in_b && hi > lo {
        let (t, cell) = crossings[hi - 1];
        hi -= 1;
        match b.1 {
            End::Sample => out.entry = Some(t),
            _ => {
                trail = Some(Chord {
                    start: t,
                    end: b.0,
                    cell,
                })
            }
        }
    }
    // The parity makes the crossings left between the ends' come in pairs.
    debug_assert_eq!(hi.saturating_sub(lo) % 2, 0);
    for pair in crossings.get(lo..hi)?.chunks_exact(2) {
        out.push(Chord {
            start: pair[0].0,
            end: pair[1].0,
            cell: pair[0].1,
        })?;
    }
    if let Some(c) = trail {
        out.push(c)?;
    }
    Some(out)
}

/// Whether neither end's side is known, so that [`classify`] needs one found first.
pub(crate) fn side_unknown(a: End, b: End) -> bool {
    let unknown = |e: End| matches!(e, End::Unknown | End::Passed);
    unknown(a) && unknown(b)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_chord_between_two_positions_outside_and_a_gap_between_two_samples() {
        // Between two positions outside, the ray enters at 1.2 and leaves at 1.5: one chord.
        let b = classify(
            &[(1.2, 7), (1.5, 8)],
            (1.0, End::Outside),
            (2.0, End::Outside),
        )
        .unwrap();
        let chord = Chord {
            start: 1.2,
            end: 1.5,
            cell: 7,
        };
        assert_eq!(b.chords(), &[chord]);
        assert_eq!((b.exit, b.entry), (None, None));
        // Between two samples in the mesh, it leaves at 1.2 and comes back at 1.5: a gap.
        let b = classify(
            &[(1.2, 7), (1.5, 8)],
            (1.0, End::Sample),
            (2.0, End::Sample),
        )
        .unwrap();
        assert_eq!(
            (b.exit, b.entry, b.chords().len()),
            (Some(1.2), Some(1.5), 0)
        );
        // An odd number of crossings cannot join two positions outside.
        assert!(classify(&[(1.2, 7)], (1.0, End::Outside), (2.0, End::Outside)).is_none());
    }

    const A: f64 = 0.0;
    const B: f64 = 10.0;

    fn xs(ts: &[f64]) -> Vec<(f64, u32)> {
        ts.iter().enumerate().map(|(i, &t)| (t, i as u32)).collect()
    }

    fn spans(b: &Between) -> Vec<(f64, f64)> {
        b.chords().iter().map(|c| (c.start, c.end)).collect()
    }

    /// Every in-mesh stretch between the two positions is accounted for once: as the end of
    /// a sample's segment (exit, entry) or as a chord; what is outside is in none.
    #[test]
    fn every_stretch_in_the_mesh_is_a_sample_end_or_a_chord() {
        let ends = [
            End::Sample,
            End::Outside,
            End::In,
            End::Unknown,
            End::Passed,
        ];
        for n in 0..=6usize {
            let ts: Vec<f64> = (1..=n).map(|i| i as f64).collect();
            for ea in ends {
                for eb in ends {
                    let got = classify(&xs(&ts), (A, ea), (B, eb));
                    // The sides by parity where one end is known.
                    let known = |e: End| match e {
                        End::Sample | End::In => Some(true),
                        End::Outside => Some(false),
                        _ => None,
                    };
                    let side_a = match (known(ea), known(eb)) {
                        (Some(x), Some(y)) => ((x != y) == (n % 2 == 1)).then_some(x),
                        (Some(x), None) => Some(x),
                        (None, Some(y)) => Some(y != (n % 2 == 1)),
                        (None, None) => None,
                    };
                    let consistent = side_a;
                    let (Some(in_a), Some(got)) = (consistent, got) else {
                        assert!(
                            consistent.is_none() && got.is_none(),
                            "{n} {ea:?} {eb:?}: {got:?}"
                        );
                        continue;
                    };
                    // The stretches in the mesh: from each crossing's side.
                    let mut bounds = vec![A];
                    bounds.extend(&ts);
                    bounds.push(B);
                    let inside: Vec<(f64, f64)> = bounds
                        .windows(2)
                        .enumerate()
                        .filter(|(i, _)| (i % 2 == 0) == in_a)
                        .map(|(_, w)| (w[0], w[1]))
                        .collect();
                    // A stretch at a sample's end is that sample's (cut at the crossing
                    // where there is one; a position passed over in the mesh is a sample);
                    // every other one is a chord.
                    let is_sample = |e: End| matches!(e, End::Sample | End::Passed);
                    let mut chords = Vec::new();
                    let (mut exit, mut entry) = (None, None);
                    for &(s, e) in &inside {
                        let at_a = s == A && is_sample(ea);
                        let at_b = e == B && is_sample(eb);
                        if at_a && e < B {
                            exit = Some(e);
                        }
                        if at_b && s > A {
                            entry = Some(s);
                        }
                        if !at_a && !at_b {
                            chords.push((s, e));
                        }
                    }
                    assert_eq!(spans(&got), chords, "{n} {ea:?} {eb:?}: {got:?}");
                    assert_eq!((got.exit, got.entry), (exit, entry), "{n} {ea:?} {eb:?}");
                }
            }
        }
    }

    #[test]
    fn a_sample_with_no_crossing_keeps_its_whole_segment() {
        let b = classify(&[], (A, End::Sample), (B, End::Sample)).unwrap();
        assert_eq!(b, Between::default());
        let b = classify(&[], (A, End::Unknown), (B, End::Sample)).unwrap();
        assert_eq!(b, Between::default());
    }

    #[test]
    fn a_chord_starts_near_the_face_it_enters_by() {
        let b = classify(&[(2.0, 5), (3.0, 9)], (A, End::Outside), (B, End::Outside)).unwrap();
        assert_eq!(b.chords()[0].cell, 5);
        assert_eq!(b.chords()[0].middle(), 2.5);
        assert_eq!(b.chords()[0].length(), 1.0);
        // A piece from an unknown end in the mesh lies by the face it leaves through.
        let b = classify(&[(2.0, 5)], (A, End::Unknown), (B, End::Outside)).unwrap();
        assert_eq!(
            b.chords(),
            &[Chord {
                start: A,
                end: 2.0,
                cell: 5
            }]
        );
        let b = classify(&[(2.0, 5)], (A, End::Outside), (B, End::Unknown)).unwrap();
        assert_eq!(
            b.chords(),
            &[Chord {
                start: 2.0,
                end: B,
                cell: 5
            }]
        );
    }

    #[test]
    fn too_many_chords_for_the_room_are_refused_not_dropped() {
        let ts: Vec<f64> = (1..=2 * MAX_CHORDS + 2).map(|i| i as f64).collect();
        assert!(classify(&xs(&ts), (A, End::Outside), (B * 10.0, End::Outside)).is_none());
    }
}
