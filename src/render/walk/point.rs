//! The walk of a point through face neighbours: the fast path's location of a point near a
//! known cell.
//!
//! From the cell of the previous sample, the next sample is first sought by a *visibility
//! walk* over the cells' face planes — no inverse map: each face of a cell is approximated by
//! the plane through its centroid normal to the cross product of its diagonals (oriented
//! away from the cell's centroid), and the walk steps across the face whose plane the point
//! lies farthest beyond, until it reaches a cell with the point behind all its face planes.
//! That cell gets one inverse-map test. Where a face is not planar (twisted cells) the test
//! may fail; its parametric coordinates then name the face the point lies beyond (the largest
//! violation of `[0, 1]³`), and the walk continues there with tests. A walk that reaches the
//! mesh boundary, or runs out of its budget, hands the sample back to the structure.
//!
//! The walk only *proposes* cells: a cell is accepted only by the inverse map's containment
//! test, the same test the structure's location uses, so a walk never yields a point outside
//! its cell; where it gives up, the structure's answer is exact.

use glam::DVec3;

use super::{Across, Cells};
use crate::geometry::containment::{param_inside, reject_box};
use crate::geometry::inverse::invert;
use crate::mesh::topology::FACES;

/// Cells a walk may cross by face planes before it gives up.
pub(crate) const MAX_PLANE_STEPS: u32 = 64;
/// Plane steps of a walk from a hint (the previous ray's first cell) to a ray's entry: such a
/// walk usually succeeds within a few cells or not at all (the entry lies across a gap of the
/// mesh), when the structure answers.
pub(crate) const MAX_ENTRY_PLANE_STEPS: u32 = 16;
/// Inverse-map tests a walk may make before it gives up.
pub(crate) const MAX_WALK_TESTS: u32 = 4;

/// How a walk ended.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum WalkEnd {
    /// The point lies in this cell, at these parametric coordinates.
    Found(u32, DVec3),
    /// The point lies in this cell, certified by its face planes alone
    /// ([`crate::geometry::containment::certainly_inside`]), with no parametric coordinates:
    /// the march asks only for cells the caller does not need them in (transparent ones).
    Certified(u32),
    /// The point lies beyond a boundary face (no neighbour) of the mesh, by its face plane.
    Boundary,
    /// The walk gave up (budget spent, a non-finite value, a reject-box miss).
    GaveUp,
}

/// The work of one walk.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub(crate) struct WalkWork {
    /// Inverse-map containment tests.
    pub(crate) tests: u64,
    /// Cells stepped across by face planes (no inverse map).
    pub(crate) plane_steps: u64,
    /// Points found inside a cell by its face planes alone ([`WalkEnd::Certified`]).
    pub(crate) certified: u64,
}

/// The face (0–5, in [`FACES`] order) whose plane `p` lies farthest beyond, with that signed
/// distance (negative when `p` is behind every face plane); degenerate faces are ignored.
#[inline]
pub(crate) fn farthest_face(corners: &[DVec3; 8], p: DVec3) -> (usize, f64) {
    let x0 = corners[0];
    let rel = corners.map(|c| c - x0);
    let q = p - x0;
    let centre = rel.iter().fold(DVec3::ZERO, |a, &c| a + c) * 0.125;
    let mut best = (0usize, f64::NEG_INFINITY);
    for (f, slots) in FACES.iter().enumerate() {
        let [a, b, c, d] = slots.map(|s| rel[s]);
        let n = (c - a).cross(d - b);
        let len = n.length();
        if len.is_nan() || len <= 0.0 {
            continue;
        }
        let mid = (a + b + c + d) * 0.25;
        let mut dist = n.dot(q - mid) / len;
        if n.dot(centre - mid) > 0.0 {
            dist = -dist;
        }
        if dist > best.1 {
            best = (f, dist);
        }
    }
    best
}

/// The face (0–5) whose parametric bound `param` violates most: `u < 0` is face 0, `u > 1`
/// face 1, `v < 0` face 2, `v > 1` face 3, `w < 0` face 4, `w > 1` face 5.
#[inline]
pub(crate) fn violated_face(param: DVec3) -> usize {
    let v = [
        -param.x,
        param.x - 1.0,
        -param.y,
        param.y - 1.0,
        -param.z,
        param.z - 1.0,
    ];
    let mut best = 0;
    for f in 1..6 {
        if v[f] > v[best] {
            best = f;
        }
    }
    best
}

/// The containment test of [`crate::geometry::containment::locate_in_cell`], but returning the
/// parametric coordinates also when they lie outside the cell (`Err(Some(q))`), so a walk can
/// see which face the point lies beyond; `Err(None)` when the reject box misses or the inverse
/// fails.
#[inline]
pub(crate) fn test_cell(
    corners: &[DVec3; 8],
    p: DVec3,
    guess: Option<DVec3>,
) -> Result<DVec3, Option<DVec3>> {
    if !reject_box(corners).contains(p) {
        return Err(None);
    }
    match invert(corners, p, guess).param() {
        Some(q) if param_inside(q) => Ok(q),
        other => Err(other),
    }
}

/// Walks from `start` (the previous sample's cell, `guess` its parametric coordinates there,
/// used to warm-start Newton if the walk tests that cell) to the cell holding `p`, with at
/// most [`MAX_PLANE_STEPS`] plane steps.
pub(crate) fn walk(
    cells: &Cells,
    start: u32,
    guess: Option<DVec3>,
    p: DVec3,
    work: &mut WalkWork,
) -> WalkEnd {
    walk_within(cells, start, guess, p, MAX_PLANE_STEPS, work)
}

/// [`walk`] with at most `max_plane_steps` plane steps.
pub(crate) fn walk_within(
    cells: &Cells,
    start: u32,
    guess: Option<DVec3>,
    p: DVec3,
    max_plane_steps: u32,
    work: &mut WalkWork,
) -> WalkEnd {
    let n_cells = cells.mesh.cell_count();
    let mut cell = start;
    let mut guess = guess;
    let mut steps = 0u32;
    let mut tests = 0u32;
    // After a failed test moved the walk, test the next cell at once (no plane phase), so the
    // planes and the parameters cannot send the walk back and forth.
    let mut test_now = false;
    loop {
        if cell as usize >= n_cells {
            return WalkEnd::GaveUp;
        }
        let corners = cells.mesh.cell_corners(cell as usize);
        if !test_now {
            let (f, dist) = farthest_face(&corners, p);
            if dist.is_nan() {
                return WalkEnd::GaveUp;
            }
            if dist > 0.0 {
                if steps >= max_plane_steps {
                    return WalkEnd::GaveUp;
                }
                let Across::Cell(n) = cells.across(cell, f) else {
                    return WalkEnd::Boundary;
                };
                steps += 1;
                work.plane_steps += 1;
                cell = n;
                guess = None;
                continue;
            }
        }
        if tests >= MAX_WALK_TESTS {
            return WalkEnd::GaveUp;
        }
        tests += 1;
        work.tests += 1;
        match test_cell(&corners, p, guess) {
            Ok(q) => return WalkEnd::Found(cell, q),
            Err(Some(q)) => {
                let Across::Cell(n) = cells.across(cell, violated_face(q)) else {
                    return WalkEnd::GaveUp;
                };
                cell = n;
                guess = None;
                test_now = true;
            }
            Err(None) => return WalkEnd::GaveUp,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::trilinear::CORNER_PARAMETERS;

    #[test]
    fn farthest_face_of_the_unit_cube() {
        let cube = CORNER_PARAMETERS.map(DVec3::from_array);
        let (f, d) = farthest_face(&cube, DVec3::new(1.5, 0.5, 0.6));
        assert_eq!((f, d), (1, 0.5));
        let (f, d) = farthest_face(&cube, DVec3::new(0.5, 0.5, -0.25));
        assert_eq!((f, d), (4, 0.25));
        let (_, d) = farthest_face(&cube, DVec3::splat(0.5));
        assert!(d < 0.0);
        // A mirrored (left-handed) cell is oriented by its centroid, not by vertex order.
        let mirrored = cube.map(|c| DVec3::new(-c.x, c.y, c.z));
        let (f, d) = farthest_face(&mirrored, DVec3::new(-1.5, 0.5, 0.5));
        assert_eq!((f, d), (1, 0.5));
    }

    #[test]
    fn violated_face_names_the_largest_violation() {
        assert_eq!(violated_face(DVec3::new(1.2, 0.5, -0.1)), 1);
        assert_eq!(violated_face(DVec3::new(0.5, -0.3, 1.1)), 2);
        assert_eq!(violated_face(DVec3::new(0.5, 0.5, 1.1)), 5);
    }
}
