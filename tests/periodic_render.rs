//! The wheel drawn from one periodic sector: the mixer's 90° sector, drawn as four copies from
//! its own structure and topology, against the same wheel replicated as one mesh
//! (`periodic::replicate`, which VTK's angular periodic filter matches) — every structure, both
//! paths, shading on and off, several views; a constant medium seen through the interfaces
//! between copies gives the exact Beer–Lambert transmittance; a range of copies draws only
//! those.

mod common;

use cylvol::accel::{Accel, AccelParams, StructureKind};
use cylvol::axis::periodic::{self, Periodicity};
use cylvol::axis::Axis;
use cylvol::render::{
    default_step, face_neighbours, Camera, Copies, Image, RenderOptions, RenderPath, Renderer,
    Shading, TransferFunction, Volume,
};
use cylvol::{DataArray, Mesh, MeshParts};

fn load(name: &str) -> Mesh {
    let mut mesh = cylvol::io::read_file(&common::data(name), &Default::default()).unwrap();
    mesh.set_active_scalar("p").unwrap();
    mesh
}

/// The largest and mean per-pixel difference of two images (premultiplied RGBA, in /255),
/// and the fraction of pixels within 8/255.
fn difference(a: &Image, b: &Image) -> (f64, f64, f64) {
    let mut worst = 0.0f64;
    let mut sum = 0.0;
    let mut within = 0usize;
    for (p, q) in a.rgba.iter().zip(&b.rgba) {
        let d = (0..4)
            .map(|c| (f64::from(p[c]) - f64::from(q[c])).abs() * 255.0)
            .fold(0.0, f64::max);
        worst = worst.max(d);
        sum += d;
        within += usize::from(d <= 8.0);
    }
    let n = a.rgba.len() as f64;
    (worst, sum / n, within as f64 / n)
}

struct Scene<'m> {
    mesh: &'m Mesh,
    accel: Accel,
}

impl<'m> Scene<'m> {
    fn new(mesh: &'m Mesh, kind: StructureKind, axis: &Axis) -> Scene<'m> {
        let accel = Accel::build(mesh, kind, axis, &AccelParams::default()).unwrap();
        Scene { mesh, accel }
    }

    fn render(
        &self,
        transfer: &TransferFunction,
        options: &RenderOptions,
        camera: &Camera,
        copies: Option<Copies>,
    ) -> Image {
        let volume = Volume::new(self.mesh, &self.accel).unwrap();
        let mut renderer = Renderer::new(&volume, transfer, options).unwrap();
        let topology = face_neighbours(self.mesh, &self.accel);
        let topology = match &copies {
            Some(c) => topology.with_periodic_sides(self.mesh, c.periodicity()).0,
            None => topology,
        };
        if options.path == RenderPath::Fast {
            renderer = renderer.with_topology(&topology);
        }
        if let Some(c) = copies {
            renderer = renderer.with_copies(c).unwrap();
        }
        renderer.render(camera, None).unwrap().0
    }
}

fn mixer_wheel() -> (Mesh, Periodicity, Mesh) {
    let sector = load("mixer.vtk");
    let found = periodic::detect(&sector, &cylvol::axis::detect(&sector)).unwrap();
    let wheel = periodic::replicate(&sector, &found, (0, found.copies)).unwrap();
    (sector, found, wheel)
}

#[test]
fn four_copies_of_the_mixer_draw_the_replicated_wheel() {
    let (sector, found, wheel) = mixer_wheel();
    let axis = cylvol::axis::detect(&sector);
    let copies = Copies::new(&sector, found, None).unwrap();
    let [lo, hi] = [-44.0, 75.0];
    let b = copies.bounds();
    let diagonal = ((b[1] - b[0]).powi(2) + (b[3] - b[2]).powi(2) + (b[5] - b[4]).powi(2)).sqrt();
    let transfer = TransferFunction::default_for_range(lo, hi, 0.8, diagonal / 100.0);
    let size = 96;
    for kind in StructureKind::ALL {
        let (s, w) = (
            Scene::new(&sector, kind, &axis),
            Scene::new(&wheel, kind, &axis),
        );
        for path in [RenderPath::Fast, RenderPath::Paper] {
            for (shade, view) in [(false, [20.0, 40.0, 1.0]), (true, [75.0, -10.0, 1.6])] {
                if path == RenderPath::Paper && shade {
                    continue;
                }
                let mut options = RenderOptions::new(size, size, default_step(&sector));
                options.path = path;
                options.shading = shade.then(Shading::default);
                let camera = Camera::view(b, size, size, view[0], view[1], view[2]);
                let from_sector = s.render(&transfer, &options, &camera, Some(copies));
                let replicated = w.render(&transfer, &options, &camera, None);
                let lit = replicated.rgba.iter().filter(|p| p[3] > 0.05).count();
                assert!(
                    lit > size as usize * size as usize / 4,
                    "{kind} {path:?}: {lit}"
                );
                let (worst, mean, within) = difference(&from_sector, &replicated);
                assert!(
                    mean <= 0.5 && within >= 0.999,
                    "{kind} {path:?} shade {shade}: mean {mean:.3}/255, {:.3} % within 8/255, \
                     worst {worst:.1}/255",
                    within * 100.0
                );
            }
        }
    }
}

/// A quarter annulus about z of constant density, r 1–2, h 0–1, as the tests' sector builder
/// makes it.
fn constant_quarter() -> Mesh {
    let frame =
        cylvol::geometry::cylindrical::CylFrame::new(glam::DVec3::ZERO, glam::DVec3::Z).unwrap();
    let mesh = common::sector(
        &frame,
        [1.0, 2.0],
        [0.0, std::f64::consts::FRAC_PI_2],
        1.0,
        [3, 6, 2],
        false,
    );
    let mut parts: MeshParts = mesh.into_parts();
    parts.point_data = vec![DataArray::scalar("rho", vec![1.0; parts.points.len()])];
    parts.cell_data.clear();
    Mesh::from_parts(parts).unwrap()
}

#[test]
fn a_constant_medium_through_the_copies_is_exact() {
    use glam::DVec3;
    let sector = constant_quarter();
    let found = periodic::detect(&sector, &Axis::Z).unwrap();
    assert_eq!(found.copies, 4);
    let copies = Copies::new(&sector, found, None).unwrap();
    // Opacity 0.4 per half unit of length, read as an attenuation coefficient.
    let (alpha, unit) = (0.4, 0.5);
    let attenuation = -(1.0f64 - alpha).ln() / unit;
    let transfer = TransferFunction::constant([1.0; 3], alpha, unit);
    for kind in StructureKind::ALL {
        let accel = Accel::build(&sector, kind, &Axis::Z, &AccelParams::default()).unwrap();
        let volume = Volume::new(&sector, &accel).unwrap();
        let topology = face_neighbours(&sector, &accel)
            .with_periodic_sides(&sector, copies.periodicity())
            .0;
        for path in [RenderPath::Fast, RenderPath::Paper] {
            let mut options = RenderOptions::new(1, 1, 0.37);
            options.path = path;
            options.early_termination = 1.0;
            // The boundary surface makes every crossing exact, on either path.
            let renderer = Renderer::new(&volume, &transfer, &options)
                .unwrap()
                .with_copies(copies)
                .unwrap()
                .with_topology(&topology);
            // Rays across many copies, along an interface plane (x = 0), through the axis
            // where all copies meet, grazing the inner radius, and seeded ones.
            let mut rng = common::Rng::new(0x5EC7);
            let seeded = (0..60).map(|_| {
                let mut point =
                    || DVec3::new(rng.unit() * 4.0 - 2.0, rng.unit() * 4.0 - 2.0, rng.unit());
                let (a, b) = (point() * 2.0, point());
                (a, b - a)
            });
            let rays = [
                (DVec3::new(-3.0, 0.3, 0.5), DVec3::new(1.0, 0.05, 0.0)),
                (DVec3::new(-3.0, 1.5, 0.4), DVec3::X),
                (DVec3::new(0.0, -3.0, 0.5), DVec3::Y),
                (DVec3::new(-3.0, -3.0, 0.2), DVec3::new(1.0, 1.0, 0.1)),
                (DVec3::new(-3.0, 1.0, 0.6), DVec3::new(1.0, 0.0, 0.02)),
                (DVec3::new(2.5, 2.5, -1.0), DVec3::new(-0.6, -0.7, 0.9)),
            ];
            for (o, d) in rays.into_iter().chain(seeded) {
                let d = d.normalize();
                let length = exact_length_in_annulus(o, d);
                let mut stats = Default::default();
                let r = renderer.cast(o, d, f64::INFINITY, &mut stats);
                let expected = 1.0 - (-attenuation * length).exp();
                assert!(
                    (r.rgba[3] - expected).abs() < 1e-9,
                    "{kind} {path:?} {o} {d}: opacity {} against {expected} (length {length})",
                    r.rgba[3]
                );
            }
        }
    }
}

/// The length of the ray `o + t d` (t ≥ 0) inside the wheel of [`constant_quarter`]'s four
/// copies, exactly: between the regular 24-gons of radii 1 and 2 about z (its faces are flat
/// between the sector's points, six per quarter) and within 0 ≤ z ≤ 1.
fn exact_length_in_annulus(o: glam::DVec3, d: glam::DVec3) -> f64 {
    let (z0, z1) = if d.z == 0.0 {
        if (0.0..=1.0).contains(&o.z) {
            (f64::NEG_INFINITY, f64::INFINITY)
        } else {
            return 0.0;
        }
    } else {
        let (p, q) = (-o.z / d.z, (1.0 - o.z) / d.z);
        (p.min(q), p.max(q))
    };
    let inside = |r: f64| -> (f64, f64) {
        // The 24-gon as 24 half-planes n · x <= r cos(π/24), n at the edges' middles.
        let (mut t0, mut t1) = (z0.max(0.0), z1);
        let apothem = r * (std::f64::consts::PI / 24.0).cos();
        for k in 0..24 {
            let a = (f64::from(k) + 0.5) * std::f64::consts::TAU / 24.0;
            let n = glam::DVec3::new(a.cos(), a.sin(), 0.0);
            let (no, nd) = (n.dot(o), n.dot(d));
            if nd == 0.0 {
                if no > apothem {
                    return (0.0, 0.0);
                }
            } else if nd > 0.0 {
                t1 = t1.min((apothem - no) / nd);
            } else {
                t0 = t0.max((apothem - no) / nd);
            }
        }
        (t0, t1.max(t0))
    };
    let (a0, a1) = inside(2.0);
    let (b0, b1) = inside(1.0);
    (a1 - a0) - (b1.min(a1) - b0.max(a0)).max(0.0)
}

#[test]
fn copy_ranges_draw_only_their_copies() {
    let (sector, found, _) = mixer_wheel();
    assert!(Copies::new(&sector, found, Some((0, 0))).is_err());
    assert!(Copies::new(&sector, found, Some((3, 5))).is_err());
    let three = Copies::new(&sector, found, Some((0, 3))).unwrap();
    assert_eq!(three.count(), 3);
    let axis = cylvol::axis::detect(&sector);
    let accel = Accel::build(
        &sector,
        StructureKind::CylBvh,
        &axis,
        &AccelParams::default(),
    )
    .unwrap();
    // Three quarters drawn: a ray through the missing quarter only sees nothing.
    let volume = Volume::new(&sector, &accel).unwrap();
    let transfer = TransferFunction::default_for_range(-44.0, 75.0, 1.0, 0.01);
    let options = RenderOptions::new(1, 1, default_step(&sector));
    let topology = face_neighbours(&sector, &accel)
        .with_periodic_sides(&sector, &found)
        .0;
    let renderer = Renderer::new(&volume, &transfer, &options)
        .unwrap()
        .with_topology(&topology);
    let all = renderer
        .with_copies(Copies::new(&sector, found, None).unwrap())
        .unwrap();
    let mut stats = Default::default();
    let frame = found.frame();
    // Along the axis direction, at 45° + k·90°: copy k's middle.
    let through = |k: u32| {
        let angle = found.start + (f64::from(k) + 0.5) * found.pitch();
        let p = frame.from_cylindrical(0.05, angle, -1.0);
        (p, frame.axis)
    };
    let (o, d) = through(3);
    assert!(all.cast(o, d, f64::INFINITY, &mut stats).rgba[3] > 0.01);
    let renderer = Renderer::new(&volume, &transfer, &options)
        .unwrap()
        .with_topology(&topology)
        .with_copies(three)
        .unwrap();
    assert_eq!(renderer.cast(o, d, f64::INFINITY, &mut stats).rgba[3], 0.0);
    let (o, d) = through(1);
    assert!(renderer.cast(o, d, f64::INFINITY, &mut stats).rgba[3] > 0.01);
}

/// A vector's component turns with the copies, as the replicated wheel's vectors were turned:
/// the copies' range is the wheel's; at the default step the copies' image is as close to the
/// converged one (the replicated wheel at an eighth of the step) as the replicated wheel's
/// own (where the samples fall differs, and this field's error at that step is up to 20/255
/// either way), and at the fine step the two are the same image. A magnitude keeps the
/// sector's range.
#[test]
fn a_vector_component_turns_with_the_copies() {
    let (mut sector, found, mut wheel) = mixer_wheel();
    let axis = cylvol::axis::detect(&sector);
    let copies = Copies::new(&sector, found, None).unwrap();
    for name in ["U", "U[0]", "point:U[1]"] {
        sector.set_active_scalar(name).unwrap();
        wheel.set_active_scalar(name).unwrap();
        let kind = StructureKind::CylBvh;
        let (s, w) = (
            Scene::new(&sector, kind, &axis),
            Scene::new(&wheel, kind, &axis),
        );
        let sector_volume = Volume::new(&sector, &s.accel).unwrap();
        let wheel_volume = Volume::new(&wheel, &w.accel).unwrap();
        let range = copies.scalar_range(&sector_volume).unwrap();
        let expected = wheel_volume.scalar_range();
        assert!(
            (range[0] - expected[0]).abs() < 1e-9 && (range[1] - expected[1]).abs() < 1e-9,
            "{name}: copies' range {range:?}, the wheel's {expected:?}"
        );
        if name == "U" {
            assert_eq!(range, sector_volume.scalar_range());
        } else {
            assert_ne!(range, sector_volume.scalar_range(), "{name}");
        }
        let b = copies.bounds();
        let diagonal =
            ((b[1] - b[0]).powi(2) + (b[3] - b[2]).powi(2) + (b[5] - b[4]).powi(2)).sqrt();
        let transfer =
            TransferFunction::default_for_range(range[0], range[1], 0.8, diagonal / 100.0);
        let size = 64;
        let camera = Camera::view(b, size, size, 30.0, 50.0, 1.0);
        for path in [RenderPath::Fast, RenderPath::Paper] {
            let options = |fraction: f64| {
                let mut o = RenderOptions::new(size, size, default_step(&sector) * fraction);
                o.path = path;
                o
            };
            let reference = w.render(&transfer, &options(0.125), &camera, None);
            let fine = s.render(&transfer, &options(0.125), &camera, Some(copies));
            let (worst, mean, _) = difference(&fine, &reference);
            assert!(
                worst <= 1.0,
                "{name} {path:?}, fine step: worst {worst:.2}/255, mean {mean:.4}/255"
            );
            let from_sector = s.render(&transfer, &options(1.0), &camera, Some(copies));
            let replicated = w.render(&transfer, &options(1.0), &camera, None);
            let (_, mean_copies, within_copies) = difference(&from_sector, &reference);
            let (_, mean_wheel, within_wheel) = difference(&replicated, &reference);
            assert!(
                mean_copies <= mean_wheel * 1.05 + 0.01 && within_copies >= within_wheel - 0.001,
                "{name} {path:?}: the copies' error mean {mean_copies:.3}/255 with {:.2} % \
                 within 8/255, the replicated wheel's {mean_wheel:.3}/255 with {:.2} %",
                within_copies * 100.0,
                within_wheel * 100.0
            );
        }
    }
}
