//! The march of a ray from cell to cell through its exit faces: the fast path's location of
//! the samples along a ray, and the estimates and exact crossings of the mesh's boundary that
//! follow the ray across the cells.
//!
//! A ray inside the mesh crosses a sequence of face-adjacent cells. Rather than asking, for
//! every sample, which face plane of the previous sample's cell the sample lies beyond (a
//! point walk, see [`super::walk`]), the march follows the ray itself: each cell is entered
//! once, and the ray's exit from it is computed from its face planes (each face approximated
//! by the plane through its centroid normal to the cross product of its diagonals, oriented
//! away from the cell's centroid) as the smallest `t` at which the ray crosses a plane it is
//! heading out of. Every sample with `t` up to that exit is proposed to that cell, and the
//! march moves across the exit face to the neighbour only when a sample lies beyond it. One
//! plane evaluation per cell crossed, none per sample, and no square root or per-face
//! division: the face planes need not be normalised to compare the ray's crossings.
//!
//! Like the walk, the march only *proposes* cells: the proposed cell must hold the sample by
//! the inverse map's containment test, the same test the structure uses. Where it does not
//! (a face far from planar, a twisted cell), the walk takes over from there, and where the
//! march leaves through a face without a neighbour, or runs out of its budget, the caller
//! locates the sample another way. The answer is therefore exact whatever the planes say.

use glam::{DVec3, Vec3A};

use super::point::{test_cell, walk, WalkEnd, WalkWork};
use super::{Across, Cells};
use crate::accel::prefetch;
use crate::geometry::bounds::Aabb;
use crate::geometry::containment::{certainly_inside, param_inside, reject_box};
use crate::geometry::inverse::PreparedCell;
use crate::geometry::patch::segment_crossings;
use crate::mesh::topology::{FaceKey, FACES};
use crate::render::ray::Ray;
use crate::Mesh;

/// Cells a march may cross between two samples before it gives up.
pub(crate) const MAX_MARCH_STEPS: u32 = 64;

/// Where a ray leaves a cell by its face planes: the face (0–5, in [`FACES`] order) and the
/// ray parameter `t` of the crossing, for the ray `o + t d`. `None` when the ray heads out of
/// no face plane (a degenerate cell, or non-finite input).
///
/// The planes are evaluated in `f32`, measured from corner 0 of the cell and from the point
/// of the ray nearest it, so that every quantity is of the cell's size: the crossing is found
/// to about `1e-7` of the cell's size wherever the cell lies (a proposal, which the inverse
/// map then verifies).
#[inline]
pub(crate) fn exit_face(corners: &[DVec3; 8], o: DVec3, d: DVec3) -> Option<(usize, f64)> {
    exit_face_except(corners, o, d, usize::MAX)
}

/// [`exit_face`] with the face `entry` (0–5; any other value for none) left out: the face
/// the ray entered the cell through, whose plane it crosses inwards (or, grazing it, at no
/// distance, which would send the march back where it came from).
#[inline]
pub(crate) fn exit_face_except(
    corners: &[DVec3; 8],
    o: DVec3,
    d: DVec3,
    entry: usize,
) -> Option<(usize, f64)> {
    let (t_ref, planes) = face_planes(corners, o, d)?;
    // The smallest num/den over faces with den > 0, compared without dividing.
    let mut best: Option<(usize, f32, f32)> = None;
    for (f, &(num, den)) in planes.iter().enumerate() {
        if f == entry || !(den > 0.0 && den.is_finite()) || !num.is_finite() {
            continue;
        }
        if best.map_or(true, |(_, bn, bd)| num * bd < bn * den) {
            best = Some((f, num, den));
        }
    }
    best.map(|(f, num, den)| (f, t_ref + f64::from(num / den)))
}

/// Where the ray `o + t d` enters and leaves a cell by its face planes: the entry `t` (the
/// largest crossing of a plane it heads into the cell by; `-inf` where there is none) with
/// [`exit_face`]'s answer, from one evaluation of the planes. `None` where `exit_face` gives
/// none.
#[inline]
pub(crate) fn entry_and_exit(
    corners: &[DVec3; 8],
    o: DVec3,
    d: DVec3,
) -> Option<(f64, (usize, f64))> {
    let (t_ref, planes) = face_planes(corners, o, d)?;
    let mut exit: Option<(usize, f32, f32)> = None;
    let mut entry: Option<(f32, f32)> = None;
    for (f, &(num, den)) in planes.iter().enumerate() {
        if !(den.is_finite() && num.is_finite()) {
            continue;
        }
        if den > 0.0 {
            if exit.map_or(true, |(_, bn, bd)| num * bd < bn * den) {
                exit = Some((f, num, den));
            }
        } else if den < 0.0 {
            // The largest num/den over den < 0: with both denominators negative the
            // comparison of cross products flips once for each, so it keeps its sense.
            if entry.map_or(true, |(bn, bd)| num * bd > bn * den) {
                entry = Some((num, den));
            }
        }
    }
    let (f, num, den) = exit?;
    let entry = entry.map_or(f64::NEG_INFINITY, |(n, d)| t_ref + f64::from(n / d));
    Some((entry, (f, t_ref + f64::from(num / den))))
}

/// The six face planes of a cell for the ray `o + t d`, as [`face_plane`] gives them, with
/// the ray parameter `t_ref` their crossings are measured from (`t = t_ref + num / den`);
/// `None` for a zero or non-finite direction.
#[inline(always)]
fn face_planes(corners: &[DVec3; 8], o: DVec3, d: DVec3) -> Option<(f64, [(f32, f32); 6])> {
    let x0 = corners[0];
    let dd = d.length_squared();
    if !(dd > 0.0 && dd.is_finite()) {
        return None;
    }
    let t_ref = (x0 - o).dot(d) / dd;
    let r = (o + d * t_ref - x0).as_vec3a();
    let dir = d.as_vec3a();
    // Rebased corners written out: `relative_corners(corners).map(..)` (two array maps)
    // makes the whole call about a third slower.
    let rel = [
        Vec3A::ZERO,
        (corners[1] - x0).as_vec3a(),
        (corners[2] - x0).as_vec3a(),
        (corners[3] - x0).as_vec3a(),
        (corners[4] - x0).as_vec3a(),
        (corners[5] - x0).as_vec3a(),
        (corners[6] - x0).as_vec3a(),
        (corners[7] - x0).as_vec3a(),
    ];
    let centre = (rel[1] + rel[2] + rel[3] + rel[4] + rel[5] + rel[6] + rel[7]) * 0.125;
    // The six planes written out (a loop over the faces is not unrolled, and indexes the
    // corners through the face table at run time: about 12 % slower).
    let plane = |f: usize| face_plane(&rel, FACES[f], centre, r, dir);
    Some((
        t_ref,
        [plane(0), plane(1), plane(2), plane(3), plane(4), plane(5)],
    ))
}

/// The plane of a face (its corners' slots in `rel`, the corners relative to corner 0) for
/// [`exit_face_except`]: `(num, den)` such that the ray `r + s dir` crosses it at
/// `s = num / den`, heading out of the cell where `den > 0`. The plane passes through the
/// face's centroid, normal to the cross product of its diagonals, oriented away from the
/// cell's `centre`.
#[inline(always)]
fn face_plane(
    rel: &[Vec3A; 8],
    slots: [usize; 4],
    centre: Vec3A,
    r: Vec3A,
    dir: Vec3A,
) -> (f32, f32) {
    let [a, b, c, e] = slots.map(|s| rel[s]);
    let n = (c - a).cross(e - b);
    let mid = (a + b + c + e) * 0.25;
    let (num, den) = (n.dot(mid - r), n.dot(dir));
    if n.dot(centre - mid) > 0.0 {
        (-num, -den)
    } else {
        (num, den)
    }
}

/// A ray's march through the mesh: the current cell, where the ray leaves it, and the cell
/// prepared for the inverse map once a sample has been tested in it (the next samples in the
/// same cell reuse it).
#[derive(Clone, Debug)]
pub(crate) struct March {
    cell: u32,
    /// The current cell's corners (gathered once per cell crossed).
    corners: [DVec3; 8],
    /// The exit face and its `t`; `None` when the cell has no exit by its planes.
    exit: Option<(usize, f64)>,
    /// The `t` of the sample by which the march was [`March::place`]d in `cell` without
    /// gathering it (the corners and exit still the previous cell's); NaN once gathered.
    placed_at: f64,
    /// The ray's typical chord in the cells it met so far (their lengths along it by their
    /// planes, each new cell's taking half the weight); NaN before any.
    chord: f64,
    solver: Solver,
}

/// The current cell prepared for containment tests: its reject box and inverse map.
#[derive(Clone, Debug, Default)]
struct Solver {
    /// The cell's id (`u32::MAX` before any).
    id: u32,
    /// Whether the cell could be prepared (else the plain test is used).
    ready: bool,
    reject: Aabb,
    cell: PreparedCell,
}

impl Solver {
    /// [`test_cell`] with the preparation done.
    fn test(&self, p: DVec3, guess: Option<DVec3>) -> Result<DVec3, Option<DVec3>> {
        if !self.reject.contains(p) {
            return Err(None);
        }
        match self.cell.locate(p, guess).param() {
            Some(q) if param_inside(q) => Ok(q),
            other => Err(other),
        }
    }
}

impl Default for March {
    fn default() -> March {
        March::new()
    }
}

impl March {
    /// A march in no cell yet: [`March::move_to`] puts it in one (a ray's march is made once
    /// and moved, so that its prepared cell is never copied).
    pub(crate) fn new() -> March {
        March {
            cell: u32::MAX,
            corners: [DVec3::ZERO; 8],
            exit: None,
            chord: f64::NAN,
            placed_at: f64::NAN,
            solver: Solver {
                id: u32::MAX,
                ..Solver::default()
            },
        }
    }

    /// Moves the march to `cell` (in place: the prepared cell, if any, stays until a sample
    /// is tested in another cell).
    pub(crate) fn move_to(&mut self, mesh: &Mesh, cell: u32, ray: &Ray) {
        self.cell = cell;
        self.exit = None;
        self.placed_at = f64::NAN;
        if (cell as usize) < mesh.cell_count() {
            mesh.cell_corners_into(cell as usize, &mut self.corners);
            if let Some((entry, exit)) = entry_and_exit(&self.corners, ray.origin, ray.dir) {
                self.exit = Some(exit);
                self.observe_chord(exit.1 - entry);
            }
        }
    }

    /// Puts the march in `cell`, where the sample at `t` was found by other means (a
    /// structure look-up), without gathering the cell: until the next [`March::locate`]
    /// gathers it, [`March::cells_ahead`] estimates from `t` and the ray's typical chord, so a
    /// run of samples located far ahead gathers no cell for the march.
    pub(crate) fn place(&mut self, cell: u32, t: f64) {
        self.cell = cell;
        self.exit = None;
        self.placed_at = t;
    }

    /// Takes a cell's chord into the ray's typical one (non-positive or non-finite chords,
    /// of degenerate cells, are left out).
    fn observe_chord(&mut self, chord: f64) {
        if chord > 0.0 && chord.is_finite() {
            self.chord = if self.chord.is_nan() {
                chord
            } else {
                0.5 * (self.chord + chord)
            };
        }
    }

    /// Moves the march to `cell`, entered through its face `entry` (none if not 0–5).
    fn enter(&mut self, mesh: &Mesh, cell: u32, entry: usize, ray: &Ray) {
        let entered_at = self.exit.map_or(f64::NAN, |(_, t)| t);
        self.cell = cell;
        self.exit = if (cell as usize) < mesh.cell_count() {
            mesh.cell_corners_into(cell as usize, &mut self.corners);
            exit_face_except(&self.corners, ray.origin, ray.dir, entry)
        } else {
            None
        };
        if let Some((_, t_exit)) = self.exit {
            self.observe_chord(t_exit - entered_at);
        }
    }

    /// The current cell.
    pub(crate) fn cell(&self) -> u32 {
        self.cell
    }

    /// The face (0–5) by whose plane the ray leaves the current cell, if any.
    pub(crate) fn exit_face(&self) -> Option<usize> {
        self.exit.map(|(f, _)| f)
    }

    /// About how many cells the march would cross to reach the sample at `t` on the ray it
    /// is marching along: none while `t` is in the current cell by its planes, else the
    /// distance past the current cell's exit measured in the ray's typical chord, plus one for
    /// the cell the exit leads into. The typical chord follows the cells met so far (each
    /// cell's length along the ray by its planes, from where the march crossed into it or,
    /// for a cell it was moved to, from the planes' entry; each new cell's taking half the
    /// weight), so that one cell grazed at a corner does not stand for the cells ahead. An
    /// estimate for choosing between marching and a structure look-up; zero before any cell
    /// with a positive chord, or in a cell with no exit, so that those keep marching. Where
    /// the march was [`March::place`]d by a sample, its distance from that sample in typical
    /// chords, plus a half.
    pub(crate) fn cells_ahead(&self, t: f64) -> f64 {
        if !self.placed_at.is_nan() {
            // Placed by a sample, half a chord from the exit on average.
            return if t > self.placed_at && self.chord > 0.0 {
                0.5 + (t - self.placed_at) / self.chord
            } else {
                0.0
            };
        }
        match self.exit {
            Some((_, t_exit)) if t > t_exit && self.chord > 0.0 => 1.0 + (t - t_exit) / self.chord,
            _ => 0.0,
        }
    }

    /// Locates the sample `p = o + t d` (`t` not before the march's previous sample): marches
    /// across exit faces to the cell the ray is in at `t` by the planes, and tests it (Newton
    /// warm-started at `guess` when the cell is `guess`'s). Where the test fails, the walk
    /// goes on from that cell; the march then restarts in the cell found. A cell for which
    /// `no_parameters` holds (the caller needs no parametric coordinates there: a transparent
    /// cell) is first tried by its face planes alone
    /// ([`crate::geometry::containment::certainly_inside`]), and where they settle it the
    /// answer is [`WalkEnd::Certified`], with no inverse map.
    pub(crate) fn locate(
        &mut self,
        cells: &Cells,
        ray: &Ray,
        t: f64,
        guess: Option<(u32, DVec3)>,
        no_parameters: impl Fn(u32) -> bool,
        work: &mut WalkWork,
    ) -> WalkEnd {
        let mesh = cells.mesh;
        if !self.placed_at.is_nan() {
            self.move_to(mesh, self.cell, ray);
        }
        let n_cells = mesh.cell_count();
        let p = ray.at(t);
        let mut steps = 0u32;
        while let Some((face, t_exit)) = self.exit {
            if t <= t_exit {
                break;
            }
            if steps >= MAX_MARCH_STEPS {
                return WalkEnd::GaveUp;
            }
            let Across::Cell(n) = cells.across(self.cell, face) else {
                return WalkEnd::Boundary;
            };
            steps += 1;
            work.plane_steps += 1;
            let around = cells.neighbours.neighbours(n);
            let entry = entry_face(&around, self.cell);
            // The next cell is one of these: start loading them all while this one is solved.
            for (f, &m) in around.iter().enumerate() {
                if f != entry && (m as usize) < n_cells {
                    prefetch(&mesh.cells()[m as usize]);
                    cells.neighbours.prefetch(m);
                }
            }
            self.enter(mesh, n, entry, ray);
        }
        if self.cell as usize >= n_cells {
            return WalkEnd::GaveUp;
        }
        if no_parameters(self.cell) && certainly_inside(&self.corners, p) {
            work.certified += 1;
            return WalkEnd::Certified(self.cell);
        }
        let start_guess = guess.filter(|g| g.0 == self.cell).map(|g| g.1);
        work.tests += 1;
        if self.solver.id != self.cell {
            self.solver.id = self.cell;
            self.solver.ready = self.solver.cell.prepare(&self.corners).is_ok();
            self.solver.reject = reject_box(&self.corners);
        }
        let tested = if self.solver.ready {
            self.solver.test(p, start_guess)
        } else {
            test_cell(&self.corners, p, start_guess)
        };
        match tested {
            Ok(q) => WalkEnd::Found(self.cell, q),
            Err(_) => {
                let end = walk(cells, self.cell, start_guess, p, work);
                if let WalkEnd::Found(c, _) = end {
                    if c != self.cell {
                        self.move_to(mesh, c, ray);
                    }
                }
                end
            }
        }
    }
}

/// The face (0–5) of a cell whose neighbours are `around` across which `from` lies,
/// `usize::MAX` if none: the face a ray crossing from `from` into the cell enters by.
fn entry_face(around: &[u32; 6], from: u32) -> usize {
    around.iter().position(|&m| m == from).unwrap_or(usize::MAX)
}

/// Where the ray `o + t d` leaves the mesh by the face planes, marching from `cell` (which
/// holds the ray at `t_from`) towards `t_to`, backwards along the ray when `t_to < t_from`:
/// the `t` at which it crosses the plane of the first face without a neighbour, if that lies
/// between `t_from` and `t_to` and is reached within [`MAX_MARCH_STEPS`] cells. An estimate
/// of a boundary crossing, exact for planar faces; callers verify it.
pub(crate) fn boundary_plane_crossing(
    cells: &Cells,
    cell: u32,
    ray: &Ray,
    t_from: f64,
    t_to: f64,
) -> Option<f64> {
    let (o, d) = (ray.origin, ray.dir);
    let (dir, sign) = if t_to >= t_from { (d, 1.0) } else { (-d, -1.0) };
    let n_cells = cells.mesh.cell_count();
    let mut c = cell;
    for _ in 0..MAX_MARCH_STEPS {
        if c as usize >= n_cells {
            return None;
        }
        let (face, s) = exit_face(&cells.mesh.cell_corners(c as usize), o, dir)?;
        let t = sign * s;
        if (t - t_from) * sign > (t_to - t_from) * sign {
            return None;
        }
        match cells.across(c, face) {
            Across::Boundary => return ((t - t_from) * sign >= 0.0).then_some(t),
            Across::Invalid => return None,
            Across::Cell(n) => c = n,
        }
    }
    None
}

/// Where the ray `o + t d` leaves the mesh, exactly, walking from `cell` (which holds the ray
/// at `t_from`) towards `t_to` (backwards along the ray when `t_to < t_from`): in each cell,
/// the first crossing of one of its faces (bilinear patches, the trilinear map's own faces,
/// [`segment_crossings`]) after the point the ray entered it by, the face it entered by left
/// out. Across a face with a neighbour the walk goes on; the first face without one is where
/// the ray leaves the mesh. Faces of fewer than three distinct points (no area) are never
/// crossed. `None` where a crossing cannot be told robustly (near a face's edge or a cell's
/// corner, a grazing ray), where the ray reaches `t_to` inside the mesh, or after
/// [`MAX_MARCH_STEPS`] cells. The answer means what it says only where every face without a
/// neighbour bounds the mesh ([`super::Neighbours::complete`]).
pub(crate) fn boundary_face_crossing(
    cells: &Cells,
    cell: u32,
    ray: &Ray,
    t_from: f64,
    t_to: f64,
) -> Option<f64> {
    let (o, d) = (ray.origin, ray.dir);
    let mesh = cells.mesh;
    // Along s = ±t, so that the walk always goes towards larger s.
    let (dir, sign) = if t_to >= t_from { (d, 1.0) } else { (-d, -1.0) };
    let s_to = sign * t_to;
    let (mut c, mut s_from, mut entry) = (cell, sign * t_from, usize::MAX);
    for _ in 0..MAX_MARCH_STEPS {
        let ids = *mesh.cells().get(c as usize)?;
        let corners = mesh.cell_corners(c as usize);
        let mut first: Option<(f64, usize)> = None;
        for (f, slots) in FACES.iter().enumerate() {
            if f == entry {
                continue;
            }
            if FaceKey::of_cell(&ids, f).is_degenerate() {
                continue;
            }
            let crossings =
                segment_crossings(&slots.map(|k| corners[k]), o, dir, s_from, s_to, 0.0)?;
            if let Some(&s) = crossings.ts().first() {
                if first.map_or(true, |(b, _)| s < b) {
                    first = Some((s, f));
                }
            }
        }
        let (s, f) = first?;
        let n = match cells.across(c, f) {
            Across::Boundary => return Some(sign * s),
            Across::Invalid => return None,
            Across::Cell(n) => n,
        };
        entry = entry_face(&cells.neighbours.neighbours(n), c);
        c = n;
        s_from = s;
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::trilinear::CORNER_PARAMETERS;
    use crate::{CellKind, MeshParts};

    /// The cells of `mesh` with the neighbours `nb`.
    fn row_cells<'a>(mesh: &'a Mesh, nb: &'a impl super::super::Neighbours) -> Cells<'a> {
        Cells {
            mesh,
            neighbours: nb,
        }
    }

    /// The unit cube as a mesh of one cell.
    fn unit_cube() -> Mesh {
        Mesh::from_parts(MeshParts {
            points: CORNER_PARAMETERS.map(DVec3::from_array).to_vec(),
            cells: vec![[0, 1, 2, 3, 4, 5, 6, 7]],
            kinds: vec![CellKind::Hexahedron],
            ..Default::default()
        })
        .unwrap()
    }

    #[test]
    fn exit_entry_and_exit_of_a_ray_through_the_cube() {
        let cube = CORNER_PARAMETERS.map(DVec3::from_array);
        let (face, t) = exit_face(&cube, DVec3::new(-1.0, 0.5, 0.5), DVec3::X).unwrap();
        assert_eq!(face, 1); // u = 1
        assert!((t - 2.0).abs() < 1e-6);
        let (entry, (face, exit)) =
            entry_and_exit(&cube, DVec3::new(-1.0, 0.5, 0.5), DVec3::X).unwrap();
        assert!((entry - 1.0).abs() < 1e-6 && (exit - 2.0).abs() < 1e-6);
        assert_eq!(face, 1);
        // Entered through u = 0 (face 0) on the plane itself, heading along the face.
        let (o, d) = (DVec3::new(0.0, 0.5, 0.5), DVec3::new(-1e-9, 1.0, 0.0));
        assert_eq!(exit_face(&cube, o, d).unwrap().0, 0);
        assert_eq!(exit_face_except(&cube, o, d, 0).unwrap().0, 3); // v = 1
    }

    #[test]
    fn exact_exit_of_one_cube_along_a_slanted_ray() {
        let mesh = unit_cube();
        let none = |_: u32| [u32::MAX; 6];
        let cells = row_cells(&mesh, &none);
        let ray = Ray::line(DVec3::splat(0.5), DVec3::new(1.0, 0.3, -0.2));
        // Out through x = 1 at t = 0.5, backwards through x = 0; not before t_to.
        let t = boundary_face_crossing(&cells, 0, &ray, 0.0, 2.0).unwrap();
        assert!((t - 0.5).abs() < 1e-12);
        let t = boundary_face_crossing(&cells, 0, &ray, 0.0, -2.0).unwrap();
        assert!((t + 0.5).abs() < 1e-12);
        assert_eq!(boundary_face_crossing(&cells, 0, &ray, 0.0, 0.4), None);
    }

    #[test]
    fn exit_of_the_unit_cube_along_each_axis() {
        let cube = CORNER_PARAMETERS.map(DVec3::from_array);
        let centre = DVec3::splat(0.5);
        let close = |got: Option<(usize, f64)>, face: usize, t: f64| {
            let (f, tt) = got.unwrap();
            assert_eq!(f, face);
            assert!((tt - t).abs() < 1e-6, "{tt} vs {t}");
        };
        for (axis, (lo, hi)) in [(DVec3::X, (0, 1)), (DVec3::Y, (2, 3)), (DVec3::Z, (4, 5))] {
            close(exit_face(&cube, centre, axis), hi, 0.5);
            close(exit_face(&cube, centre, -axis), lo, 0.5);
        }
        // A diagonal ray leaves through the face it reaches first; a longer direction scales t.
        close(exit_face(&cube, centre, DVec3::new(1.0, 0.5, 0.0)), 1, 0.5);
        close(exit_face(&cube, centre, DVec3::new(2.0, 1.0, 0.0)), 1, 0.25);
        // Non-finite or zero directions have no exit.
        assert_eq!(exit_face(&cube, centre, DVec3::ZERO), None);
        assert_eq!(
            exit_face(&cube, centre, DVec3::new(f64::NAN, 0.0, 1.0)),
            None
        );
    }

    #[test]
    fn the_entry_face_is_left_out() {
        let cube = CORNER_PARAMETERS.map(DVec3::from_array);
        let o = DVec3::new(0.5, 0.5, 0.5);
        // Heading out through u = 1 (face 1): leaving that face out leaves no exit ahead, and
        // leaving out a face the ray does not head out of changes nothing.
        assert_eq!(exit_face(&cube, o, DVec3::X).unwrap().0, 1);
        assert_eq!(exit_face_except(&cube, o, DVec3::X, 1), None);
        assert_eq!(
            exit_face_except(&cube, o, DVec3::X, 0),
            exit_face(&cube, o, DVec3::X)
        );
        // A ray grazing the face it came in by (its plane crossed at no distance ahead) goes
        // on to the face it really leaves by.
        let o = DVec3::new(0.0, 0.5, 0.5);
        let d = DVec3::new(1e-9, 1.0, 0.0);
        assert_eq!(exit_face(&cube, o, -d).unwrap().0, 0);
        let (f, t) = exit_face_except(&cube, o, -d, 0).unwrap();
        assert_eq!(f, 2);
        assert!((t - 0.5).abs() < 1e-6, "{t}");
    }

    #[test]
    fn boundary_crossing_of_a_row_of_cubes() {
        // Three unit cubes along x: the ray along x leaves the row at x = 3 forwards and at
        // x = 0 backwards, whichever cube it starts in.
        let mut points = Vec::new();
        for i in 0..4 {
            for (y, z) in [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)] {
                points.push([i as f64, y, z]);
            }
        }
        let cells: Vec<[u32; 8]> = (0..3u32)
            .map(|i| {
                let a = 4 * i;
                let b = a + 4;
                [a, b, b + 1, a + 1, a + 3, b + 3, b + 2, a + 2]
            })
            .collect();
        let mesh = Mesh::from_parts(MeshParts {
            points: points.into_iter().map(DVec3::from_array).collect(),
            kinds: vec![CellKind::Hexahedron; cells.len()],
            cells,
            ..Default::default()
        })
        .unwrap();
        let nb = |c: u32| -> [u32; 6] {
            let left = if c == 0 { u32::MAX } else { c - 1 };
            let right = if c == 2 { u32::MAX } else { c + 1 };
            [left, right, u32::MAX, u32::MAX, u32::MAX, u32::MAX]
        };
        let o = DVec3::new(-1.0, 0.5, 0.5);
        let (cells, ray) = (row_cells(&mesh, &nb), Ray::line(o, DVec3::X));
        for start in 0..3 {
            let t_from = 1.5 + start as f64;
            let fwd = boundary_plane_crossing(&cells, start, &ray, t_from, 10.0);
            assert!((fwd.unwrap() - 4.0).abs() < 1e-12, "{start}: {fwd:?}");
            let back = boundary_plane_crossing(&cells, start, &ray, t_from, 0.0);
            assert!((back.unwrap() - 1.0).abs() < 1e-12, "{start}: {back:?}");
            // Not within the bracket.
            assert_eq!(
                boundary_plane_crossing(&cells, start, &ray, t_from, 3.9),
                None
            );
        }
    }

    #[test]
    fn exact_boundary_crossing_lies_on_a_twisted_end_face() {
        use crate::geometry::inverse::invert;
        // Three cubes along x; the far end face (x = 3) twisted: one corner pushed out by 0.4.
        let mut points = Vec::new();
        for i in 0..4 {
            for (y, z) in [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)] {
                let x = if i == 3 && (y, z) == (1.0, 1.0) {
                    3.4
                } else {
                    i as f64
                };
                points.push(DVec3::new(x, y, z));
            }
        }
        let cells: Vec<[u32; 8]> = (0..3u32)
            .map(|i| {
                let a = 4 * i;
                let b = a + 4;
                [a, b, b + 1, a + 1, a + 3, b + 3, b + 2, a + 2]
            })
            .collect();
        let mesh = Mesh::from_parts(MeshParts {
            points,
            kinds: vec![CellKind::Hexahedron; cells.len()],
            cells,
            ..Default::default()
        })
        .unwrap();
        let nb = |c: u32| -> [u32; 6] {
            let left = if c == 0 { u32::MAX } else { c - 1 };
            let right = if c == 2 { u32::MAX } else { c + 1 };
            [left, right, u32::MAX, u32::MAX, u32::MAX, u32::MAX]
        };
        let o = DVec3::new(0.5, 0.3, 0.4);
        let d = DVec3::new(1.0, 0.17, 0.11).normalize();
        let (cells, ray) = (row_cells(&mesh, &nb), Ray::line(o, d));
        let t = boundary_face_crossing(&cells, 0, &ray, 0.0, 10.0).unwrap();
        // On the last cell's face u = 1, inside its edges: the trilinear map's own face.
        let q = invert(&mesh.cell_corners(2), o + d * t, None)
            .param()
            .unwrap();
        assert!((q.x - 1.0).abs() < 1e-12, "{q}");
        assert!(q.y > 0.0 && q.y < 1.0 && q.z > 0.0 && q.z < 1.0, "{q}");
        // The planes' estimate is off the twisted face; the exact crossing is not.
        let planes = boundary_plane_crossing(&cells, 0, &ray, 0.0, 10.0).unwrap();
        assert!((planes - t).abs() > 1e-3, "{planes} vs {t}");
        // Backwards from the last cell, out through x = 0.
        let back = boundary_face_crossing(&cells, 2, &ray, 2.5, -10.0).unwrap();
        assert!((o + d * back).x.abs() < 1e-12, "{back}");
    }

    #[test]
    fn exit_is_independent_of_orientation_and_far_origins() {
        let cube = CORNER_PARAMETERS.map(DVec3::from_array);
        let mirrored = cube.map(|c| DVec3::new(-c.x, c.y, c.z));
        let (f, t) = exit_face(&mirrored, DVec3::new(-0.5, 0.5, 0.5), -DVec3::X).unwrap();
        assert_eq!(f, 1);
        assert!((t - 0.5).abs() < 1e-6);
        // A small cell a million units away, seen from far off: the crossing to the cell's
        // precision, not to the origin's.
        let shift = DVec3::splat(1e6);
        let small = cube.map(|c| c * 1e-3 + shift);
        let o = shift + DVec3::new(-5e2, 0.5e-3, 0.5e-3);
        let (f, t) = exit_face(&small, o, DVec3::X).unwrap();
        assert_eq!(f, 1);
        assert!((t - (5e2 + 1e-3)).abs() < 1e-9, "{t}");
    }

    proptest::proptest! {
        /// One evaluation of the planes gives both ends: the exit is [`exit_face`]'s and the
        /// entry is the exit backwards along the ray, for sheared and stretched cells and any
        /// ray through them.
        #[test]
        fn entry_and_exit_are_the_exits_both_ways(
            shear in proptest::array::uniform3(-0.4f64..0.4),
            scale in proptest::array::uniform3(0.05f64..20.0),
            inside in proptest::array::uniform3(0.1f64..0.9),
            dir in proptest::array::uniform3(-1.0f64..1.0),
        ) {
            let cell = CORNER_PARAMETERS.map(|c| {
                let p = DVec3::from_array(c);
                DVec3::new(p.x + shear[0] * p.y, p.y + shear[1] * p.z, p.z + shear[2] * p.x)
                    * DVec3::from_array(scale)
            });
            let p = DVec3::from_array(inside);
            let o = DVec3::new(p.x + shear[0] * p.y, p.y + shear[1] * p.z, p.z + shear[2] * p.x)
                * DVec3::from_array(scale);
            let d = DVec3::from_array(dir);
            proptest::prop_assume!(d.length() > 0.1);
            let (entry, exit) = entry_and_exit(&cell, o, d).expect("a ray from inside leaves");
            proptest::prop_assert_eq!(Some(exit), exit_face(&cell, o, d));
            let (_, back) = exit_face(&cell, o, -d).expect("and leaves backwards");
            let size = DVec3::from_array(scale).max_element() / d.length();
            proptest::prop_assert!((entry + back).abs() <= 1e-6 * size, "{entry} vs {back}");
            proptest::prop_assert!(entry < 0.0 && exit.1 > 0.0);
        }
    }

    #[test]
    fn cells_ahead_follows_the_ray_s_typical_chord() {
        // A row of unit cubes along x, crossed along x from x = -1: chords of 1.
        let (o, d) = (DVec3::new(-1.0, 0.5, 0.5), DVec3::X);
        let cube = CORNER_PARAMETERS.map(DVec3::from_array);
        let row: Vec<[DVec3; 8]> = (0..4)
            .map(|i| cube.map(|c| c + DVec3::X * i as f64))
            .collect();
        let mut points = Vec::new();
        let mut cells = Vec::new();
        for c in &row {
            let base = points.len() as u32;
            points.extend_from_slice(c);
            cells.push(std::array::from_fn(|k| base + k as u32));
        }
        let mesh = Mesh::from_parts(MeshParts {
            kinds: vec![CellKind::Hexahedron; cells.len()],
            cells,
            points,
            ..Default::default()
        })
        .unwrap();
        let mut march = March::new();
        assert_eq!(march.cells_ahead(10.0), 0.0, "no chord before any cell");
        march.move_to(&mesh, 0, &Ray::line(o, d));
        // In the cell (exit at t = 2): none ahead; 3.5 is in the second cell past the exit.
        assert_eq!(march.cells_ahead(1.5), 0.0);
        assert!((march.cells_ahead(3.5) - 2.5).abs() < 1e-6);
        // Placed by a sample at t = 2.5 (in cell 1), without gathering it: half a chord plus
        // the distance in chords.
        march.place(1, 2.5);
        assert_eq!(march.cell(), 1);
        assert!((march.cells_ahead(4.5) - 2.5).abs() < 1e-6);
        assert_eq!(march.cells_ahead(2.0), 0.0);
    }
}
