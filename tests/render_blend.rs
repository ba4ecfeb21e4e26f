//! Maximum- and minimum-intensity projections ([`Blend`]) on a slab whose scalar is known in
//! closed form: each pixel is the colour and opacity of the extreme scalar on its ray, on every
//! structure and both paths; a transparent extreme stays transparent (no cell is skipped for
//! its opacity); and none of compositing's work — gradients, early termination, skipping — is
//! done, while the fast path passes over the cells that cannot beat a ray's extreme so far.

use cylvol::accel::{Accel, AccelParams, StructureKind};
use cylvol::axis::Axis;
use cylvol::io::structured::hexahedra;
use cylvol::render::{
    Blend, GradientOpacity, RenderOptions, RenderPath, RenderStats, Renderer, Shading,
    TransferFunction, Volume,
};
use cylvol::{CellKind, DataArray, Mesh, MeshParts};
use glam::DVec3;

const STEP: f64 = 0.002;

/// The unit cube in 8 × 8 × 8 hexahedra (points slightly jittered inside, so that cells are
/// not boxes), scalar `s = x + z / 2`: along a ray down `−z` its maximum is `x + 1/2` (at the
/// top face) and its minimum `x` (at the bottom face).
fn slab() -> Mesh {
    slab_of(|p| p.x + 0.5 * p.z)
}

/// [`slab`]'s cells with the point scalar `scalar(p)`.
fn slab_of(scalar: impl Fn(DVec3) -> f64) -> Mesh {
    let n = 9;
    let mut points = Vec::new();
    for k in 0..n {
        for j in 0..n {
            for i in 0..n {
                let interior = |a: usize| a > 0 && a < n - 1;
                let wobble = if interior(i) && interior(j) && interior(k) {
                    0.01 * ((i * 7 + j * 3 + k * 5) % 5) as f64 - 0.02
                } else {
                    0.0
                };
                let q = |a: usize| a as f64 / (n - 1) as f64;
                points.push(DVec3::new(q(i) + wobble, q(j) - wobble, q(k) + wobble));
            }
        }
    }
    let scalars = points.iter().map(|&p| scalar(p)).collect();
    let cells = hexahedra([n, n, n], &points);
    let kinds = vec![CellKind::Hexahedron; cells.len()];
    Mesh::from_parts(MeshParts {
        points,
        cells,
        kinds,
        point_data: vec![DataArray::scalar("s", scalars)],
        ..Default::default()
    })
    .expect("valid slab")
}

/// Colour ramps over the scalar range `[0, 1.5]`; opacity rises from 0.1 to 0.9, and with
/// `transparent_top` drops to zero above 1.2.
fn transfer(transparent_top: bool) -> TransferFunction {
    let mut opacity = vec![(0.0, 0.1), (1.2, 0.8)];
    if transparent_top {
        opacity.push((1.2 + 1e-9, 0.0));
    } else {
        opacity.push((1.5, 0.9));
    }
    TransferFunction {
        color: vec![(0.0, [0.0, 0.2, 1.0]), (1.5, [1.0, 0.5, 0.0])],
        opacity,
        unit_distance: 0.5,
    }
}

fn options(path: RenderPath, blend: Blend) -> RenderOptions {
    let mut o = RenderOptions::new(1, 1, STEP);
    o.path = path;
    o.blend = blend;
    o
}

/// Casts a ray down `−z` through `(x, y)` and returns its premultiplied colour and opacity.
fn cast(renderer: &Renderer, x: f64, y: f64, stats: &mut RenderStats) -> [f64; 4] {
    renderer
        .cast(DVec3::new(x, y, 2.0), DVec3::NEG_Z, f64::NAN, stats)
        .rgba
}

/// The pixel a projection must give for the extreme scalar `s`: the table's colour and opacity
/// per unit distance there, premultiplied.
fn expected(tf: &TransferFunction, s: f64) -> [f64; 4] {
    let table = tf.table(0.0, 1.5, STEP, 1024).expect("table");
    let [r, g, b, _] = table.lookup(s);
    let a = table.unit_opacity(s);
    [r * a, g * a, b * a, a]
}

fn max_difference(a: [f64; 4], b: [f64; 4]) -> f64 {
    a.iter()
        .zip(&b)
        .map(|(p, q)| (p - q).abs())
        .fold(0.0, f64::max)
}

/// Rays at these `(x, y)`, away from the jittered interior's effect on `s` only at the top and
/// bottom faces (which are flat: the extremes lie on them).
fn rays() -> Vec<(f64, f64)> {
    (0..9)
        .flat_map(|i| (0..4).map(move |j| (0.05 + 0.1125 * i as f64, 0.1 + 0.27 * j as f64)))
        .collect()
}

/// Each ray's pixel is the extreme's colour and opacity: `x + 1/2` for the maximum, `x` for
/// the minimum, found by the samples to within half a step in `z` (a quarter step in `s`),
/// which moves the tables' values by less than 2e-3.
#[test]
fn projections_give_the_extreme_scalar_colour_and_opacity() {
    let mesh = slab();
    let axis = Axis::Z;
    for kind in StructureKind::ALL {
        let accel = Accel::build(&mesh, kind, &axis, &AccelParams::default()).expect("build");
        let volume = Volume::new(&mesh, &accel).expect("volume");
        for path in [RenderPath::Paper, RenderPath::Fast] {
            let tf = transfer(false);
            for (blend, extreme) in [(Blend::Maximum, 0.5), (Blend::Minimum, 0.0)] {
                let r = Renderer::new(&volume, &tf, &options(path, blend)).expect("renderer");
                let mut stats = RenderStats::default();
                for (x, y) in rays() {
                    let got = cast(&r, x, y, &mut stats);
                    let want = expected(&tf, x + extreme);
                    assert!(
                        max_difference(got, want) < 2e-3,
                        "{kind} {path:?} {blend:?} at ({x}, {y}): {got:?}, want {want:?}"
                    );
                }
                assert!(stats.samples_located > 0);
            }
            // Compositing gives neither: the check above could fail.
            let r =
                Renderer::new(&volume, &tf, &options(path, Blend::Composite)).expect("renderer");
            let got = cast(&r, 0.5, 0.5, &mut RenderStats::default());
            assert!(max_difference(got, expected(&tf, 1.0)) > 0.05);
            assert!(max_difference(got, expected(&tf, 0.5)) > 0.05);
        }
    }
}

/// An extreme where the opacity is zero gives a transparent pixel, though cells on the ray are
/// visible: the projection looks at every cell, transparent or not. Compositing the same rays
/// shows the visible cells, skipping the transparent ones (so the mask that skips them exists
/// here, and the projection did not use it).
#[test]
fn a_transparent_maximum_is_not_skipped() {
    let mesh = slab();
    let axis = Axis::Z;
    let tf = transfer(true);
    for kind in [StructureKind::CylBvh, StructureKind::CartGrid] {
        let accel = Accel::build(&mesh, kind, &axis, &AccelParams::default()).expect("build");
        let volume = Volume::new(&mesh, &accel).expect("volume");
        let mip = Renderer::new(&volume, &tf, &options(RenderPath::Fast, Blend::Maximum))
            .expect("renderer");
        let composite = Renderer::new(&volume, &tf, &options(RenderPath::Fast, Blend::Composite))
            .expect("renderer");
        let (mut mip_stats, mut composite_stats) = (RenderStats::default(), RenderStats::default());
        // x + 1/2 > 1.2 from x = 0.75: transparent maxima, visible cells lower down.
        for x in [0.8, 0.9, 0.97] {
            let got = cast(&mip, x, 0.5, &mut mip_stats);
            assert_eq!(got, [0.0; 4], "{kind}: x = {x}");
            let shown = cast(&composite, x, 0.5, &mut composite_stats);
            assert!(shown[3] > 0.1, "{kind}: x = {x}: {shown:?}");
        }
        assert_eq!(mip_stats.samples_skipped, 0);
        assert!(composite_stats.samples_skipped > 0, "{kind}");
        // Below 1.2 the maximum is visible again.
        let got = cast(&mip, 0.6, 0.5, &mut mip_stats);
        assert!(max_difference(got, expected(&tf, 1.1)) < 2e-3, "{got:?}");
    }
}

/// Shading, gradient opacity and early termination belong to compositing: a projection asked
/// for them evaluates no gradient and stops no ray early, and its image is the plain one.
#[test]
fn projections_compute_none_of_compositing() {
    let mesh = slab();
    let axis = Axis::Z;
    let tf = transfer(false);
    let accel =
        Accel::build(&mesh, StructureKind::CylBvh, &axis, &AccelParams::default()).expect("build");
    let volume = Volume::new(&mesh, &accel).expect("volume");
    for path in [RenderPath::Paper, RenderPath::Fast] {
        let plain = Renderer::new(&volume, &tf, &options(path, Blend::Maximum)).expect("renderer");
        let mut asked = options(path, Blend::Maximum);
        asked.shading = Some(Shading::default());
        asked.gradient_opacity = Some(GradientOpacity::new(&[(0.0, 0.2), (1.0, 1.0)]).unwrap());
        asked.early_termination = 0.05;
        let asked = Renderer::new(&volume, &tf, &asked).expect("renderer");
        let (mut a, mut b) = (RenderStats::default(), RenderStats::default());
        for (x, y) in rays() {
            assert_eq!(cast(&plain, x, y, &mut a), cast(&asked, x, y, &mut b));
        }
        assert_eq!(b.gradient_evaluations, 0);
        assert_eq!(b.early_terminations, 0);
        assert_eq!(a.samples, b.samples);
        // The same options compositing do all three.
        let mut composite = options(path, Blend::Composite);
        composite.shading = Some(Shading::default());
        composite.early_termination = 0.05;
        let composite = Renderer::new(&volume, &tf, &composite).expect("renderer");
        let mut c = RenderStats::default();
        for (x, y) in rays() {
            cast(&composite, x, y, &mut c);
        }
        assert!(c.gradient_evaluations > 0 && c.early_terminations > 0);
    }
}

/// The fast path passes over the cells whose scalar range cannot beat the ray's extreme so
/// far: where the extreme comes first on the ray (the maximum of rays down `−z`, the minimum of
/// rays up `+z`) a grid passes over most located samples, most of them with no inverse map,
/// and a BVH jumps over most samples unlocated; in every direction the image is the paper
/// path's, which interpolates every sample (a skip of a cell that could beat the extreme
/// would show where the extreme comes last).
#[test]
fn projections_pass_over_cells_that_cannot_beat_the_extreme() {
    let axis = Axis::Z;
    let tf = transfer(false);
    // The slab, and a valley `x + |z − 0.6|` whose maximum down `−z` comes after a stretch
    // of cells that cannot beat the first samples' (a jump must land before it).
    for (mesh, first_wins) in [
        (slab(), true),
        (slab_of(|p| p.x + (p.z - 0.6).abs()), false),
    ] {
        projections_equal_the_paper_path(&mesh, &axis, &tf, first_wins);
    }
}

/// The checks of [`projections_pass_over_cells_that_cannot_beat_the_extreme`] on `mesh`, whose
/// rays' maximum down `−z` and minimum up `+z` come first where `first_wins`.
fn projections_equal_the_paper_path(
    mesh: &Mesh,
    axis: &Axis,
    tf: &TransferFunction,
    first_wins: bool,
) {
    for kind in StructureKind::ALL {
        let accel = Accel::build(mesh, kind, axis, &AccelParams::default()).expect("build");
        let volume = Volume::new(mesh, &accel).expect("volume");
        for blend in [Blend::Maximum, Blend::Minimum] {
            let fast = Renderer::new(&volume, tf, &options(RenderPath::Fast, blend)).unwrap();
            let paper = Renderer::new(&volume, tf, &options(RenderPath::Paper, blend)).unwrap();
            for (z, dir) in [(2.0, DVec3::NEG_Z), (-1.0, DVec3::Z)] {
                let (mut f, mut p) = (RenderStats::default(), RenderStats::default());
                for (x, y) in rays() {
                    let o = DVec3::new(x, y, z);
                    let got = fast.cast(o, dir, f64::NAN, &mut f).rgba;
                    let want = paper.cast(o, dir, f64::NAN, &mut p).rgba;
                    assert!(
                        max_difference(got, want) < 1e-9,
                        "{kind} {blend:?} {dir}: at ({x}, {y}): {got:?}, paper {want:?}"
                    );
                }
                assert_eq!(
                    p.extreme_skips, 0,
                    "the paper path interpolates every sample"
                );
                let first = (blend == Blend::Maximum) == (dir == DVec3::NEG_Z);
                if first && !first_wins && !kind.is_grid() {
                    // The valley's maximum down −z: a jump over the middle, then a new maximum.
                    assert!(f.extreme_jumps > 0, "{kind} {blend:?} {dir}: {f:?}");
                }
                if first && first_wins {
                    let why = format!("{kind} {blend:?} {dir}: {f:?}");
                    assert!(f.extreme_skips > 0, "{why}");
                    assert!(f.hex_tests < p.hex_tests / 2, "{why}");
                    if kind.is_grid() {
                        // Passed over sample by sample, most with no inverse map.
                        assert_eq!(f.extreme_jumps, 0, "{why}");
                        assert!(2 * f.extreme_skips > f.samples_located, "{why}");
                        assert!(f.plane_certified > 0, "{why}");
                    } else {
                        // A BVH's node ranges let the ray jump to the next cell that may beat
                        // the extreme: most samples are not even located.
                        assert!(f.extreme_jumps > 0, "{why}");
                        assert!(2 * f.samples_located < p.samples_located, "{why}");
                    }
                }
            }
        }
    }
}

/// A projection of the valley (whose rays jump over cells that cannot beat the maximum) moved
/// 10⁶ units away, rays too, gives the same pixels within 1/255 and makes the same jumps.
#[test]
fn a_projection_far_away_is_the_same() {
    let offset = DVec3::new(1e6, -1e6, 1e6);
    let near = slab_of(|p| p.x + (p.z - 0.6).abs());
    let mut parts = near.clone().into_parts();
    for p in &mut parts.points {
        *p += offset;
    }
    let far = Mesh::from_parts(parts).expect("moved slab");
    let (near_axis, far_axis) = (Axis::Z, Axis::new(offset, DVec3::Z).expect("axis"));
    let tf = transfer(false);
    for kind in [StructureKind::CylBvh, StructureKind::CartBvh] {
        let build = |m: &Mesh, a: &Axis| Accel::build(m, kind, a, &AccelParams::default());
        let (near_accel, far_accel) = (
            build(&near, &near_axis).unwrap(),
            build(&far, &far_axis).unwrap(),
        );
        let near_volume = Volume::new(&near, &near_accel).expect("volume");
        let far_volume = Volume::new(&far, &far_accel).expect("volume");
        for blend in [Blend::Maximum, Blend::Minimum] {
            let o = options(RenderPath::Fast, blend);
            let a = Renderer::new(&near_volume, &tf, &o).expect("renderer");
            let b = Renderer::new(&far_volume, &tf, &o).expect("renderer");
            let (mut sa, mut sb) = (RenderStats::default(), RenderStats::default());
            for (x, y) in rays() {
                let origin = DVec3::new(x, y, 2.0);
                let got = a.cast(origin, DVec3::NEG_Z, f64::NAN, &mut sa).rgba;
                let away = b
                    .cast(origin + offset, DVec3::NEG_Z, f64::NAN, &mut sb)
                    .rgba;
                assert!(
                    max_difference(got, away) <= 1.0 / 255.0,
                    "{kind} {blend:?} at ({x}, {y}): {got:?} against {away:?} far away"
                );
                assert!(got[3] > 0.0);
            }
            if blend == Blend::Maximum {
                assert!(sa.extreme_jumps > 0, "{kind}: {sa:?}");
            }
            assert_eq!(sa.extreme_jumps, sb.extreme_jumps, "{kind} {blend:?}");
        }
    }
}

#[test]
fn blend_names_parse() {
    for b in Blend::ALL {
        assert_eq!(b.name().parse::<Blend>().unwrap(), b);
    }
    let err = "maximum".parse::<Blend>().unwrap_err().to_string();
    assert!(err.contains("composite") && err.contains("max"), "{err}");
    assert_eq!(Blend::default(), Blend::Composite);
}
