//! The renderer's images and counters on a fixed set of scenes, against a committed baseline:
//! every structure, both paths, shading, gradient opacity, nearest interpolation, clipping
//! planes, the three blend modes, depth in and out, long steps (chords and gaps), whole steps,
//! the march's reach, neighbours with and without a boundary surface and none at all, rays
//! with and without a projection (the boundary faces sorted to the image or the surface's
//! BVH), a camera inside the mesh, a parallel projection, odd tiles, and the real meshes of
//! `tests/data/`. Each scene's image (colour and depth, as stored, bit for bit) is hashed and
//! kept with every [`RenderStats`] counter in `tests/render_baseline.json`; a change of the
//! renderer that is meant to change no pixel and no counter must leave them all equal.
//!
//! Rendering is deterministic whatever the number of threads (each pixel is computed alone,
//! the counters are integer sums): the test checks that first, on a few scenes, with pools
//! of one and of three threads.
//!
//! To write the baseline anew (only where a change of the images is intended and understood):
//! `CYLVOL_WRITE_RENDER_BASELINE=1 cargo test --release --test render_regression`.

mod common;

use std::collections::BTreeMap;

use cylvol::accel::{Accel, AccelParams, StructureKind};
use cylvol::datasets::{generate, Dataset};
use cylvol::io::ReadOptions;
use cylvol::mesh::topology::FaceNeighbours;
use cylvol::render::{
    default_step, face_neighbours, Blend, Camera, ClipPlanes, GradientOpacity, Image,
    Interpolation, NoNeighbours, RayGenerator, RaySource, RenderOptions, RenderPath, RenderStats,
    Renderer, Shading, Topology, TransferFunction, Volume,
};
use cylvol::Mesh;
use glam::DVec3;
use serde_json::{json, Value};

/// Image size of every scene.
const WIDTH: u32 = 40;
const HEIGHT: u32 = 30;

/// Where the baseline is kept.
fn baseline_path() -> std::path::PathBuf {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/render_baseline.json")
}

/// A mesh with its axis, its four structures and its face neighbours (with their boundary
/// surface), built once.
struct Setup {
    name: &'static str,
    mesh: Mesh,
    accels: Vec<Accel>,
    topology: Topology,
}

impl Setup {
    fn new(name: &'static str, mesh: Mesh) -> Setup {
        let axis = cylvol::axis::detect(&mesh);
        let params = AccelParams::default();
        let accels: Vec<Accel> = StructureKind::ALL
            .iter()
            .map(|&k| Accel::build(&mesh, k, &axis, &params).expect("structure"))
            .collect();
        let topology = face_neighbours(&mesh, &accels[2]);
        Setup {
            name,
            mesh,
            accels,
            topology,
        }
    }
}

fn load(file: &str) -> Mesh {
    cylvol::input::load(
        common::data(file).to_str().expect("a path"),
        &ReadOptions::default(),
    )
    .expect("a test mesh")
}

/// The rays of a camera without a projection: the renderer cannot sort the boundary faces to
/// the image and asks the boundary surface's BVH instead.
struct Unprojected(RayGenerator);

impl RaySource for Unprojected {
    fn size(&self) -> (u32, u32) {
        self.0.size()
    }
    fn ray(&self, i: u32, j: u32) -> (DVec3, DVec3) {
        self.0.ray(i, j)
    }
}

/// Which neighbours a scene walks.
#[derive(Clone, Copy)]
enum Walk {
    /// Welded, checked, with their boundary surface ([`face_neighbours`]).
    Topology,
    /// Built without welding seams: no boundary surface, complete only where closed.
    Plain,
    /// None.
    Nothing,
}

/// One scene: what differs from the default options, camera and transfer function.
#[derive(Clone)]
struct Scene {
    name: String,
    options: RenderOptions,
    camera: Camera,
    transfer: TransferFunction,
    walk: Walk,
    depth_in: Option<Vec<f32>>,
    unprojected: bool,
}

/// The default scene of a mesh and structure: the CLI's default transfer function, default
/// step and view, the given path.
fn base(setup: &Setup, kind: StructureKind, path: RenderPath) -> Scene {
    let field = cylvol::render::ScalarField::gather(&setup.mesh).expect("scalars");
    let [lo, hi] = field.range();
    let mut options = RenderOptions::new(WIDTH, HEIGHT, default_step(&setup.mesh));
    options.path = path;
    Scene {
        name: format!("{} {} {}", setup.name, kind.name(), path.name()),
        options,
        camera: Camera::view(setup.mesh.bounds(), WIDTH, HEIGHT, 30.0, 20.0, 1.0),
        transfer: TransferFunction::default_for_range(lo, hi, 0.8, 0.2),
        walk: Walk::Topology,
        depth_in: None,
        unprojected: false,
    }
}

/// The mesh's bounding box centre and diagonal.
fn centre_and_diagonal(mesh: &Mesh) -> (DVec3, f64) {
    let b = mesh.bounds();
    let lo = DVec3::new(b[0], b[2], b[4]);
    let hi = DVec3::new(b[1], b[3], b[5]);
    ((lo + hi) * 0.5, (hi - lo).length())
}

/// The variants rendered on top of the default scene (named by what they change).
fn variants(setup: &Setup, scene: &Scene) -> Vec<Scene> {
    let (centre, diagonal) = centre_and_diagonal(&setup.mesh);
    let [lo, hi] = {
        let f = cylvol::render::ScalarField::gather(&setup.mesh).expect("scalars");
        f.range()
    };
    let with = |what: &str, change: &dyn Fn(&mut Scene)| {
        let mut s = scene.clone();
        s.name = format!("{} / {what}", scene.name);
        change(&mut s);
        s
    };
    let eye_distance = (scene.camera.eye - centre).length();
    vec![
        with("shading", &|s| s.options.shading = Some(Shading::default())),
        with("gradient opacity, nearest", &|s| {
            s.options.gradient_opacity =
                Some(GradientOpacity::new(&[(0.0, 0.2), (hi - lo, 1.0)]).expect("ramp"));
            s.options.interpolation = Interpolation::Nearest;
            s.options.shading = Some(Shading::default());
        }),
        with("maximum", &|s| s.options.blend = Blend::Maximum),
        with("minimum", &|s| s.options.blend = Blend::Minimum),
        with("clip planes", &|s| {
            s.options.clip_planes = ClipPlanes::new(&[
                ClipPlanes::equation(centre, DVec3::new(0.3, -1.0, 0.2)),
                ClipPlanes::equation(centre + DVec3::Z * 0.2 * diagonal, -DVec3::Z),
            ])
            .expect("planes");
        }),
        with("depth in", &|s| {
            let d: Vec<f32> = (0..WIDTH * HEIGHT)
                .map(|k| match k % 4 {
                    0 => f32::INFINITY,
                    r => (eye_distance * (0.8 + 0.15 * r as f64)) as f32,
                })
                .collect();
            s.depth_in = Some(d);
        }),
        with("long step", &|s| s.options.step *= 6.0),
        with("whole steps", &|s| s.options.boundary_segments = false),
        with("march always", &|s| s.options.march_reach = f64::INFINITY),
        with("march never", &|s| s.options.march_reach = 0.0),
        with("plain neighbours", &|s| s.walk = Walk::Plain),
        with("no neighbours", &|s| s.walk = Walk::Nothing),
        with("unprojected", &|s| s.unprojected = true),
        with("inside", &|s| {
            // A wide view from within the mesh's box (in the mesh or in a hole of it).
            s.camera = Camera::perspective(
                centre + DVec3::new(0.13, 0.07, 0.05) * diagonal,
                centre - DVec3::new(0.2, 0.1, 0.3) * diagonal,
                DVec3::Z,
                80.0,
            )
            .expect("camera");
        }),
        with("parallel, tiles of 7", &|s| {
            let bounds = setup.mesh.bounds();
            s.camera = Camera::reset(bounds, WIDTH, HEIGHT, true).turned(-50.0, 35.0, 1.3);
            s.options.tile = 7;
        }),
        with("opaque, early termination", &|s| {
            s.transfer = TransferFunction::default_for_range(lo, hi, 1.0, 0.002);
            s.options.early_termination = 0.9;
            s.options.depth_opacity = 0.3;
        }),
        with("transparent everywhere", &|s| {
            s.transfer = TransferFunction::constant([1.0, 0.5, 0.2], 0.0, 1.0);
        }),
    ]
}

/// The scenes of one mesh: the default scene on every structure and path, and with
/// `all_variants` every variant of each.
fn scenes_of(setup: &Setup, all_variants: bool) -> Vec<(usize, Scene)> {
    let mut out = Vec::new();
    for (k, &kind) in StructureKind::ALL.iter().enumerate() {
        for path in [RenderPath::Paper, RenderPath::Fast] {
            let scene = base(setup, kind, path);
            if all_variants {
                out.extend(variants(setup, &scene).into_iter().map(|s| (k, s)));
            }
            out.push((k, scene));
        }
    }
    out
}

/// Renders a scene: its image and counters.
fn render(setup: &Setup, structure: usize, scene: &Scene) -> (Image, RenderStats) {
    let volume = Volume::new(&setup.mesh, &setup.accels[structure]).expect("volume");
    let renderer = Renderer::new(&volume, &scene.transfer, &scene.options).expect("renderer");
    let plain;
    let renderer = match scene.walk {
        Walk::Topology => renderer.with_topology(&setup.topology),
        Walk::Plain => {
            plain = FaceNeighbours::build(&setup.mesh);
            renderer.with_neighbours(&plain)
        }
        Walk::Nothing => renderer.with_neighbours(&NoNeighbours),
    };
    let rays = RayGenerator::new(&scene.camera, WIDTH, HEIGHT).expect("rays");
    let depth = scene.depth_in.as_deref();
    if scene.unprojected {
        renderer.render_rays(&Unprojected(rays), depth)
    } else {
        renderer.render_rays(&rays, depth)
    }
    .expect("render")
}

/// FNV-1a, 64 bits, over the image's colour and depth as stored (bit for bit).
fn image_hash(image: &Image) -> String {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    let mut eat = |x: f32| {
        for b in x.to_bits().to_le_bytes() {
            h ^= u64::from(b);
            h = h.wrapping_mul(0x0000_0100_0000_01b3);
        }
    };
    for px in &image.rgba {
        px.iter().for_each(|&v| eat(v));
    }
    image.depth.iter().for_each(|&v| eat(v));
    format!("{h:016x}")
}

fn record(image: &Image, stats: &RenderStats) -> Value {
    json!({ "image": image_hash(image), "stats": stats })
}

/// Every mesh of the test, built once, on one thread: the grids' builds sum the pieces'
/// extents in parallel, and a sum's rounding follows how the work was split, which can tip
/// a grid's resolution (the unit cube's lattice of cells does).
fn setups() -> Vec<(Setup, bool)> {
    rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .expect("pool")
        .install(all_setups)
}

/// [`setups`] on the calling thread's pool.
fn all_setups() -> Vec<(Setup, bool)> {
    vec![
        (
            Setup::new("pump-rotor", generate(Dataset::PumpRotor, 3000).unwrap()),
            true,
        ),
        (Setup::new("mixer", load("mixer.vtk")), true),
        (
            Setup::new("pump-inlet", generate(Dataset::PumpInlet, 2000).unwrap()),
            false,
        ),
        (
            Setup::new("lox-post", {
                // Its density is constant: the energy varies.
                let mut post = load("postxyz.bin");
                post.set_active_scalar("StagnationEnergy").expect("energy");
                post
            }),
            false,
        ),
        (Setup::new("combustor", load("combxyz.bin")), false),
        (Setup::new("amr-cube", load("hexa.vtk")), false),
    ]
}

#[test]
fn images_and_counters_match_the_baseline() {
    let setups = setups();
    // Deterministic whatever the threads, before the baseline is relied on.
    let (rotor, _) = &setups[0];
    for (structure, scene) in scenes_of(rotor, true).iter().step_by(7) {
        let in_pool = |threads: usize| {
            rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .expect("pool")
                .install(|| render(rotor, *structure, scene))
        };
        let (a, sa) = in_pool(1);
        let (b, sb) = in_pool(3);
        assert_eq!(image_hash(&a), image_hash(&b), "{}: threads", scene.name);
        assert_eq!(sa, sb, "{}: threads", scene.name);
    }
    let mut got = BTreeMap::new();
    for (setup, all_variants) in &setups {
        for (structure, scene) in scenes_of(setup, *all_variants) {
            let (image, stats) = render(setup, structure, &scene);
            assert!(
                got.insert(scene.name.clone(), record(&image, &stats))
                    .is_none(),
                "two scenes named {}",
                scene.name
            );
        }
    }
    let path = baseline_path();
    if std::env::var_os("CYLVOL_WRITE_RENDER_BASELINE").is_some() {
        let text = serde_json::to_string_pretty(&got).expect("json") + "\n";
        std::fs::write(&path, text).expect("write the baseline");
        return;
    }
    let text = std::fs::read_to_string(&path).expect("the baseline (see the module's doc)");
    let want: BTreeMap<String, Value> = serde_json::from_str(&text).expect("baseline json");
    let names = |m: &BTreeMap<String, Value>| m.keys().cloned().collect::<Vec<_>>();
    assert_eq!(names(&got), names(&want), "the scenes");
    let differ: Vec<String> = want
        .iter()
        .filter(|(name, w)| got.get(*name) != Some(*w))
        .map(|(name, w)| format!("{name}:\n  want {w}\n  got  {}", got[name]))
        .collect();
    assert!(
        differ.is_empty(),
        "{} of {} scenes differ from the baseline:\n{}",
        differ.len(),
        want.len(),
        differ.join("\n")
    );
}
