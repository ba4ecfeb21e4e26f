//! The ray caster on hard meshes built in code: a constant medium gives the exact Beer–Lambert
//! transmittance through a closed annulus (with and without a duplicated θ seam), an O-grid
//! cylinder with wedges on the axis and a cube of twisted (jittered) cells, for rays through
//! vertices, along edges, inside shared faces, along and through the axis and in the seam
//! plane — on every structure and both paths. Then: all structures and paths give the same
//! image; shading alone evaluates gradients; 1 and 2 threads give identical images; a mesh
//! moved 10⁶ units away (camera too) renders the same; a camera inside the mesh works.

mod common;

use std::collections::HashMap;
use std::f64::consts::PI;

use common::{moved, o_grid_with_axis_wedges, sector, Rng};
use cylvol::accel::{Accel, AccelParams, StructureKind};
use cylvol::axis::Axis;
use cylvol::geometry::cylindrical::CylFrame;
use cylvol::io::structured::hexahedra;
use cylvol::render::BISECTIONS;
use cylvol::render::{
    Camera, ClipPlanes, Image, RenderOptions, RenderPath, RenderStats, Renderer, Shading,
    TransferFunction, Volume,
};
use cylvol::{CellKind, DataArray, Mesh, MeshParts};
use glam::{DVec2, DVec3};

const PATHS: [RenderPath; 2] = [RenderPath::Paper, RenderPath::Fast];

fn frame() -> CylFrame {
    CylFrame::new(DVec3::ZERO, DVec3::Z).expect("z axis")
}

/// The chord `[t0, t1]` of a ray through a right prism over a convex polygon (in the xy plane)
/// between heights `z[0]` and `z[1]`, if any.
fn prism_chord(poly: &[DVec2], z: [f64; 2], o: DVec3, d: DVec3) -> Option<(f64, f64)> {
    let (mut t0, mut t1) = (f64::NEG_INFINITY, f64::INFINITY);
    if d.z == 0.0 {
        if o.z < z[0] || o.z > z[1] {
            return None;
        }
    } else {
        let (a, b) = ((z[0] - o.z) / d.z, (z[1] - o.z) / d.z);
        t0 = t0.max(a.min(b));
        t1 = t1.min(a.max(b));
    }
    let c = poly.iter().copied().sum::<DVec2>() / poly.len() as f64;
    for k in 0..poly.len() {
        let (a, b) = (poly[k], poly[(k + 1) % poly.len()]);
        let e = b - a;
        let mut n = DVec2::new(e.y, -e.x);
        if n.dot(c - a) > 0.0 {
            n = -n;
        }
        let (o2, d2) = (DVec2::new(o.x, o.y), DVec2::new(d.x, d.y));
        let (num, den) = (n.dot(o2 - a), n.dot(d2));
        if den == 0.0 {
            if num > 0.0 {
                return None;
            }
        } else if den > 0.0 {
            t1 = t1.min(-num / den);
        } else {
            t0 = t0.max(-num / den);
        }
    }
    (t0 < t1).then_some((t0, t1))
}

fn polygon(radius: f64, n: usize, offset: f64) -> Vec<DVec2> {
    (0..n)
        .map(|j| {
            let p = frame().from_cylindrical(
                radius,
                -PI + 2.0 * PI * j as f64 / n as f64 + offset,
                0.0,
            );
            DVec2::new(p.x, p.y)
        })
        .collect()
}

/// The analytic `[t0, t1]` intervals of a ray (origin, unit direction) inside a domain.
type Intervals = dyn Fn(DVec3, DVec3) -> Vec<(f64, f64)>;

/// A mesh with the analytic intervals of a ray inside it.
struct Case {
    name: &'static str,
    mesh: Mesh,
    axis: Axis,
    intervals: Box<Intervals>,
    /// Whether a point is on the domain's boundary (to skip rays that graze it).
    on_boundary: Box<dyn Fn(DVec3) -> bool>,
    /// Whether the axis and the θ = ±π plane cross the interior (not for the cube, where
    /// they are on its boundary).
    cylindrical: bool,
}

fn annulus(close_ring: bool) -> Case {
    let (nr, nt, nh) = (4, 24, 4);
    let mesh = sector(
        &frame(),
        [0.5, 1.0],
        [-PI, PI],
        1.0,
        [nr, nt, nh],
        close_ring,
    );
    let outer = polygon(1.0, nt, 0.0);
    let inner = polygon(0.5, nt, 0.0);
    // The polygons' inradii, to recognise boundary points.
    let cos = (PI / nt as f64).cos();
    Case {
        name: if close_ring {
            "closed annulus"
        } else {
            "annulus with a duplicated seam"
        },
        mesh,
        axis: Axis::Z,
        intervals: Box::new(move |o, d| {
            let Some((a, b)) = prism_chord(&outer, [0.0, 1.0], o, d) else {
                return vec![];
            };
            match prism_chord(&inner, [0.0, 1.0], o, d) {
                Some((c, e)) if c < b && e > a => vec![(a, c.max(a)), (e.min(b), b)],
                _ => vec![(a, b)],
            }
        }),
        on_boundary: Box::new(move |p| {
            let r = DVec2::new(p.x, p.y).length();
            p.z.abs() < 1e-9 || (p.z - 1.0).abs() < 1e-9 || r > 1.0 * cos - 1e-9 || r < 0.5 + 1e-9
        }),
        cylindrical: true,
    }
}

fn o_grid() -> Case {
    let (nt, rings) = (16, 4);
    let mesh = o_grid_with_axis_wedges(&frame(), 1.0, nt, rings, 4);
    let outer = polygon(1.0, nt, 0.1 * rings as f64);
    let cos = (PI / nt as f64).cos();
    Case {
        name: "O-grid with wedges on the axis",
        mesh,
        axis: Axis::Z,
        intervals: Box::new(move |o, d| {
            prism_chord(&outer, [0.0, 1.0], o, d).into_iter().collect()
        }),
        on_boundary: Box::new(move |p| {
            let r = DVec2::new(p.x, p.y).length();
            p.z.abs() < 1e-9 || (p.z - 1.0).abs() < 1e-9 || r > cos - 1e-9
        }),
        cylindrical: true,
    }
}

/// The unit cube as `n³` cells whose interior points are jittered by up to 0.2 of a cell in
/// every direction (boundary points only along the boundary): twisted, non-planar cells whose
/// union is still exactly the cube.
fn jittered_cube(n: usize) -> Case {
    let mut rng = Rng::new(0xC0BE);
    let m = n + 1;
    let mut points = Vec::with_capacity(m * m * m);
    for k in 0..m {
        for j in 0..m {
            for i in 0..m {
                let mut p = DVec3::new(i as f64, j as f64, k as f64);
                for (a, idx) in [i, j, k].into_iter().enumerate() {
                    if idx != 0 && idx != n {
                        p[a] += 0.4 * (rng.unit() - 0.5);
                    }
                }
                points.push(p / n as f64);
            }
        }
    }
    let cells = hexahedra([m, m, m], &points);
    let values = points.iter().map(|p| p.x + 2.0 * p.y * p.z).collect();
    let mesh = Mesh::from_parts(MeshParts {
        kinds: vec![CellKind::Hexahedron; cells.len()],
        cells,
        points,
        point_data: vec![DataArray::scalar("f", values)],
        cell_data: vec![],
    })
    .expect("jittered cube is valid");
    let square = vec![
        DVec2::new(0.0, 0.0),
        DVec2::new(1.0, 0.0),
        DVec2::new(1.0, 1.0),
        DVec2::new(0.0, 1.0),
    ];
    Case {
        name: "cube of twisted cells",
        mesh,
        axis: Axis::Z,
        intervals: Box::new(move |o, d| {
            prism_chord(&square, [0.0, 1.0], o, d).into_iter().collect()
        }),
        on_boundary: Box::new(|p| {
            p.to_array()
                .iter()
                .any(|&x| x.abs() < 1e-9 || (x - 1.0).abs() < 1e-9)
        }),
        cylindrical: false,
    }
}

/// Cell faces as corner indices (VTK hexahedron order).
const FACES: [[usize; 4]; 6] = [
    [0, 3, 7, 4],
    [1, 2, 6, 5],
    [0, 1, 5, 4],
    [3, 2, 6, 7],
    [0, 1, 2, 3],
    [4, 5, 6, 7],
];

/// The hard rays: through vertices, along edges, inside faces, along and through the axis,
/// in the θ = ±π seam plane, and random ones — as (origin, unit direction, what).
fn hard_rays(case: &Case, seed: u64, per_kind: usize) -> Vec<(DVec3, DVec3, &'static str)> {
    let mesh = &case.mesh;
    let mut rng = Rng::new(seed);
    let mut rays = Vec::new();
    let dir = |rng: &mut Rng| loop {
        let d = DVec3::new(rng.unit() - 0.5, rng.unit() - 0.5, rng.unit() - 0.5);
        if d.length() > 0.1 {
            return d.normalize();
        }
    };
    let back = 3.0;
    // Through interior vertices.
    let interior: Vec<DVec3> = mesh
        .points()
        .iter()
        .copied()
        .filter(|p| !(case.on_boundary)(*p))
        .collect();
    for _ in 0..per_kind {
        let p = interior[rng.below(interior.len())];
        let d = dir(&mut rng);
        rays.push((p - d * back, d, "vertex"));
    }
    // Along edges (not both ends on the boundary: such a ray grazes the surface).
    let edges = [
        (0, 1),
        (3, 2),
        (4, 5),
        (7, 6),
        (0, 3),
        (1, 2),
        (4, 7),
        (5, 6),
        (0, 4),
        (1, 5),
        (2, 6),
        (3, 7),
    ];
    let mut made = 0;
    while made < per_kind {
        let c = mesh.cell_corners(rng.below(mesh.cell_count()));
        let (a, b) = edges[rng.below(12)];
        let (pa, pb) = (c[a], c[b]);
        if (pb - pa).length() < 1e-9 || ((case.on_boundary)(pa) && (case.on_boundary)(pb)) {
            continue;
        }
        let d = (pb - pa).normalize();
        rays.push((pa - d * back, d, "edge"));
        made += 1;
    }
    // Inside faces: through a random point of an interior face, tangent to it there.
    let mut made = 0;
    while made < per_kind {
        let c = mesh.cell_corners(rng.below(mesh.cell_count()));
        let f = FACES[rng.below(6)];
        let (s, t) = (rng.unit(), rng.unit());
        let q = [c[f[0]], c[f[1]], c[f[2]], c[f[3]]];
        let at = |s: f64, t: f64| {
            q[0] * (1.0 - s) * (1.0 - t)
                + q[1] * s * (1.0 - t)
                + q[2] * s * t
                + q[3] * (1.0 - s) * t
        };
        let p = at(s, t);
        let ds = at(s + 1e-3, t) - at(s - 1e-3, t);
        let dt = at(s, t + 1e-3) - at(s, t - 1e-3);
        let a = rng.unit() * PI;
        let d = (ds.normalize_or_zero() * a.cos() + dt.normalize_or_zero() * a.sin())
            .normalize_or_zero();
        if d == DVec3::ZERO || (case.on_boundary)(p) {
            continue;
        }
        rays.push((p - d * back, d, "face"));
        made += 1;
    }
    // Along the axis, and through it at many heights (layer heights included).
    let f = frame();
    for k in 0..per_kind * usize::from(case.cylindrical) {
        let x = DVec3::new(0.0, 0.0, -1.0);
        if k == 0 {
            rays.push((x, DVec3::Z, "along axis"));
            rays.push((DVec3::new(0.0, 0.0, 2.0), -DVec3::Z, "along axis"));
        }
        let h = if k % 2 == 0 {
            (k / 2 % 5) as f64 * 0.25
        } else {
            rng.unit()
        };
        let h = h.clamp(0.05, 0.95);
        let phi = rng.unit() * 2.0 * PI;
        let tilt = (rng.unit() - 0.5) * 0.5;
        let d = (f.from_cylindrical(1.0, phi, 0.0) + DVec3::Z * tilt).normalize();
        rays.push((DVec3::new(0.0, 0.0, h) - d * back, d, "through axis"));
    }
    // In the θ = ±π seam plane.
    for _ in 0..per_kind * usize::from(case.cylindrical) {
        let p = f.from_cylindrical(0.3 + 0.65 * rng.unit(), PI, 0.1 + 0.8 * rng.unit());
        let a = rng.unit() * PI;
        let d = (f.from_cylindrical(1.0, PI, 0.0) * a.cos() + DVec3::Z * a.sin()).normalize();
        rays.push((p - d * back, d, "seam plane"));
    }
    // Random rays through the box.
    for _ in 0..per_kind {
        let target =
            DVec3::new(rng.unit(), rng.unit(), rng.unit()) * 2.0 - DVec3::new(1.0, 1.0, 0.0);
        let d = dir(&mut rng);
        rays.push((target - d * back, d, "random"));
    }
    rays
}

/// Rays past the domain's boundary vertices whose way through it has a stretch in it or
/// between two parts of it shorter than `max_len` (a corner or an edge cut, the hole grazed):
/// such a stretch may hold no sample, and only the boundary surface sees it.
fn grazing_rays(
    case: &Case,
    seed: u64,
    n: usize,
    max_len: f64,
) -> Vec<(DVec3, DVec3, &'static str)> {
    let mut rng = Rng::new(seed);
    let boundary: Vec<DVec3> = case
        .mesh
        .points()
        .iter()
        .copied()
        .filter(|p| (case.on_boundary)(*p))
        .collect();
    let mut rays = Vec::new();
    for _ in 0..1000 * n {
        if rays.len() == n {
            break;
        }
        let p = boundary[rng.below(boundary.len())];
        let d = loop {
            let d = DVec3::new(rng.unit() - 0.5, rng.unit() - 0.5, rng.unit() - 0.5);
            if d.length() > 0.1 {
                break d.normalize();
            }
        };
        let (s, t) = d.any_orthonormal_pair();
        let a = rng.unit() * 2.0 * PI;
        let o = p + (s * a.cos() + t * a.sin()) * max_len * rng.unit() - d * 3.0;
        let intervals = (case.intervals)(o, d);
        let mut ends: Vec<f64> = intervals.iter().flat_map(|&(a, b)| [a, b]).collect();
        ends.sort_by(f64::total_cmp);
        if ends
            .windows(2)
            .any(|w| w[1] - w[0] > 0.0 && w[1] - w[0] < max_len)
        {
            rays.push((o, d, "grazing"));
        }
    }
    assert_eq!(rays.len(), n, "{}: grazing rays", case.name);
    rays
}

fn renderer_options(step: f64, path: RenderPath) -> RenderOptions {
    let mut o = RenderOptions::new(8, 8, step);
    o.path = path;
    o.early_termination = 2.0; // never: the whole path counts
    o
}

/// A constant medium: the transmittance of every ray is `exp(−σ L)` with `L` the exact
/// analytic length of the ray inside the domain (boundary-aware segments, see the raycast
/// module). Tolerance: each crossing is found by bisection to a bracket of `step / 64`, then
/// either interpolated inside it or its midpoint taken, so it is off by at most `step / 64`;
/// the transmittance is then off by at most `σ · 2·(intervals)·step / 64` relative (plus
/// rounding, 1e-10) — about 4e-4 here, where a sample's whole step would be 1.4 %. Rays with a
/// sample within 1e-7 of a step of the domain boundary are ambiguous (on the surface, inside is
/// a matter of rounding), as are rays with an interval or a gap between intervals shorter than
/// two steps (two crossings between two samples are not seen by sampling); they are skipped,
/// at most 10 % may be.
fn check_beer_lambert(case: &Case, step: f64) {
    check_beer_lambert_clipped(case, step, ClipPlanes::NONE);
}

/// [`check_beer_lambert`] with clipping planes: the analytic intervals are cut to the span
/// the planes keep, so the transmittance checks that the volume ends exactly on a plane that
/// cuts the mesh (the ray starting or ending in it) and nowhere else.
fn check_beer_lambert_clipped(case: &Case, step: f64, planes: ClipPlanes) {
    check_beer_lambert_with(case, step, planes, cylvol::render::DEFAULT_MARCH_REACH);
}

/// [`check_beer_lambert_clipped`] with the fast path's [`RenderOptions::march_reach`] set;
/// below one cell, every sample past the previous one's cell is located through the
/// structure wherever the boundary surface proves the ray stays in the mesh up to it, which
/// the test then asserts happens (with face neighbours, which bring the surface).
fn check_beer_lambert_with(case: &Case, step: f64, planes: ClipPlanes, march_reach: f64) {
    let (alpha, unit) = (0.4, 0.5);
    let sigma = -(1.0f64 - alpha).ln() / unit;
    let color = [0.2, 0.6, 1.0];
    let tf = TransferFunction::constant(color, alpha, unit);
    let mut rays = hard_rays(case, 0xBEE7, 40);
    rays.extend(grazing_rays(case, 0x6A2E, 40, 2.0 * step));
    // Without face neighbours crossings are searched through the structure; with them
    // (welded across a duplicated seam) locally, a face without a neighbour being boundary.
    let neighbours = common::closed_neighbours(&case.mesh);
    for kind in StructureKind::ALL {
        let accel =
            Accel::build(&case.mesh, kind, &case.axis, &AccelParams::default()).expect("build");
        let volume = Volume::new(&case.mesh, &accel).expect("volume");
        for (path, with_neighbours) in PATHS.into_iter().flat_map(|p| [(p, false), (p, true)]) {
            let mut options = renderer_options(step, path);
            options.clip_planes = planes;
            options.march_reach = march_reach;
            let mut far_locates = 0u64;
            let r = Renderer::new(&volume, &tf, &options).expect("renderer");
            let r = if with_neighbours {
                r.with_topology(&neighbours)
            } else {
                r
            };
            let (mut checked, mut skipped, mut inside) = (0usize, 0usize, 0usize);
            let mut cut_in_mesh = 0usize;
            // Rays with a stretch in or out of the mesh shorter than two steps.
            let mut short = 0usize;
            let mut max_rel = 0.0f64;
            // The grazing rays' short stretches are seen only with the boundary surface.
            let rays: Vec<_> = rays
                .iter()
                .filter(|r| with_neighbours || r.2 != "grazing")
                .collect();
            for &&(o, d, what) in &rays {
                let (o, d) = (&o, &d);
                let mut stats = RenderStats::default();
                let res = r.cast(*o, *d, f64::INFINITY, &mut stats);
                assert!(res.rgba.iter().all(|v| v.is_finite()), "{}: NaN", case.name);
                let kept = planes.clip_span(*o, *d, (f64::NEG_INFINITY, f64::INFINITY));
                let whole = (case.intervals)(*o, *d);
                let intervals: Vec<(f64, f64)> = whole
                    .iter()
                    .filter_map(|&(a, b)| {
                        let (lo, hi) = kept?;
                        let (a, b) = (a.max(lo), b.min(hi));
                        (a < b).then_some((a, b))
                    })
                    .collect();
                let Some((t_in, t_out)) = r.clip(*o, *d) else {
                    assert!(
                        intervals.iter().all(|(a, b)| b - a < 1e-9),
                        "{}: {what} ray missed the box",
                        case.name
                    );
                    continue;
                };
                let mut n = 0u64;
                let mut ambiguous = false;
                let mut k = 0;
                loop {
                    let t = t_in + (k as f64 + 0.5) * step;
                    if t >= t_out {
                        break;
                    }
                    k += 1;
                    for &(a, b) in &intervals {
                        if (t - a).abs() < 1e-7 * step || (t - b).abs() < 1e-7 * step {
                            ambiguous = true;
                        }
                        if t > a && t < b {
                            n += 1;
                        }
                    }
                }
                let mut ends: Vec<f64> = intervals
                    .iter()
                    .filter(|(a, b)| b > a)
                    .flat_map(|&(a, b)| [a.max(t_in), b.min(t_out)])
                    .collect();
                ends.sort_by(f64::total_cmp);
                // Two crossings between two samples: seen with the boundary surface alone
                // (chords and gaps), so only checked with it, and on rays not built through
                // the mesh's vertices, edges or seam, which may cross the boundary on a face's
                // edge, where a crossing is not told robustly (the chord is then not seen). A
                // stretch of a millionth of a step is ambiguous too (a sliver of a corner:
                // inside is a matter of rounding).
                let close = ends.windows(2).any(|w| w[1] - w[0] < 2.0 * step);
                let generic = matches!(what, "grazing" | "random");
                if (close && !(with_neighbours && generic))
                    || ends.windows(2).any(|w| w[1] - w[0] < 1e-6 * step)
                {
                    ambiguous = true;
                }
                if ambiguous {
                    skipped += 1;
                    continue;
                }
                checked += 1;
                short += usize::from(close);
                inside += usize::from(n > 0);
                // A plane's crossing inside the mesh, where the volume must end.
                let in_mesh = |t: f64| whole.iter().any(|&(a, b)| t > a && t < b);
                cut_in_mesh += usize::from(kept.is_some_and(|(lo, hi)| in_mesh(lo) || in_mesh(hi)));
                let length: f64 = intervals.iter().map(|(a, b)| (b - a).max(0.0)).sum();
                let expected = (-sigma * length).exp();
                let got = 1.0 - res.rgba[3];
                let crossings = 2.0 * intervals.len() as f64;
                let tol = sigma * crossings * step / 64.0 + 1e-10;
                assert!(
                    (got - expected).abs() <= tol * expected,
                    "{}: {kind} {} (neighbours: {with_neighbours}): {what} ray {o} → {d}: transmittance {got}, expected {expected} ({n} samples inside, {} located)",
                    case.name,
                    path.name(),
                    stats.samples_located
                );
                assert_eq!(
                    stats.samples_located,
                    n,
                    "{}: {kind} {}: {what} ray",
                    case.name,
                    path.name()
                );
                // A constant colour: the premultiplied colour is that colour times the opacity.
                for (got, c) in res.rgba.iter().zip(color) {
                    assert!((got - c * res.rgba[3]).abs() < 1e-12);
                }
                // The sample count approximates the analytic length within a step per end.
                assert!((n as f64 * step - length).abs() <= step * intervals.len() as f64 + 1e-9);
                max_rel = max_rel.max((got - expected).abs() / expected);
                far_locates += stats.far_locates;
            }
            eprintln!(
                "{}{}: {kind} {} (neighbours: {with_neighbours}, march reach {march_reach}): {checked} rays checked ({inside} through the mesh, {cut_in_mesh} cut by a plane in it, {short} with a stretch shorter than two steps), {skipped} ambiguous, {far_locates} samples located far ahead, max relative transmittance error {max_rel:.2e}",
                case.name,
                if planes.is_empty() { "" } else { " (clipped)" },
                path.name()
            );
            if path == RenderPath::Paper || !with_neighbours {
                assert_eq!(far_locates, 0, "only the fast path with the surface jumps");
            } else if march_reach < 1.0 {
                assert!(
                    far_locates as usize > checked,
                    "{}: {kind}: {far_locates} samples located far ahead on {checked} rays",
                    case.name
                );
            }
            assert!(
                skipped * 10 <= rays.len(),
                "{}: {skipped} ambiguous rays",
                case.name
            );
            // The grazing rays cut short stretches: with the surface, they are checked.
            assert!(
                !with_neighbours || short >= 10,
                "{}: {short} of {checked} rays with a short stretch",
                case.name
            );
            assert!(
                checked > 0 && inside * 2 > checked,
                "{}: too few rays inside",
                case.name
            );
            assert!(
                planes.is_empty() || cut_in_mesh * 4 > checked,
                "{}: {cut_in_mesh} of {checked} rays cut by a plane in the mesh",
                case.name
            );
        }
    }
}

#[test]
fn constant_medium_is_crack_free_in_a_closed_annulus() {
    check_beer_lambert(&annulus(true), 0.0137);
}

/// Two planes across the annulus, slanted to every axis: one cuts a cap off its side (rays
/// start and end in the mesh on it), the other its top, through the axis and the seam.
fn annulus_clip_planes() -> ClipPlanes {
    ClipPlanes::new(&[
        ClipPlanes::equation(
            DVec3::new(-0.55, 0.1, 0.5),
            DVec3::new(1.0, 0.3, 0.2).normalize(),
        ),
        ClipPlanes::equation(
            DVec3::new(0.0, 0.0, 0.8),
            DVec3::new(0.15, -0.2, -1.0).normalize(),
        ),
    ])
    .expect("two planes")
}

#[test]
fn constant_medium_ends_exactly_on_clipping_planes() {
    check_beer_lambert_clipped(&annulus(true), 0.0137, annulus_clip_planes());
}

/// The fast path locating every sample past the previous one's cell through the structure
/// (march reach 0), where the boundary surface proves the ray stays in the mesh up to it:
/// still the exact transmittance — no jump passes over the annulus's hole, the O-grid's
/// axis or a twisted cell's boundary, and no sample is located twice or lost.
#[test]
fn constant_medium_is_crack_free_when_far_samples_are_located_through_the_structure() {
    check_beer_lambert_with(&annulus(true), 0.0137, ClipPlanes::NONE, 0.0);
    check_beer_lambert_with(&annulus(false), 0.0137, annulus_clip_planes(), 0.0);
    check_beer_lambert_with(&o_grid(), 0.0113, ClipPlanes::NONE, 0.0);
    check_beer_lambert_with(&jittered_cube(6), 0.0091, ClipPlanes::NONE, 0.0);
}

#[test]
fn constant_medium_is_crack_free_across_a_duplicated_seam() {
    check_beer_lambert(&annulus(false), 0.0137);
}

#[test]
fn constant_medium_is_crack_free_in_an_o_grid_with_axis_wedges() {
    check_beer_lambert(&o_grid(), 0.0113);
}

#[test]
fn constant_medium_is_crack_free_in_twisted_cells() {
    check_beer_lambert(&jittered_cube(6), 0.0091);
}

fn ramp(volume: &Volume) -> TransferFunction {
    let [lo, hi] = volume.scalar_range();
    TransferFunction::default_for_range(lo, hi, 0.6, 0.2)
}

fn render(
    mesh: &Mesh,
    axis: &Axis,
    kind: StructureKind,
    path: RenderPath,
    shading: Option<Shading>,
    camera: &Camera,
    size: u32,
) -> (Image, RenderStats) {
    let accel = Accel::build(mesh, kind, axis, &AccelParams::default()).expect("build");
    let volume = Volume::new(mesh, &accel).expect("volume");
    let mut options = RenderOptions::new(size, size, 0.02);
    options.path = path;
    options.shading = shading;
    let r = Renderer::new(&volume, &ramp(&volume), &options).expect("renderer");
    r.render(camera, None).expect("render")
}

/// Every structure and both paths give the same image: the samples are the same points, and a
/// point on a shared face may be given to either cell, whose interpolated values agree to the
/// inverse map's accuracy (1e-9 of the scalar range at worst); 1e-6 in [0, 1] RGBA units
/// leaves room for that and nothing else (one sample's opacity differs by 1e-2 or more).
#[test]
fn all_structures_and_paths_give_the_same_image() {
    let case = o_grid();
    let camera = Camera::view(case.mesh.bounds(), 40, 40, 30.0, 25.0, 1.2);
    let (reference, paper_stats) = render(
        &case.mesh,
        &case.axis,
        StructureKind::CartBvh,
        RenderPath::Paper,
        None,
        &camera,
        40,
    );
    assert!(
        reference.rgba.iter().any(|p| p[3] > 0.2),
        "the image is not empty"
    );
    for kind in StructureKind::ALL {
        let mut paper_tests = 0;
        for path in PATHS {
            let (image, stats) = render(&case.mesh, &case.axis, kind, path, None, &camera, 40);
            let diff = image.max_abs_difference(&reference);
            assert!(diff <= 1e-6, "{kind} {}: differs by {diff}", path.name());
            assert_eq!(stats.samples, paper_stats.samples, "{kind} {}", path.name());
            eprintln!("{kind} {}: {stats:?}", path.name());
            if path == RenderPath::Fast {
                assert!(
                    stats.samples_skipped > 0,
                    "the ramp's transparent part is skipped"
                );
                assert!(
                    stats.hex_tests < paper_tests,
                    "{kind}: warm start saves cell tests"
                );
            } else {
                assert_eq!(stats.samples_skipped, 0);
                paper_tests = stats.hex_tests;
            }
        }
    }
}

/// Face neighbours by shared corner sets (brute force), as the mesh topology will give them.
fn face_neighbours(mesh: &Mesh) -> Vec<[u32; 6]> {
    let mut by_face: HashMap<[u32; 4], Vec<u32>> = HashMap::new();
    for (c, cell) in mesh.cells().iter().enumerate() {
        for f in FACES {
            let mut key = f.map(|k| cell[k]);
            key.sort_unstable();
            by_face.entry(key).or_default().push(c as u32);
        }
    }
    mesh.cells()
        .iter()
        .enumerate()
        .map(|(c, cell)| {
            FACES.map(|f| {
                let mut key = f.map(|k| cell[k]);
                key.sort_unstable();
                by_face[&key]
                    .iter()
                    .copied()
                    .find(|&o| o != c as u32)
                    .unwrap_or(u32::MAX)
            })
        })
        .collect()
}

/// With complete face neighbours the fast path finds where a ray enters and leaves the mesh
/// exactly (walking the faces it crosses, `render::march::boundary_face_crossing`); without
/// them, by bisection to within `step / 2^(BISECTIONS + 1)` of it. The same samples are
/// located, so the images differ by at most the opacity of two such slivers (entry and exit:
/// the O-grid is convex) of the most opaque medium.
#[test]
fn face_neighbours_change_the_work_not_the_image() {
    let case = o_grid();
    let mesh = &case.mesh;
    let accel = Accel::build(
        mesh,
        StructureKind::CylBvh,
        &case.axis,
        &AccelParams::default(),
    )
    .expect("build");
    let volume = Volume::new(mesh, &accel).expect("volume");
    let mut options = RenderOptions::new(32, 32, 0.02);
    options.path = RenderPath::Fast;
    let tf = ramp(&volume);
    let camera = Camera::view(mesh.bounds(), 32, 32, -40.0, 10.0, 1.0);
    let plain = Renderer::new(&volume, &tf, &options).expect("renderer");
    let (a, sa) = plain.render(&camera, None).expect("render");
    let table = face_neighbours(mesh);
    let lookup = |c: u32| table[c as usize];
    let with = Renderer::new(&volume, &tf, &options)
        .expect("renderer")
        .with_neighbours(&lookup);
    let (b, sb) = with.render(&camera, None).expect("render");
    let [lo, hi] = volume.scalar_range();
    let densest = (0..=1000)
        .map(|k| plain.table().lookup(lo + (hi - lo) * k as f64 / 1000.0)[3])
        .fold(0.0f64, f64::max);
    let bound = 2.0 * (1.0 - (1.0 - densest).powf(0.5f64.powi(BISECTIONS as i32 + 1)));
    let diff = f64::from(a.max_abs_difference(&b));
    eprintln!("differs by {diff}, bound {bound}");
    assert!(diff <= bound, "{diff} > {bound}");
    assert_eq!(sa.samples, sb.samples);
    assert_eq!(sa.samples_located, sb.samples_located);
    assert_eq!(sa.neighbour_hits, 0);
    assert!(sb.neighbour_hits > 0 && sb.previous_cell_hits > 0);
    assert!(
        sb.internal_visits + sb.leaf_visits < sa.internal_visits + sa.leaf_visits,
        "neighbours spare structure traversals: {sb:?} vs {sa:?}"
    );
}

#[test]
fn gradients_only_with_shading() {
    let case = jittered_cube(5);
    let camera = Camera::view(case.mesh.bounds(), 24, 24, 20.0, 30.0, 1.0);
    for path in PATHS {
        let (plain, off) = render(
            &case.mesh,
            &case.axis,
            StructureKind::CartGrid,
            path,
            None,
            &camera,
            24,
        );
        assert_eq!(off.gradient_evaluations, 0);
        let (shaded, on) = render(
            &case.mesh,
            &case.axis,
            StructureKind::CartGrid,
            path,
            Some(Shading::default()),
            &camera,
            24,
        );
        assert!(on.gradient_evaluations > 0);
        assert!(shaded.rgba.iter().flatten().all(|v| v.is_finite()));
        assert!(
            plain.max_abs_difference(&shaded) > 1e-3,
            "shading changes the image"
        );
        // Opacity does not depend on shading.
        for (p, q) in plain.rgba.iter().zip(&shaded.rgba) {
            assert_eq!(p[3], q[3]);
        }
    }
}

#[test]
fn one_and_two_threads_give_identical_images() {
    let case = o_grid();
    let camera = Camera::view(case.mesh.bounds(), 37, 29, 60.0, -20.0, 1.0);
    let run = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .expect("pool");
        pool.install(|| {
            render(
                &case.mesh,
                &case.axis,
                StructureKind::CylGrid,
                RenderPath::Fast,
                Some(Shading::default()),
                &camera,
                37,
            )
        })
    };
    let (a, sa) = run(1);
    let (b, sb) = run(2);
    assert_eq!(a, b);
    assert_eq!(sa, sb);
}

/// The default step, which the CLI and the C ABI render with, has the same bits whatever the
/// thread count (a parallel sum groups its terms as the work happens to be split).
#[test]
fn the_default_step_does_not_depend_on_the_threads() {
    let mesh =
        cylvol::datasets::generate(cylvol::datasets::Dataset::PumpRotor, 60_000).expect("rotor");
    let step = |threads: usize| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .expect("pool")
            .install(|| cylvol::render::default_step(&mesh))
    };
    let one = step(1);
    assert!(one > 0.0);
    for threads in [2, 3, 7] {
        for _ in 0..3 {
            assert_eq!(step(threads).to_bits(), one.to_bits(), "{threads} threads");
        }
    }
}

#[test]
fn a_mesh_moved_far_away_renders_the_same() {
    let case = o_grid();
    let offset = DVec3::new(1e6, -1e6, 1e6);
    let far = moved(&case.mesh, offset);
    let far_axis = Axis::new(offset, DVec3::Z).expect("axis");
    let camera = Camera::view(case.mesh.bounds(), 32, 32, 35.0, 20.0, 1.0);
    let mut far_camera = camera;
    far_camera.eye += offset;
    far_camera.focal += offset;
    for kind in [StructureKind::CartBvh, StructureKind::CylGrid] {
        let (near, _) = render(
            &case.mesh,
            &case.axis,
            kind,
            RenderPath::Fast,
            Some(Shading::default()),
            &camera,
            32,
        );
        let (away, _) = render(
            &far,
            &far_axis,
            kind,
            RenderPath::Fast,
            Some(Shading::default()),
            &far_camera,
            32,
        );
        let (a, b) = (near.to_rgba8(Some([0.0; 3])), away.to_rgba8(Some([0.0; 3])));
        let worst = a
            .iter()
            .zip(&b)
            .map(|(x, y)| x.abs_diff(*y))
            .max()
            .unwrap_or(0);
        assert!(worst <= 1, "{kind}: differs by {worst}/255");
        assert!(a.iter().any(|&v| v > 20), "the image is not empty");
    }
}

#[test]
fn a_camera_inside_the_mesh_renders() {
    let case = annulus(true);
    let eye = frame().from_cylindrical(0.75, 0.3, 0.5);
    let focal = frame().from_cylindrical(0.75, 1.2, 0.5);
    for camera in [
        Camera::perspective(eye, focal, DVec3::Z, 60.0).expect("camera"),
        Camera::parallel(eye, focal, DVec3::Z, 0.2).expect("camera"),
    ] {
        for path in PATHS {
            let (image, stats) = render(
                &case.mesh,
                &case.axis,
                StructureKind::CylBvh,
                path,
                Some(Shading::default()),
                &camera,
                24,
            );
            assert!(image.rgba.iter().flatten().all(|v| v.is_finite()));
            assert!(stats.samples_located > 0);
            // Every ray starts inside the material.
            assert!(image.rgba.iter().all(|p| p[3] > 0.0), "{camera:?}");
        }
    }
}

#[test]
fn depth_in_stops_rays_and_depth_out_is_reported() {
    let case = o_grid();
    let accel = Accel::build(
        &case.mesh,
        StructureKind::CartBvh,
        &case.axis,
        &AccelParams::default(),
    )
    .expect("build");
    let volume = Volume::new(&case.mesh, &accel).expect("volume");
    let tf = TransferFunction::constant([1.0; 3], 0.9, 0.1);
    let options = RenderOptions::new(16, 16, 0.01);
    let r = Renderer::new(&volume, &tf, &options).expect("renderer");
    let camera = Camera::perspective(
        DVec3::new(0.0, 0.0, 4.0),
        DVec3::new(0.0, 0.0, 0.5),
        DVec3::Y,
        20.0,
    )
    .expect("camera");
    let (image, stats) = r.render(&camera, None).expect("render");
    assert!(stats.early_terminations > 0);
    // The centre ray enters the top face at distance 3: the depth sample is within a few steps.
    let centre = image.depth[8 * 16 + 8] as f64;
    assert!(centre > 3.0 && centre < 3.0 + 0.1, "{centre}");
    // Opaque geometry at distance 3.02 leaves two samples.
    let (stopped, _) = r
        .render(&camera, Some(&vec![3.02f32; 256]))
        .expect("render");
    let a = stopped.rgba[8 * 16 + 8][3] as f64;
    let one = 1.0 - (1.0f64 - 0.9).powf(0.1);
    assert!((a - (1.0 - (1.0 - one).powi(2))).abs() < 1e-6, "{a}");
    assert!(r.render(&camera, Some(&[1.0f32; 3])).is_err());
}

#[test]
fn a_cell_scalar_renders_constant_per_cell() {
    let case = jittered_cube(4);
    let mut parts = case.mesh.clone().into_parts();
    let n = parts.cells.len();
    parts.point_data.clear();
    parts.cell_data = vec![DataArray::scalar(
        "id",
        (0..n).map(|c| (c % 7) as f64).collect(),
    )];
    let mesh = Mesh::from_parts(parts).expect("valid");
    let camera = Camera::view(mesh.bounds(), 20, 20, 10.0, 10.0, 1.0);
    let (paper, _) = render(
        &mesh,
        &case.axis,
        StructureKind::CartBvh,
        RenderPath::Paper,
        Some(Shading::default()),
        &camera,
        20,
    );
    let (fast, stats) = render(
        &mesh,
        &case.axis,
        StructureKind::CylBvh,
        RenderPath::Fast,
        Some(Shading::default()),
        &camera,
        20,
    );
    assert!(paper.max_abs_difference(&fast) <= 1e-6);
    assert_eq!(
        stats.gradient_evaluations, 0,
        "a cell scalar has no gradient to evaluate"
    );
}
