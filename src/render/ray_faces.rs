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
//! 3. The surface's queries given that list ([`RayFaces`]) scan it in order instead of
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

use super::camera::RaySource;
use super::surface::BoundarySurface;
use crate::accel::bvh::Enter;

/// Faces that cannot be projected (their boxes reach behind the eye) offered to every ray;
/// with more, the frame does not use projected faces.
pub const MAX_UNPROJECTED: usize = 64;

/// How far beyond a face's projected bounds, in pixels, a pixel centre still counts as
/// inside them (rounding in the projection and in the rays is far smaller).
pub const PIXEL_SLACK: f64 = 0.01;

/// A boundary face whose stored box a ray's line meets: the ray's interval in the box and the
/// face's index in [`BoundarySurface::faces`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RayFace {
    /// Where the ray's line enters the face's box.
    pub entry: f64,
    /// Where it leaves it.
    pub exit: f64,
    /// The face.
    pub face: u32,
}

/// The faces one ray meets the boxes of, sorted by entry, with the ray they were made for:
/// a query along another ray (or along this one backwards: the list is read in reverse)
/// ignores them.
#[derive(Clone, Copy, Debug)]
pub struct RayFaces<'a> {
    /// The ray's origin.
    pub origin: DVec3,
    /// The ray's direction.
    pub dir: DVec3,
    /// The faces, by increasing entry.
    pub list: &'a [RayFace],
}

/// The boundary faces of one frame filed under the image tiles their projected boxes touch.
#[derive(Clone, Debug)]
pub struct FaceBins {
    tile: u32,
    tiles_x: u32,
    /// Per tile: each face filed there with its pixel bounds `[i0, j0, i1, j1]` (inclusive).
    bins: Vec<Vec<(u32, [i32; 4])>>,
    /// Faces offered to every ray.
    unprojected: Vec<u32>,
    /// Faces whose boxes were projected.
    faces_projected: usize,
}

impl FaceBins {
    /// Files `surface`'s faces under the `tile × tile` tiles of the image of `rays`; `None`
    /// where `rays` has no projection or more than [`MAX_UNPROJECTED`] faces cannot be
    /// projected.
    pub fn new<R: RaySource + ?Sized>(
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
            faces_projected: projected.len(),
        })
    }

    /// The faces whose boxes were projected: those of the surface's BVH leaves whose nodes'
    /// boxes do not project wholly outside the image.
    pub fn faces_projected(&self) -> usize {
        self.faces_projected
    }

    /// The faces offered to every ray.
    pub fn unprojected(&self) -> &[u32] {
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
pub struct TileFaces {
    /// Pixel `k` of the tile (row-major) has `faces[start[k]..start[k + 1]]`.
    start: Vec<u32>,
    faces: Vec<RayFace>,
}

impl TileFaces {
    /// The lists of the tile `(tx, ty)` of `bins`, whose rays (row-major over the tile's
    /// pixels, clipped to the image) are `rays`.
    pub fn new(
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

    /// The faces of the tile's pixel `k` (row-major), for its ray `(origin, dir)`.
    pub fn of(&self, k: usize, origin: DVec3, dir: DVec3) -> Option<RayFaces<'_>> {
        let (a, b) = (*self.start.get(k)?, *self.start.get(k + 1)?);
        Some(RayFaces {
            origin,
            dir,
            list: self.faces.get(a as usize..b as usize)?,
        })
    }
}
