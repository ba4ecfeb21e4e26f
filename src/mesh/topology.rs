//! Face adjacency of a mesh: for every face of every (collapsed) hexahedron, the cell on the
//! other side. The ray caster's fast path uses it to walk from one sample's cell to the next
//! through shared faces before it falls back to an acceleration structure.
//!
//! **Face order.** The six faces of a stored cell are VTK's hexahedron faces, in VTK's order,
//! each with VTK's vertex list (outward normals by the right-hand rule):
//!
//! | face | where | hexahedron slots ([`face_vertices`]) |
//! |---|---|---|
//! | 0 | u = 0 | `[0, 4, 7, 3]` |
//! | 1 | u = 1 | `[1, 2, 6, 5]` |
//! | 2 | v = 0 | `[0, 1, 5, 4]` |
//! | 3 | v = 1 | `[3, 7, 6, 2]` |
//! | 4 | w = 0 | `[0, 3, 2, 1]` |
//! | 5 | w = 1 | `[4, 5, 6, 7]` |
//!
//! **Keys.** A face is identified by the sorted set of its *distinct* point ids: four for a quad
//! face, three for a triangle face (a quad collapsed along one edge: the triangles of wedges,
//! pyramids and tetrahedra stored as collapsed hexahedra, see [`crate::CellKind`]). A face with
//! two or fewer distinct points (a collapsed edge or point, such as a wedge's `v = 1` face or a
//! pyramid's apex face) is *degenerate*: it bounds no area and never has a neighbour. Two faces
//! are neighbours when their keys are equal and they belong to two different cells, so a
//! triangle never matches a quad even when it shares three of its points.
//!
//! **Non-manifold faces.** When a key is carried by more than two faces (three cells on one
//! face, or two faces of one cell), none of them gets a neighbour; they are counted by
//! [`FaceNeighbours::nonmanifold_faces`]. Faces whose key occurs once are the boundary
//! ([`FaceNeighbours::boundary_face_count`]).
//!
//! **Duplicated seams.** Meshes whose seam points are duplicated (an O-grid whose first and last
//! circumferential planes coincide, like the LOX post) are not stitched by point ids: both
//! sides of the seam are boundary. [`FaceNeighbours::build_with_tolerance`] adds a second pass
//! over the boundary faces only: it welds their points that lie within a distance `tolerance`
//! of each other (each point, in increasing id order, joins a representative within
//! `tolerance` found in a hash grid, or becomes a representative itself: the result is
//! deterministic), keys the faces by their sorted distinct representatives
//! and pairs the keys carried by exactly two faces of two different cells, both ways. Those
//! pairs are *seam faces* ([`FaceNeighbours::is_seam`], [`FaceNeighbours::seam_faces`]); they do
//! not share point ids, only positions.
//!
//! **Algorithm and cost.** Faces are bucketed by their smallest point id (a counting sort of
//! cell ids into one bucket per point, computed in parallel), then each bucket is sorted by the
//! rest of the key and equal keys are paired. Nothing bigger than the result is allocated: the
//! result is 6 `u32` per cell (24 bytes); the temporary buckets hold a cell id and a face mask
//! (5 bytes) per bucket a cell enters (at most 6; 4 on the pump datasets: a cell
//! enters a point's bucket once however many of its faces start there), plus 12 bytes per
//! point. The result is the same for any thread count. On `pump-rotor` (2.1 M hexahedra) a
//! build costs about 0.4 s of CPU time, summed over threads (the tolerance pass adds 0.13 s);
//! a `HashMap` from face key to face took 23 times as much, one parallel sort of all faces
//! 3.7 times (`benches/topology.rs` has both).
//!
//! ```
//! use cylvol::mesh::topology::{FaceNeighbours, NONE};
//! use cylvol::{CellKind, Mesh, MeshParts};
//! use glam::DVec3;
//!
//! // Two unit cubes side by side in x: cell 0's u = 1 face is cell 1's u = 0 face.
//! let points = (0..12)
//!     .map(|n| DVec3::new((n % 3) as f64, ((n / 3) % 2) as f64, (n / 6) as f64))
//!     .collect();
//! let cells = vec![[0, 1, 4, 3, 6, 7, 10, 9], [1, 2, 5, 4, 7, 8, 11, 10]];
//! let mesh = Mesh::from_parts(MeshParts {
//!     points,
//!     cells,
//!     kinds: vec![CellKind::Hexahedron; 2],
//!     ..MeshParts::default()
//! })
//! .unwrap();
//! let adjacency = FaceNeighbours::build(&mesh);
//! assert_eq!(adjacency.neighbours(0), [NONE, 1, NONE, NONE, NONE, NONE]);
//! assert_eq!(adjacency.neighbour(1, 0), Some(0));
//! assert_eq!(adjacency.boundary_face_count(), 10);
//! ```

use std::collections::HashMap;
use std::sync::atomic::{AtomicU32, AtomicU8, Ordering};

use rayon::prelude::*;

use super::Mesh;

/// The raw value of "no neighbour" in [`FaceNeighbours::neighbours`] and [`FaceNeighbours::raw`].
pub const NONE: u32 = u32::MAX;

/// A temporary marker for faces whose key is shared by too many faces; [`NONE`] in the result.
const NONMANIFOLD: u32 = u32::MAX - 1;

/// The hexahedron slots of each face, in VTK's hexahedron face order (see the module docs).
pub const FACES: [[usize; 4]; 6] = [
    [0, 4, 7, 3],
    [1, 2, 6, 5],
    [0, 1, 5, 4],
    [3, 7, 6, 2],
    [0, 3, 2, 1],
    [4, 5, 6, 7],
];

/// The twelve edges of a hexahedron as pairs of its slots (0–7, VTK order), by parametric
/// direction: the four along `u`, the four along `v`, then the four along `w`.
pub const EDGES: [[usize; 2]; 12] = [
    [0, 1],
    [3, 2],
    [4, 5],
    [7, 6],
    [0, 3],
    [1, 2],
    [4, 7],
    [5, 6],
    [0, 4],
    [1, 5],
    [2, 6],
    [3, 7],
];

/// The four hexahedron slots (0–7, VTK order) of face `face` (0–5, VTK's face order:
/// u = 0, u = 1, v = 0, v = 1, w = 0, w = 1). Faces beyond 5 wrap around (`face % 6`).
///
/// ```
/// assert_eq!(cylvol::mesh::topology::face_vertices(5), [4, 5, 6, 7]);
/// ```
pub fn face_vertices(face: usize) -> [usize; 4] {
    FACES[face % 6]
}

/// The key of a face: its distinct point ids in increasing order, padded with `u32::MAX`, and
/// how many there are (0 to 4; below 3 the face is degenerate).
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct FaceKey {
    /// Number of distinct points (3: triangle, 4: quad, fewer: degenerate).
    pub distinct: u8,
    /// The distinct point ids, increasing, padded with `u32::MAX`.
    pub ids: [u32; 4],
}

impl FaceKey {
    /// The key of the four point ids of a face, in any order.
    ///
    /// ```
    /// use cylvol::mesh::topology::FaceKey;
    /// let key = FaceKey::new([9, 4, 4, 7]);
    /// assert_eq!((key.distinct, key.ids), (3, [4, 7, 9, u32::MAX]));
    /// ```
    #[inline]
    pub fn new(ids: [u32; 4]) -> FaceKey {
        let [mut a, mut b, mut c, mut d] = ids;
        // A five-comparator sorting network for four values.
        if a > b {
            std::mem::swap(&mut a, &mut b);
        }
        if c > d {
            std::mem::swap(&mut c, &mut d);
        }
        if a > c {
            std::mem::swap(&mut a, &mut c);
        }
        if b > d {
            std::mem::swap(&mut b, &mut d);
        }
        if b > c {
            std::mem::swap(&mut b, &mut c);
        }
        let sorted = [a, b, c, d];
        let mut out = [u32::MAX; 4];
        let mut n = 0usize;
        for (i, &v) in sorted.iter().enumerate() {
            if i == 0 || v != sorted[i - 1] {
                out[n] = v;
                n += 1;
            }
        }
        FaceKey {
            distinct: n as u8,
            ids: out,
        }
    }

    /// The key of face `face` (0–5) of a stored cell.
    #[inline]
    pub fn of_cell(cell: &[u32; 8], face: usize) -> FaceKey {
        let s = face_vertices(face);
        FaceKey::new([cell[s[0]], cell[s[1]], cell[s[2]], cell[s[3]]])
    }

    /// True when the face bounds no area (two or fewer distinct points): it never has a
    /// neighbour.
    #[inline]
    pub fn is_degenerate(&self) -> bool {
        self.distinct < 3
    }
}

/// The face adjacency of a mesh: six neighbours per cell (see the module docs for the face
/// order, how faces are matched, and what has no neighbour).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct FaceNeighbours {
    /// `6 × cells` entries: the neighbour of face `f` of cell `c` at `6c + f`, or [`NONE`].
    neighbours: Vec<u32>,
    /// Seam faces matched by position, as `6c + f`, increasing.
    seams: Vec<u64>,
    boundary: usize,
    nonmanifold: usize,
    degenerate: usize,
    /// Faces without a neighbour found to have mesh beyond them by
    /// [`FaceNeighbours::check_boundary`]; `None` until it has run.
    hanging: Option<usize>,
}

/// Counts gathered while building.
#[derive(Clone, Copy, Default)]
struct Counts {
    boundary: usize,
    nonmanifold: usize,
    degenerate: usize,
}

impl std::ops::Add for Counts {
    type Output = Counts;
    fn add(self, o: Counts) -> Counts {
        Counts {
            boundary: self.boundary + o.boundary,
            nonmanifold: self.nonmanifold + o.nonmanifold,
            degenerate: self.degenerate + o.degenerate,
        }
    }
}

/// One face while a bucket is paired: the key, then the cell and face (the sort order makes the
/// pairing independent of the order cells arrived in the bucket).
type Entry = (FaceKey, u32, u8);

/// Points at which [`FaceNeighbours::check_boundary`] probes each face without a neighbour:
/// its centre and the four points halfway from there to its corners.
pub const BOUNDARY_PROBES: usize = 5;

impl FaceNeighbours {
    /// Matches faces by their point ids (see the module docs). Meshes of `u32::MAX` cells or
    /// more, which `u32` cell ids cannot address, get an empty table: every face reads as none.
    pub fn build(mesh: &Mesh) -> FaceNeighbours {
        let cells = mesh.cells();
        let n_points = mesh.point_count();
        if cells.len() >= NONE as usize || n_points == 0 {
            return FaceNeighbours {
                neighbours: Vec::new(),
                seams: Vec::new(),
                boundary: 0,
                nonmanifold: 0,
                degenerate: 0,
                hanging: None,
            };
        }

        // The distinct smallest points of a cell's non-degenerate faces (the buckets it
        // enters), each with the mask of the faces that start there.
        let starts = |cell: &[u32; 8]| -> ([(u32, u8); 6], usize, usize) {
            let mut mins = [(0u32, 0u8); 6];
            let mut n = 0;
            let mut degenerate = 0;
            for f in 0..6 {
                let key = FaceKey::of_cell(cell, f);
                if key.is_degenerate() {
                    degenerate += 1;
                } else if let Some(m) = mins[..n].iter_mut().find(|m| m.0 == key.ids[0]) {
                    m.1 |= 1 << f;
                } else {
                    mins[n] = (key.ids[0], 1 << f);
                    n += 1;
                }
            }
            (mins, n, degenerate)
        };

        // 1. Bucket sizes.
        let counts: Vec<AtomicU32> = (0..n_points).map(|_| AtomicU32::new(0)).collect();
        let degenerate: usize = cells
            .par_iter()
            .with_min_len(4096)
            .map(|cell| {
                let (mins, n, degenerate) = starts(cell);
                for &(m, _) in &mins[..n] {
                    counts[m as usize].fetch_add(1, Ordering::Relaxed);
                }
                degenerate
            })
            .sum();
        let mut offsets = Vec::with_capacity(n_points + 1);
        let mut total = 0usize;
        offsets.push(0);
        for c in &counts {
            total += c.load(Ordering::Relaxed) as usize;
            offsets.push(total);
            c.store(0, Ordering::Relaxed);
        }
        let cursor = counts;

        // 2. Scatter cell ids and face masks into their buckets (the order within a bucket
        // depends on scheduling; pairing sorts it out).
        let slots: Vec<AtomicU32> = (0..total).map(|_| AtomicU32::new(0)).collect();
        let masks: Vec<AtomicU8> = (0..total).map(|_| AtomicU8::new(0)).collect();
        cells
            .par_iter()
            .enumerate()
            .with_min_len(4096)
            .for_each(|(c, cell)| {
                let (mins, n, _) = starts(cell);
                for &(m, mask) in &mins[..n] {
                    let m = m as usize;
                    let at = offsets[m] + cursor[m].fetch_add(1, Ordering::Relaxed) as usize;
                    slots[at].store(c as u32, Ordering::Relaxed);
                    masks[at].store(mask, Ordering::Relaxed);
                }
            });
        drop(cursor);

        // 3. Pair equal keys within each bucket.
        let neighbours: Vec<AtomicU32> = (0..cells.len() * 6)
            .into_par_iter()
            .map(|_| AtomicU32::new(NONE))
            .collect();
        let counts = (0..n_points)
            .into_par_iter()
            .with_min_len(1024)
            .map_init(Vec::<Entry>::new, |entries, v| {
                entries.clear();
                let range = offsets[v]..offsets[v + 1];
                for (slot, mask) in slots[range.clone()].iter().zip(&masks[range]) {
                    let c = slot.load(Ordering::Relaxed);
                    let mask = mask.load(Ordering::Relaxed);
                    let cell = &cells[c as usize];
                    for f in 0..6 {
                        if mask & (1 << f) != 0 {
                            entries.push((FaceKey::of_cell(cell, f), c, f as u8));
                        }
                    }
                }
                pair_runs(entries, &neighbours)
            })
            .reduce(Counts::default, |a, b| a + b);
        drop(masks);
        drop(slots);

        FaceNeighbours {
            neighbours: finish(neighbours),
            seams: Vec::new(),
            boundary: counts.boundary,
            nonmanifold: counts.nonmanifold,
            degenerate,
            hanging: None,
        }
    }

    /// [`FaceNeighbours::build`], then a second pass that pairs the remaining boundary faces
    /// whose points coincide within `tolerance` (a distance in the mesh's units), so walks cross
    /// seams whose points are duplicated. See the module docs for how points are welded. A
    /// `tolerance` that is not finite and positive skips the second pass. A tolerance of about
    /// `1e-9` times the mesh's bounding-box diagonal ([`FaceNeighbours::seam_tolerance`]) joins
    /// points that are duplicated bit for bit or up to rounding, and nothing else.
    ///
    /// Faces that are boundary for a reason (two walls that touch, the two sides of a
    /// zero-thickness baffle) are joined as well when their points coincide: a walk may then
    /// cross them, which is still correct for locating samples, as both cells are real volume.
    pub fn build_with_tolerance(mesh: &Mesh, tolerance: f64) -> FaceNeighbours {
        let mut result = FaceNeighbours::build(mesh);
        if !(tolerance.is_finite() && tolerance > 0.0) || result.neighbours.is_empty() {
            return result;
        }
        let cells = mesh.cells();
        let points = mesh.points();

        // Boundary faces: no neighbour, not degenerate, not non-manifold. The non-manifold
        // faces were turned into NONE already, so recognise them again by key multiplicity:
        // they are rare, and a boundary face's id key is unique among all faces.
        let open: Vec<(u32, u8)> = result
            .neighbours
            .par_chunks(6)
            .enumerate()
            .flat_map_iter(|(c, nb)| {
                let cell = &cells[c];
                (0..6usize).filter_map(move |f| {
                    (nb[f] == NONE && !FaceKey::of_cell(cell, f).is_degenerate())
                        .then_some((c as u32, f as u8))
                })
            })
            .collect();
        if open.len() < 2 {
            return result;
        }
        // Non-manifold faces share their id key with another open face: leave them out.
        let mut by_id: Vec<(FaceKey, u32, u8)> = open
            .iter()
            .map(|&(c, f)| (FaceKey::of_cell(&cells[c as usize], f as usize), c, f))
            .collect();
        by_id.par_sort_unstable();
        let mut boundary: Vec<(u32, u8)> = Vec::with_capacity(by_id.len());
        for run in by_id.chunk_by(|a, b| a.0 == b.0) {
            if run.len() == 1 {
                boundary.push((run[0].1, run[0].2));
            }
        }

        // Weld the boundary faces' points.
        let mut ids: Vec<u32> = boundary
            .iter()
            .flat_map(|&(c, f)| face_vertices(f as usize).map(|s| cells[c as usize][s]))
            .collect();
        ids.par_sort_unstable();
        ids.dedup();
        let weld = weld_points(&ids, points, tolerance);
        let rep = |p: u32| -> u32 {
            ids.binary_search(&p)
                .ok()
                .and_then(|i| weld.get(i).copied())
                .unwrap_or(p)
        };

        // Key the boundary faces by welded points and pair.
        let mut entries: Vec<Entry> = boundary
            .par_iter()
            .filter_map(|&(c, f)| {
                let cell = &cells[c as usize];
                let s = face_vertices(f as usize);
                let key = FaceKey::new([
                    rep(cell[s[0]]),
                    rep(cell[s[1]]),
                    rep(cell[s[2]]),
                    rep(cell[s[3]]),
                ]);
                (!key.is_degenerate()).then_some((key, c, f))
            })
            .collect();
        entries.par_sort_unstable();
        let mut seams = Vec::new();
        for run in entries.chunk_by(|a, b| a.0 == b.0) {
            if let [(_, ca, fa), (_, cb, fb)] = run {
                if ca != cb {
                    let ia = *ca as usize * 6 + *fa as usize;
                    let ib = *cb as usize * 6 + *fb as usize;
                    result.neighbours[ia] = *cb;
                    result.neighbours[ib] = *ca;
                    seams.push(ia as u64);
                    seams.push(ib as u64);
                }
            }
        }
        seams.sort_unstable();
        seams.shrink_to_fit();
        result.boundary -= seams.len();
        result.seams = seams;
        result
    }

    /// A welding tolerance for [`FaceNeighbours::build_with_tolerance`]: `1e-9` times the
    /// diagonal of the mesh's bounding box (points that coincide up to rounding, for a mesh of
    /// any size and placement).
    pub fn seam_tolerance(mesh: &Mesh) -> f64 {
        let b = mesh.bounds();
        let d = glam::DVec3::new(b[1] - b[0], b[3] - b[2], b[5] - b[4]).length();
        let scale = glam::DVec3::new(b[0], b[2], b[4])
            .abs()
            .max(glam::DVec3::new(b[1], b[3], b[5]).abs())
            .max_element();
        // Never below what f64 can resolve at the mesh's coordinates.
        (1e-9 * d).max(scale * 1e-13).max(f64::MIN_POSITIVE)
    }

    /// The six neighbours of `cell`, in face order (see the module docs); [`NONE`] where a face
    /// has none (boundary, degenerate or non-manifold). A `cell` out of range has none at all.
    #[inline]
    pub fn neighbours(&self, cell: u32) -> [u32; 6] {
        let at = cell as usize * 6;
        match self.neighbours.get(at..at + 6) {
            Some(s) => [s[0], s[1], s[2], s[3], s[4], s[5]],
            None => [NONE; 6],
        }
    }

    /// The neighbour across face `face` (0–5) of `cell`, if any.
    #[inline]
    pub fn neighbour(&self, cell: u32, face: usize) -> Option<u32> {
        if face >= 6 {
            return None;
        }
        self.neighbours
            .get(cell as usize * 6 + face)
            .copied()
            .filter(|&n| n != NONE)
    }

    /// All neighbours: face `f` of cell `c` at `6c + f`, [`NONE`] where none.
    pub fn raw(&self) -> &[u32] {
        &self.neighbours
    }

    /// Number of cells covered (the mesh's cell count, or 0 for a mesh too large to index).
    pub fn cell_count(&self) -> usize {
        self.neighbours.len() / 6
    }

    /// Non-degenerate faces that have no neighbour and share their key with no other face: the
    /// mesh's boundary (less the seam faces a tolerance pass joined).
    pub fn boundary_face_count(&self) -> usize {
        self.boundary
    }

    /// Faces left without a neighbour because their key is carried by more than two faces, or
    /// by two faces of the same cell.
    pub fn nonmanifold_faces(&self) -> usize {
        self.nonmanifold
    }

    /// Faces with two or fewer distinct points (collapsed edges and points of wedges, pyramids,
    /// tetrahedra and axis cells); they never have a neighbour.
    pub fn degenerate_face_count(&self) -> usize {
        self.degenerate
    }

    /// Faces joined by position rather than by point ids (both sides of each seam pair are
    /// counted; 0 after [`FaceNeighbours::build`]).
    pub fn seam_faces(&self) -> usize {
        self.seams.len()
    }

    /// True when face `face` of `cell` was joined by position (see
    /// [`FaceNeighbours::build_with_tolerance`]).
    pub fn is_seam(&self, cell: u32, face: usize) -> bool {
        face < 6
            && self
                .seams
                .binary_search(&(cell as u64 * 6 + face as u64))
                .is_ok()
    }

    /// Joins each pair of faces `[(cell, face), (cell, face)]` (faces 0–5) that have no
    /// neighbour yet, both ways: the faces a rotationally periodic wheel makes interior (a
    /// sector's start side with its end side, [`crate::axis::periodic::side_pairs`]). Pairs
    /// out of range, of faces that have a neighbour, or of a face with itself are left alone.
    /// Returns how many pairs were joined.
    pub fn join(&mut self, pairs: &[[(u32, u8); 2]]) -> usize {
        let mut joined = 0;
        for &[(ca, fa), (cb, fb)] in pairs {
            let (a, b) = (ca as usize * 6 + fa as usize, cb as usize * 6 + fb as usize);
            let free = |i: usize| self.neighbours.get(i) == Some(&NONE);
            if fa >= 6 || fb >= 6 || a == b || !free(a) || !free(b) {
                continue;
            }
            self.neighbours[a] = cb;
            self.neighbours[b] = ca;
            self.boundary = self.boundary.saturating_sub(2);
            joined += 1;
        }
        joined
    }

    /// Checks that every non-degenerate face without a neighbour really is the mesh's
    /// boundary: `cell_at` (a point location, e.g. through an acceleration structure) must find
    /// no other cell just beyond the face. Each such face is probed at its centre and at the
    /// four points halfway from there to its corners, moved outwards along the face normal by
    /// `1e-6` of the cell's box diagonal. A face with mesh beyond it is *hanging*: a
    /// non-conforming interface (a hexahedron face against two wedges or four smaller
    /// hexahedra, hanging nodes), a non-manifold face, or a seam the tolerance pass did not
    /// weld. Returns the number of hanging faces; [`FaceNeighbours::is_closed`] is true once the
    /// check has run and found none.
    ///
    /// The ray caster trusts a face without a neighbour to be the boundary only for a closed
    /// adjacency (see [`crate::render::Neighbours::complete`]); otherwise its boundary searches
    /// ask the structure.
    pub fn check_boundary(
        &mut self,
        mesh: &Mesh,
        cell_at: impl Fn(glam::DVec3) -> Option<u32> + Sync,
    ) -> usize {
        self.check_boundary_near(mesh, |_, _, _, _| [true; BOUNDARY_PROBES], cell_at)
    }

    /// [`FaceNeighbours::check_boundary`] with a filter in front of the point location: the
    /// probes `p` beyond face `face` of `cell` are put to `near(cell, face, probes, r)`, all
    /// at once, and a probe goes to `cell_at` only where its flag says another face without a
    /// neighbour may lie within `r` of it. `r` is the probes' offset plus the face's deviation
    /// from its plane, the farthest a probe can be from the face itself; a cell holding the
    /// probe would have a face without a neighbour within that distance (the face it touches
    /// this one with, unmatched since this one has no neighbour), so a filter that answers
    /// `false` only where no such face exists (e.g. from
    /// [`crate::render::surface::BoundarySurface::other_faces_near`]) changes no result.
    pub fn check_boundary_near(
        &mut self,
        mesh: &Mesh,
        near: impl Fn(u32, usize, &[glam::DVec3; BOUNDARY_PROBES], f64) -> [bool; BOUNDARY_PROBES]
            + Sync,
        cell_at: impl Fn(glam::DVec3) -> Option<u32> + Sync,
    ) -> usize {
        use glam::DVec3;
        let cells = mesh.cells();
        let hanging = self
            .neighbours
            .par_chunks(6)
            .enumerate()
            .map(|(c, nb)| {
                let ids = &cells[c];
                let corners = mesh.cell_corners(c);
                let centre = corners.iter().copied().sum::<DVec3>() / 8.0;
                let eps = 1e-6 * crate::geometry::bounds::cell_bounds(&corners).diagonal();
                (0..6)
                    .filter(|&f| {
                        nb[f] == NONE && !FaceKey::of_cell(ids, f).is_degenerate() && {
                            let q = face_vertices(f).map(|k| corners[k]);
                            let mid = (q[0] + q[1] + q[2] + q[3]) / 4.0;
                            let mut n = (q[2] - q[0]).cross(q[3] - q[1]);
                            if n.dot(mid - centre) < 0.0 {
                                n = -n;
                            }
                            let n = n.normalize_or_zero();
                            let deviation =
                                q.iter().map(|&k| n.dot(k - mid).abs()).fold(0.0, f64::max);
                            let reach = 2.0 * (eps + deviation);
                            n != DVec3::ZERO && {
                                let probes = [mid, q[0], q[1], q[2], q[3]]
                                    .map(|k| 0.5 * (mid + k) + n * eps);
                                let near = near(c as u32, f, &probes, reach);
                                probes.iter().zip(near).any(|(&p, near)| {
                                    near && cell_at(p).is_some_and(|o| o as usize != c)
                                })
                            }
                        }
                    })
                    .count()
            })
            .sum();
        self.hanging = Some(hanging);
        hanging
    }

    /// Faces [`FaceNeighbours::check_boundary`] found to have mesh beyond them (`None` before
    /// it has run).
    pub fn hanging_faces(&self) -> Option<usize> {
        self.hanging
    }

    /// Whether [`FaceNeighbours::check_boundary`] has run and found every face without a
    /// neighbour to be the mesh's boundary.
    pub fn is_closed(&self) -> bool {
        self.hanging == Some(0)
    }

    /// Bytes held: 24 per cell plus 8 per seam face.
    pub fn bytes(&self) -> usize {
        std::mem::size_of::<Self>()
            + self.neighbours.capacity() * std::mem::size_of::<u32>()
            + self.seams.capacity() * std::mem::size_of::<u64>()
    }
}

/// Pairs the runs of equal keys in `entries` (sorted here), writing neighbours both ways.
fn pair_runs(entries: &mut [Entry], neighbours: &[AtomicU32]) -> Counts {
    entries.sort_unstable();
    let mut counts = Counts::default();
    for run in entries.chunk_by(|a, b| a.0 == b.0) {
        match run {
            [_] => counts.boundary += 1,
            [(_, ca, fa), (_, cb, fb)] if ca != cb => {
                neighbours[*ca as usize * 6 + *fa as usize].store(*cb, Ordering::Relaxed);
                neighbours[*cb as usize * 6 + *fb as usize].store(*ca, Ordering::Relaxed);
            }
            _ => {
                counts.nonmanifold += run.len();
                for &(_, c, f) in run {
                    neighbours[c as usize * 6 + f as usize].store(NONMANIFOLD, Ordering::Relaxed);
                }
            }
        }
    }
    counts
}

/// The atomics as plain values, with the non-manifold marker turned into [`NONE`].
fn finish(neighbours: Vec<AtomicU32>) -> Vec<u32> {
    neighbours
        .into_iter()
        .map(|a| match a.into_inner() {
            NONMANIFOLD => NONE,
            n => n,
        })
        .collect()
}

/// Bins of the welding grid are this many tolerances wide.
const BIN_TOLERANCES: f64 = 16.0;

/// A multiply-rotate hasher for the welding grid's integer bin coordinates (std's SipHash
/// costs more than the rest of the weld).
#[derive(Default)]
struct BinHasher(u64);

impl std::hash::Hasher for BinHasher {
    fn finish(&self) -> u64 {
        self.0
    }
    fn write(&mut self, bytes: &[u8]) {
        for &b in bytes {
            self.write_u64(u64::from(b));
        }
    }
    fn write_u64(&mut self, x: u64) {
        self.0 = (self.0.rotate_left(5) ^ x).wrapping_mul(0x51_7c_c1_b7_27_22_0a_95);
    }
    fn write_i64(&mut self, x: i64) {
        self.write_u64(x as u64);
    }
}

/// For each point of `ids` (increasing), its representative point id: an earlier
/// representative within `tolerance` (the latest entered in the point's bin), or itself.
///
/// Each representative `q` is entered in every bin (of side [`BIN_TOLERANCES`] × `tolerance`)
/// that the cube `q ± tolerance` overlaps (one to eight, usually one), so a point within
/// `tolerance` of `q` finds it in its own bin.
fn weld_points(ids: &[u32], points: &[glam::DVec3], tolerance: f64) -> Vec<u32> {
    let size = tolerance * BIN_TOLERANCES;
    // `as` saturates beyond i64 and maps NaN to 0: no panic on any input.
    let bin = |x: f64| -> i64 { (x / size).floor() as i64 };
    type Bins = HashMap<[i64; 3], usize, std::hash::BuildHasherDefault<BinHasher>>;
    let mut heads: Bins = HashMap::default();
    // Linked lists of the representatives in each bin: (point, next entry).
    let mut chain: Vec<(u32, usize)> = Vec::new();
    let mut out = Vec::with_capacity(ids.len());
    let tol2 = tolerance * tolerance;
    for &id in ids {
        let Some(&p) = points.get(id as usize) else {
            out.push(id);
            continue;
        };
        let mut at = heads
            .get(&[bin(p.x), bin(p.y), bin(p.z)])
            .copied()
            .unwrap_or(usize::MAX);
        let mut found = None;
        while let Some(&(q, next)) = chain.get(at) {
            if points
                .get(q as usize)
                .is_some_and(|pq| pq.distance_squared(p) <= tol2)
            {
                found = Some(q);
                break;
            }
            at = next;
        }
        match found {
            Some(q) => out.push(q),
            None => {
                out.push(id);
                let range = |x: f64| {
                    let (lo, hi) = (bin(x - tolerance), bin(x + tolerance));
                    lo..=hi.max(lo).min(lo.saturating_add(1))
                };
                for bz in range(p.z) {
                    for by in range(p.y) {
                        for bx in range(p.x) {
                            let head = heads.entry([bx, by, bz]).or_insert(usize::MAX);
                            chain.push((id, *head));
                            *head = chain.len() - 1;
                        }
                    }
                }
            }
        }
    }
    out
}
