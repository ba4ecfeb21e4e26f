//! The error-bounded render ([`RenderOptions::max_error`]) against a converged reference, on
//! the meshes the tests carry and a small synthetic pump rotor, in three scenes: an oblique
//! view with the default transfer function, a clip plane through the mesh, and a sharp
//! transfer function (a narrow opaque band of the scalar range).
//!
//! The reference is the fixed-step render at 1/64 of the default step (1/128 of the mean cell
//! size), with boundary segments and without early termination: what every render converges
//! to as its samples get denser. Its own error is bounded per pixel by its difference from the
//! render at twice its step (which, the fixed step's error falling at least linearly, is at
//! least its error): the *uncertainty* of the reference there. Errors are per pixel, the
//! largest absolute difference of the four premultiplied RGBA channels, in 1/255 (the unit of
//! the setting).
//!
//! At `--max-error` 1, 2 and 4 every pixel is within the setting plus the reference's
//! uncertainty there, but for at most [`SILHOUETTE_SHARE`] of the pixels (rays that graze the
//! mesh's silhouette, where a crossing is found to within its own tolerance), and those
//! within twice that. A tighter setting never gives a larger mean error (beyond what the
//! reference resolves, its mean uncertainty), its largest is within the looser setting, and it
//! takes more samples (the tightest more refinements than the loosest). The largest error of
//! one pixel is not compared between settings: the settings place their samples differently,
//! and far below both settings one pixel's error goes either way.

mod common;

use cylvol::accel::{Accel, AccelParams, StructureKind};
use cylvol::datasets::{generate, Dataset};
use cylvol::io::ReadOptions;
use cylvol::render::{
    default_step, face_neighbours, Camera, ClipPlanes, RayGenerator, RenderOptions, RenderStats,
    Renderer, ScalarField, Topology, TransferFunction, Volume,
};
use cylvol::Mesh;
use glam::DVec3;

/// The image side.
const SIDE: u32 = 24;

/// The share of pixels that may exceed the setting (at most twice it): grazing rays.
const SILHOUETTE_SHARE: f64 = 0.005;

/// The settings checked, tightest first.
const SETTINGS: [f64; 3] = [1.0, 2.0, 4.0];

/// The reference's step as a fraction of the default step.
const REFERENCE_FRACTION: f64 = 1.0 / 64.0;

fn load(file: &str) -> Mesh {
    cylvol::input::load(
        common::data(file).to_str().expect("a path"),
        &ReadOptions::default(),
    )
    .expect("a test mesh")
}

/// A mesh with its structure and face neighbours.
struct Setup {
    name: &'static str,
    mesh: Mesh,
    accel: Accel,
    topology: Topology,
}

impl Setup {
    fn new(name: &'static str, mesh: Mesh) -> Setup {
        let axis = cylvol::axis::detect(&mesh);
        let accel = Accel::build(&mesh, StructureKind::CylBvh, &axis, &AccelParams::default())
            .expect("structure");
        let topology = face_neighbours(&mesh, &accel);
        Setup {
            name,
            mesh,
            accel,
            topology,
        }
    }
}

/// A scene: its transfer function, clipping planes and camera.
struct Scene {
    name: &'static str,
    transfer: TransferFunction,
    planes: ClipPlanes,
    camera: Camera,
}

fn scenes(setup: &Setup) -> Vec<Scene> {
    let [lo, hi] = ScalarField::gather(&setup.mesh).expect("scalars").range();
    let b = setup.mesh.bounds();
    let (min, max) = (DVec3::new(b[0], b[2], b[4]), DVec3::new(b[1], b[3], b[5]));
    let (centre, diagonal) = ((min + max) * 0.5, (max - min).length());
    let camera = Camera::view(b, SIDE, SIDE, 30.0, 20.0, 1.0);
    let unit = 0.05 * diagonal;
    // Laid over the values' 5th to 95th percentiles, so that a few outliers do not leave the
    // picture empty.
    let (_, mut values) = setup.mesh.drawn_scalars().expect("scalars");
    values.sort_by(f64::total_cmp);
    let quantile = |q: f64| values[((values.len() - 1) as f64 * q) as usize];
    let (q05, q95) = (quantile(0.05), quantile(0.95));
    let at = |f: f64| q05 + (q95 - q05) * f;
    let default = TransferFunction {
        opacity: vec![(lo, 0.0), (at(0.0), 0.0), (at(1.0), 0.5), (hi, 0.5)],
        ..TransferFunction::default_for_range(lo, hi, 0.5, unit)
    };
    let band = TransferFunction {
        opacity: vec![
            (lo, 0.0),
            (at(0.48), 0.0),
            (at(0.5), 0.95),
            (at(0.52), 0.0),
            (hi, 0.0),
        ],
        ..default.clone()
    };
    let plane = ClipPlanes::equation(centre, DVec3::new(1.0, 0.3, 0.2));
    vec![
        Scene {
            name: "oblique",
            transfer: default.clone(),
            planes: ClipPlanes::NONE,
            camera,
        },
        Scene {
            name: "clip plane",
            transfer: default,
            planes: ClipPlanes::new(&[plane]).expect("a plane"),
            camera,
        },
        Scene {
            name: "narrow band",
            transfer: band,
            planes: ClipPlanes::NONE,
            camera,
        },
    ]
}

/// The image of `scene` with `options` (premultiplied RGBA in `f64`) and the work done.
fn render(setup: &Setup, scene: &Scene, options: &RenderOptions) -> (Vec<[f64; 4]>, RenderStats) {
    let volume = Volume::new(&setup.mesh, &setup.accel).expect("volume");
    let options = RenderOptions {
        clip_planes: scene.planes,
        ..*options
    };
    let renderer = Renderer::new(&volume, &scene.transfer, &options)
        .expect("renderer")
        .with_topology(&setup.topology);
    let rays = RayGenerator::new(&scene.camera, SIDE, SIDE).expect("rays");
    let mut stats = RenderStats::default();
    let mut image = Vec::with_capacity((SIDE * SIDE) as usize);
    for j in 0..SIDE {
        for i in 0..SIDE {
            let (o, d) = rays.ray(i, j);
            image.push(renderer.cast(o, d, f64::INFINITY, &mut stats).rgba);
        }
    }
    (image, stats)
}

/// Per pixel, the largest channel difference in 1/255.
fn errors(image: &[[f64; 4]], reference: &[[f64; 4]]) -> Vec<f64> {
    image
        .iter()
        .zip(reference)
        .map(|(a, b)| {
            (0..4)
                .map(|k| (a[k] - b[k]).abs() * 255.0)
                .fold(0.0, f64::max)
        })
        .collect()
}

/// What one setting achieved.
#[derive(Debug)]
struct Achieved {
    max_error: f64,
    largest: f64,
    mean: f64,
    beyond: usize,
    far_beyond: usize,
    samples: u64,
    refined: u64,
}

fn check_mesh(setup: &Setup) {
    let step = default_step(&setup.mesh);
    for scene in scenes(setup) {
        let mut reference_options = RenderOptions::new(SIDE, SIDE, step * REFERENCE_FRACTION);
        reference_options.early_termination = f64::INFINITY;
        let (reference, _) = render(setup, &scene, &reference_options);
        reference_options.step *= 2.0;
        let (coarser, _) = render(setup, &scene, &reference_options);
        let uncertainty = errors(&coarser, &reference);
        let largest_uncertainty = uncertainty.iter().copied().fold(0.0, f64::max);
        let mean_uncertainty = uncertainty.iter().sum::<f64>() / uncertainty.len() as f64;
        let visible = reference.iter().filter(|p| p[3] > 0.02).count();
        assert!(
            visible * 50 > reference.len(),
            "{} / {}: {visible} pixels show anything",
            setup.name,
            scene.name
        );
        let achieved: Vec<Achieved> = SETTINGS
            .iter()
            .map(|&e| {
                let mut options = RenderOptions::new(SIDE, SIDE, step);
                options.max_error = Some(e);
                let (image, stats) = render(setup, &scene, &options);
                let errors = errors(&image, &reference);
                let beyond = |bound: f64| {
                    errors
                        .iter()
                        .zip(&uncertainty)
                        .filter(|&(&x, &u)| x > bound + u)
                        .count()
                };
                Achieved {
                    max_error: e,
                    largest: errors.iter().copied().fold(0.0, f64::max),
                    mean: errors.iter().sum::<f64>() / errors.len() as f64,
                    beyond: beyond(e),
                    far_beyond: beyond(2.0 * e),
                    samples: stats.samples,
                    refined: stats.refined_samples,
                }
            })
            .collect();
        let what = format!(
            "{} / {}: reference uncertainty largest {largest_uncertainty:.4}, mean \
             {mean_uncertainty:.5}; {achieved:#?}",
            setup.name, scene.name
        );
        eprintln!("{what}");
        let allowed = (SILHOUETTE_SHARE * reference.len() as f64).floor() as usize;
        for a in &achieved {
            assert!(a.beyond <= allowed, "{what}");
            assert_eq!(a.far_beyond, 0, "{what}");
        }
        for w in achieved.windows(2) {
            let (tight, loose) = (&w[0], &w[1]);
            assert!(tight.mean <= loose.mean + mean_uncertainty, "{what}");
            assert!(
                tight.largest <= loose.max_error + largest_uncertainty,
                "{what}"
            );
            assert!(tight.samples > loose.samples, "{what}");
        }
        let (tightest, loosest) = (&achieved[0], &achieved[achieved.len() - 1]);
        assert!(tightest.refined > loosest.refined, "{what}");
    }
}

#[test]
fn pump_rotor_meets_each_setting() {
    check_mesh(&Setup::new(
        "pump-rotor",
        generate(Dataset::PumpRotor, 1500).expect("rotor"),
    ));
}

#[test]
fn mixer_meets_each_setting() {
    check_mesh(&Setup::new("mixer", load("mixer.vtk")));
}

#[test]
fn lox_post_meets_each_setting() {
    let mut post = load("postxyz.bin");
    // Its density is constant: the energy varies.
    post.set_active_scalar("StagnationEnergy").expect("energy");
    check_mesh(&Setup::new("lox-post", post));
}

#[test]
fn combustor_meets_each_setting() {
    check_mesh(&Setup::new("combustor", load("combxyz.bin")));
}

#[test]
fn amr_cube_meets_each_setting() {
    check_mesh(&Setup::new("amr-cube", load("hexa.vtk")));
}
