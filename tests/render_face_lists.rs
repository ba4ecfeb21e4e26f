//! The boundary faces sorted to the image: a fast render is the same image with the faces
//! each ray meets listed per ray (rays with a projection) as without the lists (rays without
//! one, whose queries traverse the boundary surface's BVH), with fewer surface visits (the
//! counter). The lists themselves are tested beside the code that makes them.

mod common;

use cylvol::accel::{Accel, AccelParams, StructureKind};
use cylvol::datasets::{generate, Dataset};
use cylvol::render::{
    default_step, Camera, RayGenerator, RaySource, RenderOptions, RenderPath, Renderer,
    TransferFunction, Volume,
};
use glam::DVec3;

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

#[test]
fn a_render_with_lists_is_the_render_without() {
    let mesh = generate(Dataset::PumpRotor, 12_000).expect("rotor");
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
            .with_topology(&topology);
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
