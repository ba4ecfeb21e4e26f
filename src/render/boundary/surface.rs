//! The mesh's boundary surface, for the fast path's empty-space skipping from points known to
//! lie outside the mesh.
//!
//! The boundary of the mesh is made of the cell faces without a face neighbour (faces with
//! fewer than three distinct points have no area and are left out). A ray that is outside the
//! mesh at `t₀` stays outside until it crosses one of them, so every sample before the first
//! such crossing is outside, with no point location at all.
//!
//! The crossing is bounded conservatively: a bilinear face lies in the convex hull of its
//! four corners, hence in their box and in the slab between the corners' extreme projections
//! on the face normal (the cross product of its diagonals). [`BoundarySurface::next_crossing`]
//! finds, through a BVH over the faces' boxes, the smallest `t ≥ t₀` at which the ray is in
//! both a face's box and its slab (padded by `1e-9` of the face's size, far above rounding).
//! The ray cannot cross a face before that, so the answer never skips a sample the mesh
//! holds. Faces the ray is already past at `t₀` (the one it just left through, typically)
//! are not in its way, which is what makes the skip reach across a blade or the hub's hole.
//!
//! Without a neighbour source that pairs shared faces, extra faces only make the bound more
//! conservative: a face counted as boundary that is not only costs skipping distance.

use glam::DVec3;

use crate::accel::bvh::ray::{box_span, clip_to_slab, reciprocal};
use crate::accel::bvh::{build_bvh, BoxF32, Bvh, BvhParams, Enter};
use crate::accel::space::Pieces;
use crate::accel::Counters;
use crate::geometry::bounds::Aabb;
use crate::geometry::patch::segment_crossings;
use crate::mesh::topology::{FaceKey, FaceNeighbours, FACES};
use crate::render::ray::{Ray, RayFace};
use crate::Mesh;

/// Padding of a face's slab, relative to the face's size.
const SLAB_PAD: f64 = 1e-9;

/// The mesh's boundary faces in a BVH over their boxes (see the module documentation).
#[derive(Clone, Debug)]
pub struct BoundarySurface {
    bvh: Bvh<Aabb>,
    /// `(cell, face)` of each boundary face; the BVH's pieces index this.
    faces: Vec<(u32, u8)>,
    /// The slab of each face, in the same order.
    slabs: Vec<Slab>,
    /// The stored box of each face (as the BVH's leaves hold it), in the same order.
    boxes: Vec<BoxF32>,
}

/// A ray's tests against the faces' stored boxes, as the BVH's traversal makes them
/// ([`BoundarySurface::ray_query`]).
#[derive(Clone, Copy, Debug)]
pub(crate) struct FaceBoxQuery<'s> {
    boxes: &'s [BoxF32],
    anchor: DVec3,
    pad: f64,
}

/// A ray prepared for [`FaceBoxQuery::ray_face`]: its origin relative to the boxes' anchor and
/// the reciprocal of its direction.
#[derive(Clone, Copy, Debug)]
pub(crate) struct PreparedRay {
    origin: DVec3,
    inv: DVec3,
}

impl FaceBoxQuery<'_> {
    /// A stored box (a face's or a BVH node's), padded, in world coordinates.
    #[inline]
    fn world(&self, b: &BoxF32) -> (DVec3, DVec3) {
        let pad = DVec3::splat(self.pad);
        let world = |c: [f32; 3]| self.anchor + DVec3::new(c[0] as f64, c[1] as f64, c[2] as f64);
        (world(b.min) - pad, world(b.max) + pad)
    }

    /// Prepares the ray `origin + t dir`.
    #[inline]
    pub(crate) fn prepare(&self, origin: DVec3, dir: DVec3) -> PreparedRay {
        PreparedRay {
            origin: origin - self.anchor,
            inv: reciprocal(dir),
        }
    }

    /// The ray's line's interval in face `face`'s stored box (padded as the BVH pads it), the
    /// same numbers a traversal of the BVH computes; `None` where it misses the box.
    #[inline]
    pub(crate) fn ray_face(&self, face: u32, ray: &PreparedRay) -> Option<RayFace> {
        let b = self.boxes.get(face as usize)?;
        box_span(
            ray.origin,
            ray.inv,
            self.pad,
            b.min,
            b.max,
            f64::NEG_INFINITY,
            f64::INFINITY,
        )
        .map(|(entry, exit)| RayFace { entry, exit, face })
    }
}

/// The slab between the extreme projections of a face's corners on its normal (padded):
/// `lo ≤ n·(x − a) ≤ hi` holds the face.
#[derive(Clone, Copy, Debug)]
struct Slab {
    a: DVec3,
    n: DVec3,
    lo: f64,
    hi: f64,
}

impl Slab {
    /// The slab of a face: along its normal, the cross product of its diagonals.
    fn of(corners: &[DVec3; 4]) -> Slab {
        let a = corners[0];
        let rel = corners.map(|c| c - a);
        Slab::along(corners, (rel[2] - rel[0]).cross(rel[3] - rel[1]))
    }

    /// The slab between the extreme projections of a face's corners on `m`, padded by
    /// `1e-9` of the face's size; the whole space where `m` vanishes.
    fn along(corners: &[DVec3; 4], m: DVec3) -> Slab {
        let a = corners[0];
        let len = m.length();
        if !(len > 0.0 && len.is_finite()) {
            return Slab {
                a,
                n: DVec3::ZERO,
                lo: f64::NEG_INFINITY,
                hi: f64::INFINITY,
            };
        }
        let (mut lo, mut hi, mut size) = (0.0f64, 0.0f64, 0.0f64);
        for k in &corners[1..] {
            let r = *k - a;
            let v = m.dot(r);
            lo = lo.min(v);
            hi = hi.max(v);
            size = size.max(r.length());
        }
        let pad = SLAB_PAD * size * len;
        Slab {
            a,
            n: m,
            lo: lo - pad,
            hi: hi + pad,
        }
    }

    /// Whether `p` lies within `r` of the slab.
    fn holds(&self, p: DVec3, r: f64) -> bool {
        let v = self.n.dot(p - self.a);
        let pad = r * self.n.length();
        v >= self.lo - pad && v <= self.hi + pad
    }

    /// The part of the ray interval `span` (finite: the ray's interval in the face's box) in
    /// the slab (empty, start above end, where the ray misses it there; see
    /// [`clip_to_slab`]).
    #[inline]
    fn clip(&self, origin: DVec3, dir: DVec3, span: (f64, f64)) -> (f64, f64) {
        let inv = 1.0 / (self.n.dot(dir) + 0.0);
        clip_to_slab(self.n.dot(origin - self.a), inv, self.lo, self.hi, span)
    }
}

impl BoundarySurface {
    /// The faces of `mesh` without a neighbour in `neighbours` (and with three or more
    /// distinct points), in a BVH.
    pub fn new(mesh: &Mesh, neighbours: &FaceNeighbours) -> BoundarySurface {
        use rayon::prelude::*;
        let cells = mesh.cells();
        let faces: Vec<(u32, u8)> = (0..cells.len() as u32)
            .into_par_iter()
            .flat_map_iter(|c| {
                let ids = cells[c as usize];
                let nb = neighbours.neighbours(c);
                (0..6u8)
                    .filter(move |&f| {
                        if nb[f as usize] != u32::MAX {
                            return false;
                        }
                        !FaceKey::of_cell(&ids, f as usize).is_degenerate()
                    })
                    .map(move |f| (c, f))
            })
            .collect();
        let bounds: Vec<Aabb> = faces
            .par_iter()
            .map(|&(c, f)| Aabb::from_points(&face_corners(mesh, c, f)))
            .collect();
        let pieces = Pieces {
            bounds,
            cells: (0..faces.len() as u32).collect(),
        };
        let slabs = faces
            .par_iter()
            .map(|&(c, f)| Slab::of(&face_corners(mesh, c, f)))
            .collect();
        let bvh = build_bvh(&pieces, &BvhParams::default());
        let mut boxes = vec![
            BoxF32 {
                min: [0.0; 3],
                max: [0.0; 3],
            };
            faces.len()
        ];
        for r in &bvh.refs {
            if let Some(b) = boxes.get_mut(r.cell as usize) {
                *b = r.bounds;
            }
        }
        BoundarySurface {
            bvh,
            faces,
            slabs,
            boxes,
        }
    }

    /// The number of boundary faces.
    pub fn face_count(&self) -> usize {
        self.faces.len()
    }

    /// The `(cell, face)` of each boundary face (face 0–5 in hexahedron face order).
    pub fn faces(&self) -> &[(u32, u8)] {
        &self.faces
    }

    /// The tests of rays against the faces' boxes that the queries' traversals make, for
    /// lists of the faces a ray meets ([`super::ray_faces`]).
    pub(crate) fn ray_query(&self) -> FaceBoxQuery<'_> {
        FaceBoxQuery {
            boxes: &self.boxes,
            anchor: self.bvh.frame.anchor,
            pad: self.bvh.query_pad(),
        }
    }

    /// The faces within the BVH's nodes that `enter` lets in ([`Bvh::collect_where`]; the
    /// nodes' and faces' boxes padded, in world coordinates, as [`FaceBoxQuery::world_box`]
    /// gives them), mapped by `face` (given the face and its box; `None` leaves it out):
    /// [`super::ray_faces::FaceBins`] passes over the subtrees of faces outside the
    /// image so.
    pub(crate) fn faces_where<T: Send>(
        &self,
        enter: impl Fn((DVec3, DVec3)) -> Enter + Sync,
        face: impl Fn(u32, (DVec3, DVec3)) -> Option<T> + Sync,
    ) -> Vec<T> {
        let query = self.ray_query();
        self.bvh
            .collect_where(|b| enter(query.world(b)), |b, f| face(f, query.world(b)))
    }

    /// [`Bvh::first_along`] over the faces along `dir` (the ray's direction or its reverse)
    /// from the ray's origin, or where the ray has a list of the faces its line meets, over
    /// that list (read backwards for the reverse): the same faces offered with the same
    /// intervals, nearest first (see [`super::ray_faces`]).
    fn along(
        &self,
        ray: &Ray,
        dir: DVec3,
        t0: f64,
        t1: f64,
        counters: &mut Counters,
        mut hit: impl FnMut(u32, f64, f64) -> Option<(f64, f64)>,
    ) -> Option<(f64, f64, u32)> {
        let origin = ray.origin;
        let forward = dir == ray.dir;
        let list = ray.faces.filter(|_| forward || dir == -ray.dir);
        let Some(list) = list else {
            return self.bvh.first_along(origin, dir, t0, t1, counters, hit);
        };
        let mut best: Option<(f64, f64, u32)> = None;
        let mut hi = t1;
        let mut offer = |face: u32, entry: f64, exit: f64, hi: &mut f64| {
            let (lo, x) = (entry.max(t0), exit.min(*hi));
            if lo <= x {
                counters.leaf_visits += 1;
                if let Some((e, x)) = hit(face, lo, x) {
                    if e <= *hi && best.map_or(true, |b| e < b.0) {
                        best = Some((e, x, face));
                        *hi = e;
                    }
                }
            }
        };
        if forward {
            for f in list {
                if f.entry > hi {
                    break;
                }
                offer(f.face, f.entry, f.exit, &mut hi);
            }
        } else {
            // Backwards: the interval along `-dir` is the negated one (exactly: the
            // reciprocal and the products change sign only).
            for f in list.iter().rev() {
                offer(f.face, -f.exit, -f.entry, &mut hi);
            }
        }
        best
    }

    /// The first `t ∈ [t0, t1]` at which the ray `origin + t dir` may cross the boundary
    /// (see the module documentation), with the cell of that face; `None` if it crosses none
    /// on that interval. If the ray is outside the mesh at `t0`, it is outside on
    /// `[t0, t)`. Node visits are counted in `counters`.
    pub(crate) fn next_crossing(
        &self,
        ray: &Ray,
        t0: f64,
        t1: f64,
        counters: &mut Counters,
    ) -> Option<(f64, u32)> {
        self.first_crossing(ray, t0, t1, &mut |_| true, counters)
            .map(|(t, (c, _))| (t, c))
    }

    /// Whether the ray `origin + t dir` may cross a boundary face other than `face` (its
    /// `(cell, face)`) for some `t` between `ta` and `tb` (in either order): `false` means it
    /// crosses no other. Each other face whose conservative bound (as in
    /// [`BoundarySurface::next_crossing`]) the segment meets is put to `may_cross` (given its
    /// `(cell, face)`), which refines the bound — an exact count of crossings, say — and says
    /// `true` where the segment may cross it. Node visits are counted in `counters`.
    pub(crate) fn may_cross_other(
        &self,
        ray: &Ray,
        (ta, tb): (f64, f64),
        face: (u32, u8),
        counters: &mut Counters,
        mut may_cross: impl FnMut((u32, u8)) -> bool,
    ) -> bool {
        let mut refine = |f: (u32, u8)| f != face && may_cross(f);
        self.first_crossing(ray, ta.min(tb), ta.max(tb), &mut refine, counters)
            .is_some()
    }

    /// For a ray in the mesh at `t_from` that crosses the boundary face `face` (its
    /// `(cell, face)`) before `t`: whether it may cross another one on `[t_from, t]`, as
    /// [`BoundarySurface::may_cross_other`] tells with `may_cross`, and if not, where it may
    /// next cross the boundary from `t` on (up to `t_end`), as
    /// [`BoundarySurface::next_crossing`] from `t` tells (`face` included: a line may cross a
    /// bilinear face twice) — in one traversal. `None` where it may cross another face before
    /// `t`; else `Some` of the next crossing (`None` inside it where there is none).
    pub(crate) fn sole_crossing_then_next(
        &self,
        ray: &Ray,
        (t_from, t): (f64, f64),
        t_end: f64,
        face: (u32, u8),
        counters: &mut Counters,
        mut may_cross: impl FnMut((u32, u8)) -> bool,
    ) -> Option<Option<(f64, u32)>> {
        let mut other = false;
        let (origin, dir) = (ray.origin, ray.dir);
        let hit = self.along(ray, dir, t_from, t_end, counters, |i, lo, hi| {
            let (f, lo, hi) = self.face_span(i, origin, dir, lo, hi)?;
            if lo < t && f != face && may_cross(f) {
                // Settled: the closest hit is now before `t`, which ends the traversal.
                other = true;
                return Some((lo, hi));
            }
            (hi >= t).then_some((lo.max(t), hi))
        });
        if other {
            return None;
        }
        Some(hit.and_then(|(t, _, i)| self.faces.get(i as usize).map(|&(c, _)| (t, c))))
    }

    /// Where the segment from `t_from` to `t_to` of the ray `origin + t dir` (backwards along
    /// the ray when `t_to < t_from`) first crosses a boundary face, exactly (the bilinear
    /// face, [`segment_crossings`], as [`crate::render::walk::march::boundary_face_crossing`] finds
    /// it by walking the cells): `Some(Some((t, (cell, face))))`, `Some(None)` where it
    /// crosses none, `None` where a face it may cross cannot be told robustly (near an edge,
    /// tangent). Only the faces whose bounds the segment meets are solved for, nearest first;
    /// node visits are counted in `counters`.
    ///
    /// From a point in the mesh, the first crossing is where the ray leaves it, wherever every
    /// face without a neighbour bounds the mesh ([`crate::render::Neighbours::complete`]).
    pub(crate) fn first_face_crossing(
        &self,
        ray: &Ray,
        mesh: &Mesh,
        t_from: f64,
        t_to: f64,
        counters: &mut Counters,
    ) -> Option<Option<(f64, (u32, u8))>> {
        let (origin, dir) = (ray.origin, ray.dir);
        // Along s = ±t, so that the search always goes towards larger s.
        let (d, sign) = if t_to >= t_from {
            (dir, 1.0)
        } else {
            (-dir, -1.0)
        };
        let (s_from, s_to) = (sign * t_from, sign * t_to);
        let mut undecided = false;
        let hit = self.along(ray, d, s_from, s_to, counters, |i, lo, hi| {
            let ((c, f), _, _) = self.face_span(i, origin, d, lo, hi)?;
            match segment_crossings(&face_corners(mesh, c, f), origin, d, s_from, s_to, 0.0) {
                Some(x) => x.ts().first().map(|&s| (s, s)),
                None => {
                    undecided = true;
                    None
                }
            }
        });
        if undecided {
            return None;
        }
        Some(hit.and_then(|(s, _, i)| self.faces.get(i as usize).map(|&f| (sign * s, f))))
    }

    /// Every crossing of a boundary face by the open segment `(t0, t1)` of the ray
    /// `origin + t dir` (`t0 < t1`), exactly (each bilinear face solved as
    /// [`BoundarySurface::first_face_crossing`] solves it), in increasing order with the cell
    /// of the face crossed; `None` where one of them cannot be told robustly (near a face's
    /// edge, tangent) or there are more than [`MAX_CROSSINGS`]. Where every face without a
    /// neighbour bounds the mesh, the ray passes between the mesh and the space outside at
    /// these `t` and nowhere else on the segment, so the parity of their number tells whether
    /// its ends lie on the same side. Node visits are counted in `counters`.
    pub(crate) fn crossings_between(
        &self,
        ray: &Ray,
        mesh: &Mesh,
        t0: f64,
        t1: f64,
        counters: &mut Counters,
    ) -> Option<BoundaryCrossings> {
        let (origin, dir) = (ray.origin, ray.dir);
        if t0.partial_cmp(&t1) != Some(std::cmp::Ordering::Less) {
            return Some(BoundaryCrossings::default());
        }
        let mut found = BoundaryCrossings::default();
        let mut undecided = false;
        self.along(ray, dir, t0, t1, counters, |i, lo, hi| {
            if undecided {
                return None;
            }
            let ((c, f), _, _) = self.face_span(i, origin, dir, lo, hi)?;
            match segment_crossings(&face_corners(mesh, c, f), origin, dir, t0, t1, 0.0) {
                Some(x) => {
                    for &t in x.ts() {
                        undecided |= !found.push(t, c);
                    }
                }
                None => undecided = true,
            }
            // No hit: every face the segment may cross is offered.
            None
        });
        if undecided {
            return None;
        }
        found.ts[..found.n].sort_by(|a, b| a.0.total_cmp(&b.0));
        Some(found)
    }

    /// Boundary face `i` (its `(cell, face)`) and the part of `[lo, hi]` (the ray's interval
    /// in the face's box) in which the ray is in the face's slab too; `None` where there is
    /// none. The conservative bound every traversal of the surface tests a face by.
    #[inline]
    fn face_span(
        &self,
        i: u32,
        origin: DVec3,
        dir: DVec3,
        lo: f64,
        hi: f64,
    ) -> Option<((u32, u8), f64, f64)> {
        let face = *self.faces.get(i as usize)?;
        let (lo, hi) = self.slabs.get(i as usize)?.clip(origin, dir, (lo, hi));
        (lo <= hi).then_some((face, lo, hi))
    }

    /// The first `t ∈ [t0, t1]` at which the ray may cross a boundary face for which
    /// `keep` holds (asked only of faces whose bound the ray meets there), with that face's
    /// `(cell, face)`.
    fn first_crossing(
        &self,
        ray: &Ray,
        t0: f64,
        t1: f64,
        keep: &mut dyn FnMut((u32, u8)) -> bool,
        counters: &mut Counters,
    ) -> Option<(f64, (u32, u8))> {
        let (origin, dir) = (ray.origin, ray.dir);
        self.along(ray, dir, t0, t1, counters, |i, lo, hi| {
            let (face, lo, hi) = self.face_span(i, origin, dir, lo, hi)?;
            keep(face).then_some((lo, hi))
        })
        .and_then(|(t, _, i)| self.faces.get(i as usize).map(|&f| (t, f)))
    }

    /// For each of `points` (the probes near one face, say), whether a boundary face other
    /// than face `face` of `cell` may lie within `r` of it: one whose corners' box, slab (see
    /// the module documentation) and four edge slabs (between the corners' extreme
    /// projections on each edge crossed with the normal), all padded by `r`, hold the point.
    /// Each holds the convex hull of the face's corners, hence the face, so `false` means no
    /// other boundary face comes that close. One traversal of the surface: the faces whose
    /// boxes, padded by `r`, meet the points' box are tested against each point in turn.
    pub(crate) fn other_faces_near<const N: usize>(
        &self,
        mesh: &Mesh,
        cell: u32,
        face: usize,
        points: &[DVec3; N],
        r: f64,
    ) -> [bool; N] {
        let mut near = [false; N];
        if N == 0 {
            return near;
        }
        self.bvh.each_near_box(&Aabb::from_points(points), r, |i| {
            self.mark_near(mesh, i, (cell, face), points, r, &mut near);
            // Stop once every point is near some face.
            near.iter().all(|&x| x)
        });
        near
    }

    /// Sets the flags of the `points` that lie within `r` of boundary face `i` (unless it is
    /// face `own`, a `(cell, face)`): in its corners' box, its slab and its four edge slabs
    /// (the slabs between the corners' extreme projections hold their hull), all padded by
    /// `r`. The edge slabs are made once a point passes the others.
    fn mark_near<const N: usize>(
        &self,
        mesh: &Mesh,
        i: u32,
        own: (u32, usize),
        points: &[DVec3; N],
        r: f64,
        near: &mut [bool; N],
    ) {
        let Some(&(c, f)) = self.faces.get(i as usize) else {
            return;
        };
        if (c, f as usize) == own {
            return;
        }
        let corners = face_corners(mesh, c, f);
        let normal = &self.slabs[i as usize];
        let b = Aabb::from_points(&corners);
        let mut edges: Option<[Slab; 4]> = None;
        for (p, near) in points.iter().zip(near.iter_mut()) {
            if *near
                || !(b.min - r).cmple(*p).all()
                || !p.cmple(b.max + r).all()
                || !normal.holds(*p, r)
            {
                continue;
            }
            let edges = edges.get_or_insert_with(|| {
                std::array::from_fn(|e| {
                    let m = (corners[(e + 1) % 4] - corners[e]).cross(normal.n);
                    Slab::along(&corners, m)
                })
            });
            *near = edges.iter().all(|s| s.holds(*p, r));
        }
    }
}

/// The most boundary crossings [`BoundarySurface::crossings_between`] reports on one segment.
pub(crate) const MAX_CROSSINGS: usize = 16;

/// A segment's crossings of the boundary ([`BoundarySurface::crossings_between`]).
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct BoundaryCrossings {
    ts: [(f64, u32); MAX_CROSSINGS],
    n: usize,
}

impl BoundaryCrossings {
    /// The crossings' `t` with the cell of the face crossed, in increasing order of `t`.
    pub(crate) fn ts(&self) -> &[(f64, u32)] {
        &self.ts[..self.n]
    }

    /// How many there are.
    #[cfg(test)]
    pub(crate) fn len(&self) -> usize {
        self.n
    }

    /// Adds one; `false` where there is no room left.
    fn push(&mut self, t: f64, cell: u32) -> bool {
        match self.ts.get_mut(self.n) {
            Some(slot) => {
                *slot = (t, cell);
                self.n += 1;
                true
            }
            None => false,
        }
    }
}

/// The four corners of face `f` of cell `c`.
pub(crate) fn face_corners(mesh: &Mesh, c: u32, f: u8) -> [DVec3; 4] {
    let ids = mesh.cells()[c as usize];
    FACES[f as usize].map(|k| mesh.points()[ids[k] as usize])
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::accel::{Accel, AccelParams, StructureKind};
    use crate::datasets::{generate, Dataset};
    use crate::geometry::bounds::Aabb;
    use crate::render::faces::face_neighbours;
    use crate::render::walk::march::boundary_face_crossing;
    use crate::render::walk::Cells;

    /// A mesh with its boundary surface.
    fn surface_of(mesh: Mesh) -> (Mesh, BoundarySurface) {
        let n = FaceNeighbours::build_with_tolerance(&mesh, FaceNeighbours::seam_tolerance(&mesh));
        let surface = BoundarySurface::new(&mesh, &n);
        (mesh, surface)
    }

    #[test]
    fn the_surface_holds_every_face_without_a_neighbour() {
        let mesh = generate(Dataset::PumpInlet, 2000).unwrap();
        let faces =
            FaceNeighbours::build_with_tolerance(&mesh, FaceNeighbours::seam_tolerance(&mesh));
        let surface = BoundarySurface::new(&mesh, &faces);
        assert_eq!(
            surface.face_count(),
            faces.boundary_face_count() + faces.nonmanifold_faces()
        );
    }

    /// A ray from far off towards the mesh's centre crosses some boundary face; the first it
    /// may cross is not the only one on the way through.
    #[test]
    fn other_crossings_and_the_next_one_after_a_sole_crossing() {
        let (mesh, surface) = surface_of(generate(Dataset::PumpInlet, 2000).unwrap());
        let b = Aabb::from_points(mesh.points());
        let ray = Ray::line(b.center() - DVec3::X * 10.0 * b.diagonal(), DVec3::X);
        let mut c = Counters::default();
        let (t, cell) = surface.next_crossing(&ray, 0.0, 1e9, &mut c).unwrap();
        let face = *surface.faces().iter().find(|f| f.0 == cell).unwrap();
        assert!(surface.may_cross_other(&ray, (0.0, 1e9), face, &mut c, |_| true));
        // Before the first crossing there is none; where the refinement says so, none at all.
        assert!(!surface.may_cross_other(&ray, (0.0, 0.5 * t), face, &mut c, |_| true));
        assert!(!surface.may_cross_other(&ray, (0.0, 1e9), face, &mut c, |_| false));
        // With no other face counted as crossed, the next crossing from a point is the one
        // next_crossing gives.
        let from = 0.5 * t;
        let next = surface.sole_crossing_then_next(&ray, (0.0, from), 1e9, face, &mut c, |_| false);
        assert_eq!(next, Some(surface.next_crossing(&ray, from, 1e9, &mut c)));
        // With every face that may be crossed counted as crossed, no answer past the first.
        let after = 0.5 * (t + 1e9);
        let none = surface.sole_crossing_then_next(&ray, (0.0, after), 1e9, face, &mut c, |_| true);
        assert_eq!(none, None);
    }

    /// A ray through the pipe from far off: in once, out once, and none between the two.
    #[test]
    fn every_crossing_of_a_ray_through_the_pipe() {
        let (mesh, surface) = surface_of(generate(Dataset::PumpInlet, 2000).unwrap());
        let b = Aabb::from_points(mesh.points());
        let o = b.center() - DVec3::new(10.0, 0.013, 0.021) * b.diagonal();
        let ray = Ray::line(o, DVec3::X);
        let mut c = Counters::default();
        let all = surface
            .crossings_between(&ray, &mesh, 0.0, 1e9, &mut c)
            .unwrap();
        assert_eq!(all.len(), 2);
        let (first, _) = surface.next_crossing(&ray, 0.0, 1e9, &mut c).unwrap();
        assert!(all.ts()[0].0 >= first);
        let (t_in, t_out) = (all.ts()[0].0, all.ts()[1].0);
        let none = surface.crossings_between(&ray, &mesh, t_in + 1e-3, t_out - 1e-3, &mut c);
        assert_eq!(none.unwrap().len(), 0);
    }

    /// The boundary surface finds the same exit as the walk across the cells: from the
    /// centres of cells of a small rotor (a ring with blades: many boundary faces) along rays
    /// in many directions, forwards and backwards, wherever both can tell, the first boundary
    /// crossing is the same `t`, bit for bit (the same face, solved the same way). The surface
    /// solves for fewer faces, so it tells at least as often.
    #[test]
    fn the_boundary_surface_finds_the_exit_the_walk_finds() {
        use std::f64::consts::PI;
        let mesh = generate(Dataset::PumpRotor, 3000).expect("rotor");
        let axis = crate::axis::detect(&mesh);
        let accel = Accel::build(
            &mesh,
            StructureKind::CartBvh,
            &axis,
            &AccelParams::default(),
        )
        .expect("build");
        // Every face without a neighbour bounds the mesh (the walk's answer means what it says).
        let topology = face_neighbours(&mesh, &accel);
        assert_eq!(topology.hanging_faces(), Some(0));
        let cells = Cells {
            mesh: &mesh,
            neighbours: topology.faces(),
        };
        let diag = Aabb::from_points(mesh.points()).diagonal();
        let (mut both, mut surface_only, mut walk_only) = (0, 0, 0);
        for cell in (0..mesh.cell_count()).step_by(7) {
            let corners = mesh.cell_corners(cell);
            let o = corners.iter().copied().sum::<DVec3>() / 8.0;
            for k in 0..6 {
                let a = 2.0 * PI * (k as f64 + 0.37 * cell as f64) / 6.0;
                let d = DVec3::new(a.cos(), a.sin(), 0.3 * (a * 3.0).sin()).normalize();
                let ray = Ray::line(o, d);
                for t_to in [2.0 * diag, -2.0 * diag] {
                    let walked = boundary_face_crossing(&cells, cell as u32, &ray, 0.0, t_to);
                    let surfaced = topology
                        .surface()
                        .first_face_crossing(&ray, &mesh, 0.0, t_to, &mut Counters::default())
                        .flatten()
                        .map(|(t, _)| t);
                    match (walked, surfaced) {
                        (Some(w), Some(s)) => {
                            assert_eq!(w, s, "cell {cell}, direction {k}, towards {t_to}");
                            both += 1;
                        }
                        (None, Some(_)) => surface_only += 1,
                        (Some(_), None) => walk_only += 1,
                        (None, None) => {}
                    }
                }
            }
        }
        assert!(both > 1000, "{both}");
        assert!(
            walk_only <= surface_only,
            "{walk_only} against {surface_only}"
        );
    }

    /// The one traversal finds every face a brute-force pass over all of them finds, for
    /// probes beside, on and between the boundary faces of a small rotor, near and far.
    #[test]
    fn faces_near_points_are_those_a_pass_over_every_face_finds() {
        let (mesh, surface) = surface_of(generate(Dataset::PumpRotor, 3000).unwrap());
        let (mut near_some, mut near_none) = (0, 0);
        for (k, &(c, f)) in surface.faces().iter().enumerate().step_by(7) {
            let q = face_corners(&mesh, c, f);
            let mid = (q[0] + q[1] + q[2] + q[3]) / 4.0;
            let size = (q[2] - q[0]).length();
            let normal = surface.slabs[k].n.normalize_or_zero();
            let points =
                [mid, q[0], q[1], q[2], q[3]].map(|x| 0.5 * (mid + x) + normal * size * 1e-3);
            for r in [1e-9 * size, 0.3 * size, 2.0 * size] {
                let got = surface.other_faces_near(&mesh, c, f as usize, &points, r);
                let mut brute = [false; 5];
                for i in 0..surface.face_count() as u32 {
                    surface.mark_near(&mesh, i, (c, f as usize), &points, r, &mut brute);
                }
                assert_eq!(got, brute, "face {k}, r {r}");
                near_some += got.iter().filter(|&&x| x).count();
                near_none += got.iter().filter(|&&x| !x).count();
            }
        }
        assert!(near_some > 0 && near_none > 0, "{near_some} {near_none}");
    }

    #[test]
    fn slab_of_a_planar_face_is_thin() {
        let square = [
            DVec3::new(0.0, 0.0, 1.0),
            DVec3::new(1.0, 0.0, 1.0),
            DVec3::new(1.0, 1.0, 1.0),
            DVec3::new(0.0, 1.0, 1.0),
        ];
        let all = (f64::NEG_INFINITY, f64::INFINITY);
        let (s, e) = Slab::of(&square).clip(DVec3::new(0.5, 0.5, 0.0), DVec3::Z, all);
        assert!((s - 1.0).abs() < 1e-8 && (e - 1.0).abs() < 1e-8 && s <= 1.0 && e >= 1.0);
        // Parallel to the face, off its plane: missed; in it: the whole interval (finite, as
        // the face's box gives it).
        let box_span = (-5.0, 5.0);
        let (s, e) = Slab::of(&square).clip(DVec3::ZERO, DVec3::X, box_span);
        assert!(s > e, "{s} {e}");
        let on = Slab::of(&square).clip(DVec3::new(0.0, 0.0, 1.0), DVec3::X, box_span);
        assert_eq!(on, box_span);
    }

    #[test]
    fn slab_of_a_twisted_face_holds_it() {
        let twisted = [
            DVec3::new(0.0, 0.0, 0.0),
            DVec3::new(1.0, 0.0, 0.3),
            DVec3::new(1.0, 1.0, 0.0),
            DVec3::new(0.0, 1.0, 0.3),
        ];
        // Points of the bilinear patch are inside the slab along any line through them.
        for (u, v) in [(0.5, 0.5), (0.1, 0.9), (0.7, 0.2)] {
            let p = twisted[0] * (1.0 - u) * (1.0 - v)
                + twisted[1] * u * (1.0 - v)
                + twisted[2] * u * v
                + twisted[3] * (1.0 - u) * v;
            let d = DVec3::new(0.3, -0.2, 1.0).normalize();
            let all = (f64::NEG_INFINITY, f64::INFINITY);
            let (s, e) = Slab::of(&twisted).clip(p - d * 2.0, d, all);
            assert!(s <= 2.0 && e >= 2.0, "{u} {v}: {s} {e}");
        }
    }
}
