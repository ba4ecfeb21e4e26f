//! The renderer's VTK-style options: nearest interpolation (a corner's value at every sample,
//! so a two-valued field shows two colours only) and gradient opacity (a factor of the
//! gradient magnitude on the opacity per unit distance; gradients evaluated only when it or
//! shading is on; zero below a threshold hides a constant volume; one everywhere changes
//! nothing; a constant factor equals scaling the opacity per unit distance) and clipping
//! planes (a plane that keeps the mesh changes nothing, one that keeps none of it samples
//! nothing; `tests/render.rs` checks the exact transmittance of rays that planes cut).

use cylvol::accel::{Accel, AccelParams, StructureKind};
use cylvol::axis::Axis;
use cylvol::io::structured::hexahedra;
use cylvol::render::{
    Blend, Camera, ClipPlanes, GradientOpacity, Image, Interpolation, RenderOptions, RenderPath,
    RenderStats, Renderer, TransferFunction, Volume, DEFAULT_MARCH_REACH,
};
use cylvol::{CellKind, DataArray, Mesh, MeshParts};
use glam::DVec3;

const PATHS: [RenderPath; 2] = [RenderPath::Paper, RenderPath::Fast];

/// The unit cube as `n³` slightly sheared cells with the point scalar `field(point, (i, j, k))`
/// (or the cell scalar `field(centre, (i, j, k))` with `cell_data`).
fn cube(n: usize, cell_data: bool, field: impl Fn(DVec3, [usize; 3]) -> f64) -> Mesh {
    let m = n + 1;
    let mut points = Vec::with_capacity(m * m * m);
    let mut ids = Vec::with_capacity(m * m * m);
    for k in 0..m {
        for j in 0..m {
            for i in 0..m {
                let p = DVec3::new(i as f64, j as f64, k as f64) / n as f64;
                points.push(p + DVec3::new(0.1 * p.z, 0.05 * p.x, 0.0));
                ids.push([i, j, k]);
            }
        }
    }
    let cells = hexahedra([m, m, m], &points);
    let (point_data, cell_data) = if cell_data {
        let values = (0..n * n * n)
            .map(|c| {
                let ijk = [c % n, (c / n) % n, c / (n * n)];
                let centre = DVec3::new(ijk[0] as f64, ijk[1] as f64, ijk[2] as f64) + 0.5;
                field(centre / n as f64, ijk)
            })
            .collect();
        (vec![], vec![DataArray::scalar("f", values)])
    } else {
        let values = points
            .iter()
            .zip(&ids)
            .map(|(&p, &i)| field(p, i))
            .collect();
        (vec![DataArray::scalar("f", values)], vec![])
    };
    Mesh::from_parts(MeshParts {
        kinds: vec![CellKind::Hexahedron; cells.len()],
        cells,
        points,
        point_data,
        cell_data,
    })
    .expect("valid cube")
}

/// The structure `kind` of `mesh` with the default parameters, about the z axis.
fn build(mesh: &Mesh, kind: StructureKind) -> Accel {
    Accel::build(mesh, kind, &Axis::Z, &AccelParams::default()).expect("build")
}

fn render(
    mesh: &Mesh,
    kind: StructureKind,
    tf: &TransferFunction,
    set: impl Fn(&mut RenderOptions),
) -> (Image, RenderStats) {
    let accel = build(mesh, kind);
    let volume = Volume::new(mesh, &accel).expect("volume");
    let neighbours = cylvol::render::face_neighbours(mesh, &accel);
    let mut options = RenderOptions::new(24, 24, 0.03);
    set(&mut options);
    let renderer = Renderer::new(&volume, tf, &options)
        .expect("renderer")
        .with_topology(&neighbours);
    let camera = Camera::view(mesh.bounds(), 24, 24, 30.0, 25.0, 1.0);
    renderer.render(&camera, None).expect("render")
}

/// A checkerboard of 0 and 1 on the points.
fn two_valued(n: usize) -> Mesh {
    cube(n, false, |_, [i, j, k]| ((i + j + k) % 2) as f64)
}

#[test]
fn nearest_takes_a_corner_value_at_every_sample() {
    let mesh = two_valued(6);
    // Red at 0, blue at 1, green only in between: premultiplied mixtures of red and blue
    // have no green at all.
    let colours = TransferFunction {
        color: vec![
            (0.0, [1.0, 0.0, 0.0]),
            (0.5, [0.0, 1.0, 0.0]),
            (1.0, [0.0, 0.0, 1.0]),
        ],
        opacity: vec![(0.0, 0.5)],
        unit_distance: 0.1,
    };
    // Opaque only strictly between the two values: nothing to see at the corners.
    let between = TransferFunction {
        color: vec![(0.0, [1.0; 3])],
        opacity: vec![(0.0, 0.0), (0.5, 0.8), (1.0, 0.0)],
        unit_distance: 0.1,
    };
    for kind in [StructureKind::CartBvh, StructureKind::CylGrid] {
        for path in PATHS {
            let nearest = |o: &mut RenderOptions| {
                o.path = path;
                o.interpolation = Interpolation::Nearest;
            };
            let linear = |o: &mut RenderOptions| o.path = path;
            let (img, stats) = render(&mesh, kind, &colours, nearest);
            assert!(stats.samples_located > 1000, "{stats:?}");
            assert!(img.rgba.iter().any(|p| p[0] > 0.05) && img.rgba.iter().any(|p| p[2] > 0.05));
            assert!(
                img.rgba.iter().all(|p| p[1] == 0.0),
                "{kind} {}: nearest shows a value between the corners'",
                path.name()
            );
            let (img, _) = render(&mesh, kind, &colours, linear);
            assert!(img.rgba.iter().any(|p| p[1] > 0.05), "linear blends");
            let (img, stats) = render(&mesh, kind, &between, nearest);
            assert!(stats.samples_located > 1000);
            assert!(
                img.rgba.iter().all(|p| p[3] == 0.0),
                "{kind} {}",
                path.name()
            );
            let (img, _) = render(&mesh, kind, &between, linear);
            assert!(img.rgba.iter().any(|p| p[3] > 0.2));
        }
    }
}

#[test]
fn nearest_changes_nothing_for_cell_data() {
    let mesh = cube(5, true, |c, _| c.x + 2.0 * c.y * c.z);
    let tf = TransferFunction::default_for_range(0.0, 3.0, 0.6, 0.2);
    for path in PATHS {
        let (a, _) = render(&mesh, StructureKind::CylBvh, &tf, |o| o.path = path);
        let (b, _) = render(&mesh, StructureKind::CylBvh, &tf, |o| {
            o.path = path;
            o.interpolation = Interpolation::Nearest;
        });
        assert!(a.rgba.iter().any(|p| p[3] > 0.2));
        assert_eq!(a.rgba, b.rgba);
        assert_eq!(a.depth, b.depth);
    }
}

fn smooth(n: usize) -> Mesh {
    cube(n, false, |p, _| p.x * p.x + p.y + 0.5 * p.z)
}

#[test]
fn gradients_only_with_shading_or_gradient_opacity() {
    let mesh = smooth(6);
    let tf = TransferFunction::default_for_range(0.0, 2.6, 0.6, 0.2);
    let half = GradientOpacity::new(&[(0.0, 0.2), (3.0, 0.9)]).expect("function");
    for path in PATHS {
        let (plain, off) = render(&mesh, StructureKind::CartGrid, &tf, |o| o.path = path);
        assert_eq!(off.gradient_evaluations, 0);
        let (faded, on) = render(&mesh, StructureKind::CartGrid, &tf, |o| {
            o.path = path;
            o.gradient_opacity = Some(half);
        });
        assert!(on.gradient_evaluations > 0);
        assert!(on.gradient_evaluations <= on.samples_located);
        // The factor is below one everywhere: every pixel is at most as opaque, some less.
        for (p, q) in plain.rgba.iter().zip(&faded.rgba) {
            assert!(q[3] <= p[3] + 1e-12);
        }
        assert!(plain.max_abs_difference(&faded) > 1e-2);
    }
}

#[test]
fn gradient_opacity_zero_below_a_threshold_hides_a_constant_volume() {
    let mesh = cube(5, false, |_, _| 3.0);
    let tf = TransferFunction::constant([1.0, 0.6, 0.2], 0.4, 0.1);
    let edges = GradientOpacity::new(&[(0.0, 0.0), (0.1, 0.0), (0.2, 1.0)]).expect("function");
    for path in PATHS {
        let (img, stats) = render(&mesh, StructureKind::CylBvh, &tf, |o| o.path = path);
        assert!(img.rgba.iter().any(|p| p[3] > 0.5), "visible without it");
        assert_eq!(stats.gradient_evaluations, 0);
        let (img, stats) = render(&mesh, StructureKind::CylBvh, &tf, |o| {
            o.path = path;
            o.gradient_opacity = Some(edges);
        });
        assert!(stats.gradient_evaluations > 1000, "{stats:?}");
        assert!(img.rgba.iter().all(|p| *p == [0.0; 4]), "{}", path.name());
        assert!(img.depth.iter().all(|d| d.is_infinite()));
    }
}

#[test]
fn gradient_opacity_one_everywhere_changes_nothing() {
    let mesh = smooth(6);
    let tf = TransferFunction::default_for_range(0.0, 2.6, 0.6, 0.2);
    let one = GradientOpacity::constant(1.0).expect("function");
    for path in PATHS {
        let (a, sa) = render(&mesh, StructureKind::CylBvh, &tf, |o| o.path = path);
        let (b, sb) = render(&mesh, StructureKind::CylBvh, &tf, |o| {
            o.path = path;
            o.gradient_opacity = Some(one);
        });
        assert_eq!(a.rgba, b.rgba);
        assert_eq!(a.depth, b.depth);
        assert!(sb.gradient_evaluations > 0);
        assert_eq!(
            RenderStats {
                gradient_evaluations: 0,
                ..sb
            },
            sa
        );
    }
}

/// The factor applies to the opacity per unit distance, before the step correction: a
/// constant factor `g` gives the image of the opacity `g α` per unit distance, at any step.
#[test]
fn a_constant_factor_scales_the_opacity_per_unit_distance() {
    let mesh = smooth(5);
    let colour = vec![(0.0, [0.2, 0.5, 0.9]), (2.6, [0.9, 0.4, 0.1])];
    let tf = |alpha: f64| TransferFunction {
        color: colour.clone(),
        opacity: vec![(0.0, alpha)],
        unit_distance: 0.1,
    };
    let g = GradientOpacity::constant(0.25).expect("function");
    for step in [0.03, 0.011] {
        let (a, _) = render(&mesh, StructureKind::CartBvh, &tf(0.8), |o| {
            o.step = step;
            o.gradient_opacity = Some(g);
        });
        let (b, _) = render(&mesh, StructureKind::CartBvh, &tf(0.2), |o| o.step = step);
        assert!(b.rgba.iter().any(|p| p[3] > 0.3));
        let diff = a.max_abs_difference(&b);
        assert!(diff < 1e-6, "step {step}: {diff}");
    }
}

#[test]
fn clipping_planes_keep_all_or_nothing_of_the_mesh_as_they_say() {
    let mesh = smooth(5);
    let tf = TransferFunction::default_for_range(0.0, 2.6, 0.6, 0.2);
    let plane =
        |x: f64| ClipPlanes::new(&[ClipPlanes::equation(DVec3::new(x, 0.0, 0.0), DVec3::X)]);
    for kind in StructureKind::ALL {
        for path in PATHS {
            let (plain, sp) = render(&mesh, kind, &tf, |o| o.path = path);
            assert!(plain.rgba.iter().any(|p| p[3] > 0.3));
            // x ≥ −1 holds the whole (sheared) cube: the same image and work.
            let (all, sa) = render(&mesh, kind, &tf, |o| {
                o.path = path;
                o.clip_planes = plane(-1.0).expect("plane");
            });
            assert_eq!(plain.rgba, all.rgba, "{kind} {}", path.name());
            assert_eq!(plain.depth, all.depth);
            assert_eq!(sp, sa);
            // x ≥ 2 holds none of it: nothing drawn and no sample taken.
            let (none, sn) = render(&mesh, kind, &tf, |o| {
                o.path = path;
                o.clip_planes = plane(2.0).expect("plane");
            });
            assert!(none.rgba.iter().all(|p| *p == [0.0; 4]));
            assert!(none.depth.iter().all(|d| d.is_infinite()));
            assert_eq!((sn.rays, sn.samples, sn.hex_tests), (24 * 24, 0, 0));
        }
    }
}

/// The fast path's reach by marching ([`RenderOptions::march_reach`]) changes how samples far
/// ahead are found, not the image: on a cube of 24³ cells with a step of about four cells,
/// locating every sample past the previous one's cell through the structure (reach 0), the
/// default reach and always marching (infinite reach) give the same image and depths within
/// rounding (a point on a shared face may be given to either cell, whose interpolated values
/// agree to the inverse map's accuracy) and the same samples located, for every structure,
/// compositing (with transparent cells passed over) and a maximum-intensity projection.
/// Counters show which ran: no sample located far ahead when always marching, some with the
/// default reach, more (a third of those located at least) with reach 0, and fewer cells
/// crossed by the march the shorter the reach. The reach counts cells per cell a look-up
/// tests ([`Accel::lookup_tests`]): each structure runs at the default reach divided by its
/// own, where all four locate as many samples far ahead; a grid's is the larger.
#[test]
fn far_samples_are_located_through_the_structure_with_the_same_image() {
    let mesh = smooth(24);
    let tf = TransferFunction::default_for_range(0.0, 2.6, 0.6, 0.2);
    let step = 0.17;
    let mut at_default = std::collections::HashMap::new();
    let mut factors = std::collections::HashMap::new();
    for kind in StructureKind::ALL {
        for blend in [Blend::Composite, Blend::Maximum] {
            let run = |reach: f64| {
                render(&mesh, kind, &tf, |o| {
                    o.step = step;
                    o.blend = blend;
                    o.march_reach = reach;
                })
            };
            let (marched, sm) = run(f64::INFINITY);
            assert!(
                marched.rgba.iter().any(|p| p[3] > 0.1),
                "{kind}: empty image"
            );
            assert_eq!(sm.far_locates, 0, "{kind} {blend:?}");
            let (mut walked, mut far) = (sm.walk_steps, 0);
            // The march goes the reach times the cells a look-up through the structure tests
            // on average: at the default reach divided by that, every structure marches the
            // default reach (a grid's factor is the larger: its look-ups test its leaf
            // cell's candidates).
            let accel = build(&mesh, kind);
            let factor = accel.lookup_tests(&mesh);
            assert!(factor >= 1.0, "{kind}: {factor}");
            factors.insert(kind, factor);
            for reach in [DEFAULT_MARCH_REACH / factor, 0.0] {
                let (image, s) = run(reach);
                let what = format!("{kind} {blend:?} reach {reach}");
                let diff = image.max_abs_difference(&marched);
                assert!(diff <= 1e-9, "{what}: differs by {diff}");
                for (a, b) in image.depth.iter().zip(&marched.depth) {
                    assert!(a == b || (a - b).abs() <= 1e-9, "{what}: depth {a} vs {b}");
                }
                assert_eq!(
                    (s.samples, s.samples_located),
                    (sm.samples, sm.samples_located),
                    "{what}"
                );
                assert!(s.far_locates > 0, "{what}: {s:?}");
                assert!(
                    s.walk_steps < walked && s.far_locates > far,
                    "{what}: {s:?}"
                );
                (walked, far) = (s.walk_steps, s.far_locates);
                if reach > 0.0 {
                    at_default.insert((kind, blend), s.far_locates);
                }
                if reach == 0.0 {
                    assert!(s.far_locates * 3 > s.samples_located, "{what}: {s:?}");
                }
            }
        }
    }
    // The same march makes the same decisions: compositing, every structure at the default
    // reach divided by its factor locates as many samples far ahead. (A projection's rays
    // jump over cells that cannot beat the extreme on a BVH only, so their marches differ.)
    for grid in [StructureKind::CartGrid, StructureKind::CylGrid] {
        for bvh in [StructureKind::CartBvh, StructureKind::CylBvh] {
            assert!(factors[&grid] > factors[&bvh], "{factors:?}");
        }
    }
    let bvh = at_default[&(StructureKind::CylBvh, Blend::Composite)];
    for kind in StructureKind::ALL {
        assert_eq!(at_default[&(kind, Blend::Composite)], bvh, "{kind}");
    }
    // A reach that is no number of cells is refused.
    let accel = build(&mesh, StructureKind::CartGrid);
    let volume = Volume::new(&mesh, &accel).expect("volume");
    for bad in [-1.0, f64::NAN, f64::NEG_INFINITY] {
        let mut options = RenderOptions::new(8, 8, step);
        options.march_reach = bad;
        let err = Renderer::new(&volume, &tf, &options)
            .err()
            .expect("refused");
        assert!(err.to_string().contains("march reach"), "{err}");
    }
}

/// The renderer's own refusals, which the C ABI and the mapper reach with any number a caller
/// passes, write the numbers short (`error::show_number`): `1e-300`, not its 302 digits, and
/// a projection or a clipping plane in the caller's terms, not as Rust's `Debug` prints it.
#[test]
fn refusals_write_numbers_short() {
    let short = |e: cylvol::Error, want: &str| {
        let text = e.to_string();
        assert!(text.contains(want) && text.len() < 160, "{text}");
    };
    let (eye, focal, up) = (DVec3::new(0.0, 0.0, 5.0), DVec3::ZERO, DVec3::Y);
    short(
        Camera::parallel(eye, focal, up, -1e-300).unwrap_err(),
        "bad camera parallel scale -1e-300 (must be positive and finite)",
    );
    short(
        Camera::perspective(eye, focal, up, 1e300).unwrap_err(),
        "bad camera view angle 1e300 (must be in (0, 180) degrees)",
    );
    let tiny = DVec3::new(1e-300, 0.0, 0.0);
    short(
        Camera::perspective(tiny, tiny, up, 30.0).unwrap_err(),
        "degenerate camera: eye (1e-300, 0, 0), focal point (1e-300, 0, 0), view-up (0, 1, 0)",
    );
    short(
        ClipPlanes::new(&[[0.0, 0.0, 0.0, 1e-300]]).unwrap_err(),
        "clipping plane 0: [0, 0, 0, 1e-300] has no normal",
    );
    let tf = TransferFunction::default_for_range(0.0, 1.0, 0.6, 0.2);
    short(
        tf.table(0.0, 1.0, 1e-300 - 2e-300, 256).unwrap_err(),
        "bad step -1e-300",
    );
    short(
        tf.table(1e-300, 0.0, 0.5, 256).unwrap_err(),
        "bad scalar range [1e-300, 0]",
    );

    let mesh = cube(2, false, |p, _| p.x);
    let accel = build(&mesh, StructureKind::CartGrid);
    let volume = Volume::new(&mesh, &accel).expect("volume");
    let mut options = RenderOptions::new(8, 8, 0.1);
    options.march_reach = -1e-300;
    short(
        Renderer::new(&volume, &tf, &options)
            .err()
            .expect("refused"),
        "march reach -1e-300 must be a number of cells",
    );
    let options = RenderOptions::new(8, 8, 1e-300);
    short(
        Renderer::new(&volume, &tf, &options)
            .err()
            .expect("refused"),
        "step 1e-300 is too small for a mesh of diagonal 1.8",
    );
}
