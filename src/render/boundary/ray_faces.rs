//! The boundary faces each ray of an image may meet, found by projecting the faces to the
//! image rather than by traversing the boundary surface's BVH once per query.
//!
//! The fast path asks the boundary surface ([`super::surface`]) where a ray may enter the
//! mesh, where it leaves it exactly, and whether it crosses a face between two points: a
//! traversal of the surface's BVH each time, about a quarter of a frame where rays leave and
//! re-enter the mesh often (the VTK comparison's scene of the 2.1 M rotor, `cargo bench
//! --bench render -- pump-rotor:2100000 512 2 cyl-bvh fast --vtk-scene --step-factor=4`).
//! Neighbouring rays meet nearly the same faces, so the faces are instead sorted to the image
//! once a frame, as VTK's Bunyk ray caster projects its boundary triangles:
//!
//! 1. [`FaceBins::new`]: each face's stored box (as the BVH tests it, padded) is projected
//!    through the camera ([`RaySource::project_box`]); the pixels whose centres lie in the
//!    box's projected bounds are its candidates, and the face is filed under every image tile
//!    they touch. A box that does not lie wholly in front of the eye cannot be projected;
//!    such faces are offered to every ray (up to [`MAX_UNPROJECTED`]; beyond that, with a
//!    camera among the faces, say, the frame keeps to the BVH). The faces are reached through
//!    the surface's BVH, whose nodes' boxes are projected the same way: the subtrees of a
//!    node that projects wholly outside the image are passed over (a band of an image, a
//!    close-up), and below a node that projects wholly inside it no node is projected.
//! 2. [`TileFaces::new`]: for each pixel of a tile, its ray's interval in each candidate
//!    face's box, computed as the BVH's traversal computes it, kept where the ray meets the
//!    box, sorted by entry.
//! 3. The surface's queries given that list (the ray's [`Ray::faces`]) scan it in order instead of
//!    traversing the BVH: the faces offered to a query are those whose boxes the ray meets on
//!    the query's interval, as the BVH offers them, so every answer is the same (a face
//!    reached at the same `t` as another may be named instead of it).
//!
//! Why a projected box holds every ray that meets the box: a perspective projection maps the
//! half-space in front of the eye onto the image plane by a map that takes segments to
//! segments, so the image of a box wholly in front of the eye is the convex hull of its
//! corners' images, within their bounds; a point of a ray projects to that ray's pixel
//! centre. A parallel projection is affine, with no such restriction. The pixel bounds are
//! widened by [`PIXEL_SLACK`] of a pixel for rounding.

use glam::DVec3;

use super::surface::BoundarySurface;
use crate::accel::bvh::Enter;
use crate::render::camera::RaySource;
#[cfg(doc)]
use crate::render::ray::Ray;
use crate::render::ray::RayFace;

/// Faces that cannot be projected (their boxes reach behind the eye) offered to every ray;
/// with more, the frame does not use projected faces.
pub(crate) const MAX_UNPROJECTED: usize = 64;

/// How far beyond a face's projected bounds, in pixels, a pixel centre still counts as
/// inside them (rounding in the projection and in the rays is far smaller).
pub(crate) const PIXEL_SLACK: f64 = 0.01;

/// The boundary faces of one frame filed under the image tiles their projected boxes touch.
#[derive(Clone, Debug)]
pub(crate) struct FaceBins {
    tile: u32,
    tiles_x: u32,
    /// Per tile: each face filed there with its pixel bounds `[i0, j0, i1, j1]` (inclusive).
    bins: Vec<Vec<(u32, [i32; 4])>>,
    /// Faces offered to every ray.
    unprojected: Vec<u32>,
    /// Faces whose boxes were projected.
    #[cfg(test)]
    faces_projected: usize,
}

impl FaceBins {
    /// Files `surface`'s faces under the `tile × tile` tiles of the image of `rays`; `None`
    /// where `rays` has no projection or more than [`MAX_UNPROJECTED`] faces cannot be
    /// projected.
    pub(crate) fn new<R: RaySource + ?Sized>(
        surface: &BoundarySurface,
        rays: &R,
        tile: u32,
    ) -> Option<FaceBins> {
        let (w, h) = rays.size();
        let tile = tile.max(1);
        let (tiles_x, tiles_y) = (w.div_ceil(tile), h.div_ceil(tile));
        // The faces whose boxes project into the image (`Some`) or cannot be projected
        // (`None`), found through the surface's BVH: a node whose box projects wholly outside
        // the image holds no face that projects into it (a box's projection holds those of
        // the boxes within it), so a band of the image or a close-up visits only the faces
        // it sees and the subtrees around them; below a node whose box projects wholly into
        // the image, no node is tested.
        let (w_max, h_max) = ((w - 1) as f64, (h - 1) as f64);
        let in_image = |(lo, hi)| match rays.project_box(lo, hi) {
            None => Enter::Test,
            Some((a, b)) if a[0] >= 0.0 && a[1] >= 0.0 && b[0] <= w_max && b[1] <= h_max => {
                Enter::All
            }
            Some(ab) => match clamped(ab, rays) {
                None => Enter::Skip,
                Some(_) => Enter::Test,
            },
        };
        let projected = surface.faces_where(in_image, |f, b| Some((f, pixel_bounds(b, rays))));
        let mut bins: Vec<Vec<(u32, [i32; 4])>> = vec![Vec::new(); (tiles_x * tiles_y) as usize];
        let mut unprojected = Vec::new();
        for &(f, bounds) in &projected {
            match bounds {
                Some(None) => {}
                None => {
                    unprojected.push(f);
                    if unprojected.len() > MAX_UNPROJECTED {
                        return None;
                    }
                }
                Some(Some(b)) => {
                    let (x0, y0) = (b[0] as u32 / tile, b[1] as u32 / tile);
                    let (x1, y1) = (b[2] as u32 / tile, b[3] as u32 / tile);
                    for ty in y0..=y1 {
                        for tx in x0..=x1 {
                            bins[(ty * tiles_x + tx) as usize].push((f, b));
                        }
                    }
                }
            }
        }
        Some(FaceBins {
            tile,
            tiles_x,
            bins,
            unprojected,
            #[cfg(test)]
            faces_projected: projected.len(),
        })
    }

    /// The faces whose boxes were projected: those of the surface's BVH leaves whose nodes'
    /// boxes do not project wholly outside the image.
    #[cfg(test)]
    pub(crate) fn faces_projected(&self) -> usize {
        self.faces_projected
    }

    /// The faces offered to every ray.
    #[cfg(test)]
    pub(crate) fn unprojected(&self) -> &[u32] {
        &self.unprojected
    }
}

/// The pixel bounds `[i0, j0, i1, j1]` (inclusive, clamped to the image) of the pixel centres
/// within the projection of a box; `Some(None)` where none is, `None` where the box cannot be
/// projected.
fn pixel_bounds<R: RaySource + ?Sized>(
    (lo, hi): (DVec3, DVec3),
    rays: &R,
) -> Option<Option<[i32; 4]>> {
    rays.project_box(lo, hi).map(|ab| clamped(ab, rays))
}

/// The pixel bounds `[i0, j0, i1, j1]` (inclusive, clamped to the image) of the pixel centres
/// within the bounds `(a, b)` widened by [`PIXEL_SLACK`]; `None` where none is.
fn clamped<R: RaySource + ?Sized>((a, b): ([f64; 2], [f64; 2]), rays: &R) -> Option<[i32; 4]> {
    let (w, h) = rays.size();
    let i0 = (a[0] - PIXEL_SLACK).ceil().max(0.0);
    let j0 = (a[1] - PIXEL_SLACK).ceil().max(0.0);
    let i1 = (b[0] + PIXEL_SLACK).floor().min(w as f64 - 1.0);
    let j1 = (b[1] + PIXEL_SLACK).floor().min(h as f64 - 1.0);
    (i0 <= i1 && j0 <= j1).then_some([i0 as i32, j0 as i32, i1 as i32, j1 as i32])
}

/// The faces each ray of one tile meets the boxes of (see the module documentation).
#[derive(Clone, Debug, Default)]
pub(crate) struct TileFaces {
    /// Pixel `k` of the tile (row-major) has `faces[start[k]..start[k + 1]]`.
    start: Vec<u32>,
    faces: Vec<RayFace>,
}

impl TileFaces {
    /// The lists of the tile `(tx, ty)` of `bins`, whose rays (row-major over the tile's
    /// pixels, clipped to the image) are `rays`.
    pub(crate) fn new(
        surface: &BoundarySurface,
        bins: &FaceBins,
        (tx, ty): (u32, u32),
        rays: &[(DVec3, DVec3)],
        tile_width: u32,
    ) -> TileFaces {
        let (x0, y0) = (tx * bins.tile, ty * bins.tile);
        let tw = tile_width.max(1) as usize;
        let th = rays.len().div_ceil(tw);
        let query = surface.ray_query();
        let prepared: Vec<_> = rays.iter().map(|&(o, d)| query.prepare(o, d)).collect();
        // Every (pixel, face) pair found.
        let mut pairs: Vec<(u32, RayFace)> = Vec::new();
        let bin = bins
            .bins
            .get((ty * bins.tiles_x + tx) as usize)
            .map_or(&[][..], |b| b.as_slice());
        for &(f, b) in bin {
            let i0 = (b[0] - x0 as i32).max(0) as usize;
            let j0 = (b[1] - y0 as i32).max(0) as usize;
            let i1 = ((b[2] - x0 as i32) as usize).min(tw - 1);
            let j1 = ((b[3] - y0 as i32) as usize).min(th - 1);
            for j in j0..=j1 {
                for i in i0..=i1 {
                    let k = j * tw + i;
                    if let Some(r) = prepared.get(k).and_then(|p| query.ray_face(f, p)) {
                        pairs.push((k as u32, r));
                    }
                }
            }
        }
        for (k, p) in prepared.iter().enumerate() {
            let offered = bins
                .unprojected
                .iter()
                .filter_map(|&f| query.ray_face(f, p));
            pairs.extend(offered.map(|r| (k as u32, r)));
        }
        // Placed by pixel (a counting sort), then each pixel's few sorted by entry.
        let mut start = vec![0u32; rays.len() + 1];
        for &(k, _) in &pairs {
            start[k as usize + 1] += 1;
        }
        for k in 0..rays.len() {
            start[k + 1] += start[k];
        }
        let mut next = start.clone();
        let none = RayFace {
            entry: 0.0,
            exit: 0.0,
            face: 0,
        };
        let mut faces = vec![none; pairs.len()];
        for (k, r) in pairs {
            faces[next[k as usize] as usize] = r;
            next[k as usize] += 1;
        }
        for k in 0..rays.len() {
            let list = &mut faces[start[k] as usize..start[k + 1] as usize];
            list.sort_unstable_by(|a, b| a.entry.total_cmp(&b.entry));
        }
        TileFaces { start, faces }
    }

    /// The faces the ray of the tile's pixel `k` (row-major) meets the boxes of, by entry.
    pub(crate) fn of(&self, k: usize) -> Option<&[RayFace]> {
        let (a, b) = (*self.start.get(k)?, *self.start.get(k + 1)?);
        self.faces.get(a as usize..b as usize)
    }
}

#[cfg(test)]
mod tests {
    use std::collections::BTreeMap;

    use glam::DMat4;

    use super::*;
    use crate::accel::{Accel, AccelParams, Counters, StructureKind};
    use crate::datasets::{generate, Dataset};
    use crate::render::camera::{band_projection, Camera, MatrixRays, Projection, RayGenerator};
    use crate::render::faces::{face_neighbours, Topology};
    use crate::render::ray::Ray;
    use crate::Mesh;

    const TILE: u32 = 16;

    /// A small rotor with its face neighbours and boundary surface.
    fn rotor() -> (Mesh, Topology) {
        let mesh = generate(Dataset::PumpRotor, 12_000).expect("rotor");
        let axis = crate::axis::detect(&mesh);
        let accel = Accel::build(
            &mesh,
            StructureKind::CartBvh,
            &axis,
            &AccelParams::default(),
        )
        .expect("build");
        let topology = face_neighbours(&mesh, &accel);
        assert_eq!(topology.hanging_faces(), Some(0));
        (mesh, topology)
    }

    /// Row-major matrices as VTK gives them: a look-at view and a perspective projection.
    fn matrices(eye: DVec3, focal: DVec3, up: DVec3, aspect: f64) -> ([f64; 16], [f64; 16]) {
        let view = DMat4::look_at_rh(eye, focal, up);
        let proj = DMat4::perspective_rh_gl(30f64.to_radians(), aspect, 0.05, 50.0);
        let row_major = |m: DMat4| {
            let c = m.to_cols_array();
            let mut r = [0.0; 16];
            for i in 0..4 {
                for j in 0..4 {
                    r[4 * i + j] = c[4 * j + i];
                }
            }
            r
        };
        (row_major(view), row_major(proj))
    }

    /// Every pixel's list: the faces its ray's line meets the boxes of, from the bins.
    fn lists<R: RaySource>(surface: &BoundarySurface, rays: &R) -> Option<Vec<Vec<RayFace>>> {
        let bins = FaceBins::new(surface, rays, TILE)?;
        let (w, h) = rays.size();
        let mut out = vec![Vec::new(); (w * h) as usize];
        for ty in 0..h.div_ceil(TILE) {
            for tx in 0..w.div_ceil(TILE) {
                let (i_end, j_end) = (((tx + 1) * TILE).min(w), ((ty + 1) * TILE).min(h));
                let tw = i_end - tx * TILE;
                let pixels: Vec<(u32, u32)> = (ty * TILE..j_end)
                    .flat_map(|j| (tx * TILE..i_end).map(move |i| (i, j)))
                    .collect();
                let tile_rays: Vec<_> = pixels.iter().map(|&(i, j)| rays.ray(i, j)).collect();
                let t = TileFaces::new(surface, &bins, (tx, ty), &tile_rays, tw);
                for (k, &(i, j)) in pixels.iter().enumerate() {
                    out[(j * w + i) as usize] = t.of(k).expect("a list").to_vec();
                }
            }
        }
        Some(out)
    }

    /// Asserts each pixel's list is exactly the faces whose boxes its ray meets, by entry.
    fn assert_lists_complete<R: RaySource>(
        name: &str,
        surface: &BoundarySurface,
        rays: &R,
    ) -> usize {
        let lists = lists(surface, rays).unwrap_or_else(|| panic!("{name}: no bins"));
        let (w, h) = rays.size();
        let query = surface.ray_query();
        let mut listed = 0;
        for j in 0..h {
            for i in 0..w {
                let (o, d) = rays.ray(i, j);
                let p = query.prepare(o, d);
                let brute: BTreeMap<u32, RayFace> = (0..surface.face_count() as u32)
                    .filter_map(|f| query.ray_face(f, &p).map(|r| (f, r)))
                    .collect();
                let list = &lists[(j * w + i) as usize];
                assert!(
                    list.windows(2).all(|x| x[0].entry <= x[1].entry),
                    "{name}: pixel ({i}, {j}) not sorted"
                );
                let got: BTreeMap<u32, RayFace> = list.iter().map(|r| (r.face, *r)).collect();
                assert_eq!(got.len(), list.len(), "{name}: a face listed twice");
                assert_eq!(got, brute, "{name}: pixel ({i}, {j})");
                listed += list.len();
            }
        }
        listed
    }

    /// Every ray's list holds exactly the faces whose boxes its line meets (brute force over
    /// every face), for perspective and parallel cameras and VTK-style matrices.
    #[test]
    fn every_ray_lists_exactly_the_face_boxes_it_meets() {
        let (mesh, topology) = rotor();
        let surface = topology.surface();
        let b = mesh.bounds();
        let mut total = 0;
        for (k, (az, el, zoom)) in [(30.0, 20.0, 1.0), (-70.0, 55.0, 1.6), (0.0, 89.0, 0.7)]
            .into_iter()
            .enumerate()
        {
            let camera = Camera::view(b, 40, 32, az, el, zoom);
            let rays = RayGenerator::new(&camera, 40, 32).expect("rays");
            total += assert_lists_complete(&format!("view {k}"), surface, &rays);
            let mut parallel = camera;
            parallel.projection = Projection::Parallel(0.4);
            let rays = RayGenerator::new(&parallel, 40, 32).expect("rays");
            total += assert_lists_complete(&format!("parallel view {k}"), surface, &rays);
        }
        let (view, proj) = matrices(
            DVec3::new(1.8, -2.1, 1.4),
            DVec3::new(0.0, 0.0, 0.2),
            DVec3::Z,
            40.0 / 32.0,
        );
        let rays = MatrixRays::new(&view, &proj, 40, 32).expect("matrix rays");
        total += assert_lists_complete("matrices", surface, &rays);
        assert!(
            total > 10_000,
            "too few faces listed to test anything: {total}"
        );
    }

    /// A band of the image or a close-up projects only the faces near its view.
    #[test]
    fn a_band_or_a_close_up_projects_only_the_faces_it_sees() {
        let (mesh, topology) = rotor();
        let surface = topology.surface();
        let faces = surface.face_count();
        let (w, h) = (40, 32);
        let (view, proj) = matrices(
            DVec3::new(1.8, -2.1, 1.4),
            DVec3::new(0.0, 0.0, 0.2),
            DVec3::Z,
            w as f64 / h as f64,
        );
        let whole = MatrixRays::new(&view, &proj, w, h).expect("matrix rays");
        let whole = FaceBins::new(surface, &whole, TILE).expect("bins");
        // Four bands, each with its rays' lists complete, each projecting a part of the faces.
        let mut projected = 0;
        for b in 0..4 {
            let (r0, r1) = (h * b / 4, h * (b + 1) / 4);
            let band = band_projection(&proj, r0, r1, h);
            let rays = MatrixRays::new(&view, &band, w, r1 - r0).expect("band rays");
            assert_lists_complete(&format!("band {b}"), surface, &rays);
            let bins = FaceBins::new(surface, &rays, TILE).expect("bins");
            assert!(
                bins.faces_projected() < faces * 3 / 4,
                "band {b}: {} of {faces} faces projected",
                bins.faces_projected()
            );
            projected += bins.faces_projected();
        }
        assert!(
            projected < whole.faces_projected() * 2,
            "four bands projected {projected} faces, the whole image {}",
            whole.faces_projected()
        );
        // A close-up.
        let camera = Camera::view(mesh.bounds(), w, h, 30.0, 20.0, 5.0);
        let rays = RayGenerator::new(&camera, w, h).expect("rays");
        assert_lists_complete("close-up", surface, &rays);
        let bins = FaceBins::new(surface, &rays, TILE).expect("bins");
        assert!(
            bins.faces_projected() < faces / 2,
            "close-up: {} of {faces} faces projected",
            bins.faces_projected()
        );
    }

    /// With the eye among the faces, the faces behind it are offered to every ray, or the
    /// frame keeps to the BVH.
    #[test]
    fn a_camera_among_the_faces_lists_them_all_or_keeps_to_the_bvh() {
        let (mesh, topology) = rotor();
        let surface = topology.surface();
        // The eye in the channel between hub and shroud, looking across the blades: faces all
        // around it reach behind it.
        let mut camera = Camera::view(mesh.bounds(), 24, 24, 10.0, 5.0, 1.0);
        camera.eye = DVec3::new(0.62, 0.05, 0.12);
        camera.focal = DVec3::new(-0.6, 0.3, 0.1);
        camera.up = DVec3::Z;
        let rays = RayGenerator::new(&camera, 24, 24).expect("rays");
        if let Some(bins) = FaceBins::new(surface, &rays, TILE) {
            assert!(!bins.unprojected().is_empty());
            assert_lists_complete("inside", surface, &rays);
        }
        // With only a few faces behind the eye, they are offered to every ray.
        let mut near = Camera::view(mesh.bounds(), 24, 24, 30.0, 20.0, 1.0);
        near.eye = DVec3::new(1.02, 0.0, 0.2);
        near.focal = DVec3::new(0.0, 0.0, 0.2);
        near.up = DVec3::Z;
        let rays = RayGenerator::new(&near, 24, 24).expect("rays");
        if FaceBins::new(surface, &rays, TILE).is_some() {
            assert_lists_complete("near", surface, &rays);
        }
    }

    /// The surface's queries answer from a ray's list as from the BVH.
    #[test]
    fn queries_answer_from_a_list_as_from_the_bvh() {
        let (mesh, topology) = rotor();
        let surface = topology.surface();
        let camera = Camera::view(mesh.bounds(), 32, 32, 30.0, 20.0, 1.0);
        let rays = RayGenerator::new(&camera, 32, 32).expect("rays");
        let lists = lists(surface, &rays).expect("bins");
        let mut crossings = 0;
        for j in 0..32 {
            for i in 0..32 {
                let (o, d) = rays.ray(i, j);
                let bare = Ray::line(o, d);
                let listed = bare.with_faces(Some(&lists[(j * 32 + i) as usize]));
                let mut c = Counters::default();
                let mut t = 0.0;
                // Each possible crossing in turn, from just past the one before.
                for _ in 0..40 {
                    // The same `t`; where two faces are reached at once, either may be named.
                    let by_list = surface.next_crossing(&listed, t, 1e3, &mut c);
                    let by_bvh = surface.next_crossing(&bare, t, 1e3, &mut c);
                    assert_eq!(
                        by_list.map(|x| x.0),
                        by_bvh.map(|x| x.0),
                        "pixel ({i}, {j}) from {t}"
                    );
                    let Some((tc, _)) = by_bvh else { break };
                    // The exact crossings on either side, forwards and backwards.
                    for (a, z) in [(t, tc + 0.05), (tc + 0.05, t)] {
                        let l = surface.first_face_crossing(&listed, &mesh, a, z, &mut c);
                        let b = surface.first_face_crossing(&bare, &mesh, a, z, &mut c);
                        let at = |x: Option<Option<(f64, (u32, u8))>>| x.map(|y| y.map(|z| z.0));
                        assert_eq!(at(l), at(b), "pixel ({i}, {j}) on [{a}, {z}]");
                        crossings += usize::from(matches!(b, Some(Some(_))));
                    }
                    t = tc + 1e-3;
                }
            }
        }
        assert!(crossings > 500, "{crossings}");
    }
}
