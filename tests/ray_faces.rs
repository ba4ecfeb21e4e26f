//! The boundary faces sorted to the image (`render::ray_faces`): every ray's list holds
//! exactly the faces whose boxes its line meets (brute force over every face), for
//! perspective and parallel cameras and VTK-style matrices; the surface's queries answer
//! from a list as from the BVH; and a fast render is the same image with the lists as
//! without them, with fewer surface visits (the counter); a band of the image or a close-up
//! projects only the faces near its view (the faces-projected counter).

mod common;

use std::collections::BTreeMap;

use cylvol::accel::{Accel, AccelParams, Counters, StructureKind};
use cylvol::datasets::{generate, Dataset};
use cylvol::render::camera::{band_projection, MatrixRays, RaySource};
use cylvol::render::ray_faces::{FaceBins, RayFace, RayFaces, TileFaces};
use cylvol::render::surface::BoundarySurface;
use cylvol::render::{
    default_step, Camera, Neighbours, RayGenerator, RenderOptions, RenderPath, Renderer,
    TransferFunction, Volume,
};
use cylvol::Mesh;
use glam::{DMat4, DVec3};

const TILE: u32 = 16;

/// The rays of `inner` with no projection: a render from them keeps to the BVH.
struct Unprojected<'a>(&'a dyn RaySource);

impl RaySource for Unprojected<'_> {
    fn size(&self) -> (u32, u32) {
        self.0.size()
    }
    fn ray(&self, i: u32, j: u32) -> (DVec3, DVec3) {
        self.0.ray(i, j)
    }
}

fn rotor() -> Mesh {
    generate(Dataset::PumpRotor, 12_000).expect("rotor")
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
                let (o, d) = tile_rays[k];
                out[(j * w + i) as usize] = t.of(k, o, d).expect("a list").list.to_vec();
            }
        }
    }
    Some(out)
}

/// Asserts each pixel's list is exactly the faces whose boxes its ray meets, by entry.
fn assert_lists_complete<R: RaySource>(name: &str, surface: &BoundarySurface, rays: &R) -> usize {
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

#[test]
fn every_ray_lists_exactly_the_face_boxes_it_meets() {
    let mesh = rotor();
    let topology = common::closed_neighbours(&mesh);
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
        parallel.projection = cylvol::render::camera::Projection::Parallel(0.4);
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

#[test]
fn a_band_or_a_close_up_projects_only_the_faces_it_sees() {
    let mesh = rotor();
    let topology = common::closed_neighbours(&mesh);
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
    let b = mesh.bounds();
    let camera = Camera::view(b, w, h, 30.0, 20.0, 5.0);
    let rays = RayGenerator::new(&camera, w, h).expect("rays");
    assert_lists_complete("close-up", surface, &rays);
    let bins = FaceBins::new(surface, &rays, TILE).expect("bins");
    assert!(
        bins.faces_projected() < faces / 2,
        "close-up: {} of {faces} faces projected",
        bins.faces_projected()
    );
}

#[test]
fn a_camera_among_the_faces_lists_them_all_or_keeps_to_the_bvh() {
    let mesh = rotor();
    let topology = common::closed_neighbours(&mesh);
    let surface = topology.surface();
    // The eye in the channel between hub and shroud, looking across the blades: faces all
    // around it reach behind it.
    let mut camera = Camera::view(mesh.bounds(), 24, 24, 10.0, 5.0, 1.0);
    camera.eye = DVec3::new(0.62, 0.05, 0.12);
    camera.focal = DVec3::new(-0.6, 0.3, 0.1);
    camera.up = DVec3::Z;
    let rays = RayGenerator::new(&camera, 24, 24).expect("rays");
    match FaceBins::new(surface, &rays, TILE) {
        None => {}
        Some(bins) => {
            assert!(!bins.unprojected().is_empty());
            assert_lists_complete("inside", surface, &rays);
        }
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

#[test]
fn queries_answer_from_a_list_as_from_the_bvh() {
    let mesh = rotor();
    let topology = common::closed_neighbours(&mesh);
    let surface = topology.surface();
    let camera = Camera::view(mesh.bounds(), 32, 32, 30.0, 20.0, 1.0);
    let rays = RayGenerator::new(&camera, 32, 32).expect("rays");
    let lists = lists(surface, &rays).expect("bins");
    let mut crossings = 0;
    for j in 0..32 {
        for i in 0..32 {
            let (o, d) = rays.ray(i, j);
            let faces = Some(RayFaces {
                origin: o,
                dir: d,
                list: &lists[(j * 32 + i) as usize],
            });
            let mut c = Counters::default();
            let mut t = 0.0;
            // Each possible crossing in turn, from just past the one before.
            for _ in 0..40 {
                // The same `t`; where two faces are reached at once, either may be named.
                let by_list = surface.next_crossing(faces, o, d, t, 1e3, &mut c);
                let by_bvh = surface.next_crossing(None, o, d, t, 1e3, &mut c);
                assert_eq!(
                    by_list.map(|x| x.0),
                    by_bvh.map(|x| x.0),
                    "pixel ({i}, {j}) from {t}"
                );
                let Some((tc, _)) = by_bvh else { break };
                // The exact crossings on either side, forwards and backwards.
                for (a, z) in [(t, tc + 0.05), (tc + 0.05, t)] {
                    let l = surface.first_face_crossing(faces, &mesh, o, d, a, z, &mut c);
                    let b = surface.first_face_crossing(None, &mesh, o, d, a, z, &mut c);
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

#[test]
fn a_render_with_lists_is_the_render_without() {
    let mesh = rotor();
    let topology = common::closed_neighbours(&mesh);
    let axis = cylvol::axis::detect(&mesh);
    for kind in [StructureKind::CylBvh, StructureKind::CartGrid] {
        let accel = Accel::build(&mesh, kind, &axis, &AccelParams::default()).expect("build");
        let volume = Volume::new(&mesh, &accel).expect("volume");
        let [lo, hi] = volume.scalar_range();
        let tf = TransferFunction::default_for_range(lo, hi, 0.6, 0.2);
        let mut options = RenderOptions::new(48, 40, 2.0 * default_step(&mesh));
        options.path = RenderPath::Fast;
        let renderer = Renderer::new(&volume, &tf, &options)
            .expect("renderer")
            .with_neighbours(&topology as &dyn Neighbours);
        let camera = Camera::view(mesh.bounds(), 48, 40, 30.0, 20.0, 1.0);
        let rays = RayGenerator::new(&camera, 48, 40).expect("rays");
        let (with, s_with) = renderer.render_rays(&rays, None).expect("render");
        let (without, s_without) = renderer
            .render_rays(&Unprojected(&rays), None)
            .expect("render");
        assert_eq!(with.rgba, without.rgba, "{kind:?}");
        assert_eq!(with.depth, without.depth, "{kind:?}");
        assert_eq!(s_with.samples_located, s_without.samples_located);
        assert!(s_without.surface_visits > 0);
        assert!(
            s_with.surface_visits < s_without.surface_visits,
            "{kind:?}: {} faces offered from lists, {} BVH visits",
            s_with.surface_visits,
            s_without.surface_visits
        );
    }
}
