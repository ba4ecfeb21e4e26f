//! The BVHs against brute force, for every preset: random boxes and sectors (arcs across ±π
//! and 0, sectors straddling the axis) and real and synthetic meshes (seams, a full ring, cells
//! on the axis, a mesh far from the origin).

use std::f64::consts::{PI, TAU};
use std::path::Path;

use cylvol::accel::bvh::{build_bvh, Bvh, BvhBounds, BvhParams};
use cylvol::accel::space::{self, Coordinates, Pieces};
use cylvol::accel::Counters;
use cylvol::axis::Axis;
use cylvol::datasets::{generate, Dataset};
use cylvol::geometry::bounds::Aabb;
use cylvol::geometry::containment::locate_in_cell;
use cylvol::geometry::cylindrical::{CylBounds, CylFrame, ThetaInterval};
use cylvol::geometry::trilinear::map;
use cylvol::{CellKind, Mesh, MeshParts};
use glam::DVec3;
use proptest::prelude::*;

/// Every cell `find` offers when nothing is accepted, sorted.
fn offered<B: BvhBounds>(bvh: &Bvh<B>, q: DVec3) -> Vec<u32> {
    let mut seen = Vec::new();
    let mut counters = Counters::default();
    let r = bvh.find(q, &mut counters, |c| {
        seen.push(c);
        false
    });
    assert_eq!(r, None);
    if !seen.is_empty() {
        assert!(counters.leaf_visits >= 1);
    }
    seen.sort_unstable();
    seen
}

/// Checks `find` against brute force over the pieces: it offers every piece whose bound
/// contains `q` (`exact`), and none whose slightly padded bound does not (`loose`).
fn check_point<B: BvhBounds>(
    bvh: &Bvh<B>,
    pieces: &Pieces<B>,
    q: DVec3,
    loose: impl Fn(&B, DVec3) -> bool,
) {
    let got = offered(bvh, q);
    let mut exact: Vec<u32> = Vec::new();
    let mut allowed: Vec<u32> = Vec::new();
    for (b, &c) in pieces.bounds.iter().zip(&pieces.cells) {
        if b.contains_point(q) {
            exact.push(c);
        }
        if loose(b, q) {
            allowed.push(c);
        }
    }
    exact.sort_unstable();
    allowed.sort_unstable();
    let mut dedup = got.clone();
    dedup.dedup();
    for c in &exact {
        assert!(dedup.binary_search(c).is_ok(), "cell {c} missed at {q:?}");
    }
    for c in &dedup {
        assert!(
            allowed.binary_search(c).is_ok(),
            "cell {c} offered at {q:?} though no piece of it is near"
        );
    }
    // Each piece at most once: a cell is offered at most as often as it has pieces.
    for c in &dedup {
        let offers = got.iter().filter(|x| *x == c).count();
        let count = pieces.cells.iter().filter(|x| *x == c).count();
        assert!(offers <= count);
    }
}

fn box_loose(b: &Aabb, q: DVec3) -> bool {
    let scale = 1.0 + b.min.abs().max(b.max.abs()).max_element();
    b.padded(1e-6 * scale).contains(q)
}

fn sector_loose(b: &CylBounds, q: DVec3) -> bool {
    if b.is_empty() {
        return false;
    }
    let e = 1e-6 * (1.0 + b.r[1].abs().max(b.h[0].abs()).max(b.h[1].abs()));
    let padded = CylBounds {
        r: [b.r[0] - e, b.r[1] + e],
        theta: b.theta.padded(2e-6),
        h: [b.h[0] - e, b.h[1] + e],
        ..*b
    };
    padded.contains(q.x, q.y, q.z)
        || (q.x <= e && b.r[0] <= e && q.z >= padded.h[0] && q.z <= padded.h[1])
}

fn arb_box() -> impl Strategy<Value = Aabb> {
    (
        prop::array::uniform3(-10.0f64..10.0),
        prop::array::uniform3(0.0f64..3.0),
    )
        .prop_map(|(lo, d)| {
            let lo = DVec3::from_array(lo);
            Aabb::new(lo, lo + DVec3::from_array(d))
        })
}

fn arb_angle() -> impl Strategy<Value = f64> {
    prop_oneof![
        -PI..PI,
        (PI - 0.3)..PI, // just before the seam at ±π
        -0.3f64..0.0,   // just before 0
        Just(PI),
        Just(-PI + 1e-12),
    ]
}

fn arb_sector() -> impl Strategy<Value = CylBounds> {
    (
        0.0f64..2.0,
        0.0f64..1.0,
        arb_angle(),
        prop_oneof![0.0f64..0.6, 0.0f64..TAU, Just(TAU)],
        -2.0f64..2.0,
        0.0f64..1.0,
        0u8..8,
    )
        .prop_map(|(r0, dr, start, width, h0, dh, kind)| {
            if kind == 0 {
                // Straddles the axis.
                CylBounds {
                    r: [0.0, r0 + dr],
                    theta: ThetaInterval::FULL,
                    h: [h0, h0 + dh],
                    straddles_axis: true,
                }
            } else {
                CylBounds {
                    r: [if kind == 1 { 0.0 } else { r0 }, r0 + dr],
                    theta: ThetaInterval::new(start, width),
                    h: [h0, h0 + dh],
                    straddles_axis: false,
                }
            }
        })
}

fn arb_cyl_point() -> impl Strategy<Value = DVec3> {
    (
        prop_oneof![0.0f64..3.2, Just(0.0)],
        prop_oneof![-PI..PI, Just(PI), (PI - 1e-3)..PI, -1e-3f64..1e-3],
        -2.2f64..3.2,
    )
        .prop_map(|(r, t, h)| DVec3::new(r, if t <= -PI { PI } else { t }, h))
}

fn pieces_of<B>(bounds: Vec<B>) -> Pieces<B> {
    // Some cells get several pieces.
    let cells = (0..bounds.len() as u32).map(|i| i / 2 + i % 3).collect();
    Pieces { bounds, cells }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    #[test]
    fn boxes_offer_exactly_the_containing_pieces(
        bounds in prop::collection::vec(arb_box(), 0..300),
        points in prop::collection::vec(prop::array::uniform3(-11.0f64..14.0), 1..40),
    ) {
        let pieces = pieces_of(bounds);
        for (_, params) in BvhParams::PRESETS {
            let bvh = build_bvh(&pieces, &params);
            bvh.assert_well_formed(&pieces);
            for p in &points {
                check_point(&bvh, &pieces, DVec3::from_array(*p), box_loose);
            }
            // Points at piece corners lie on bounds: found.
            for b in pieces.bounds.iter().take(20) {
                check_point(&bvh, &pieces, b.min, box_loose);
                check_point(&bvh, &pieces, b.max, box_loose);
            }
        }
    }

    #[test]
    fn sectors_offer_exactly_the_containing_pieces(
        bounds in prop::collection::vec(arb_sector(), 0..300),
        points in prop::collection::vec(arb_cyl_point(), 1..40),
    ) {
        let pieces = pieces_of(bounds);
        for (_, params) in BvhParams::PRESETS {
            let bvh = build_bvh(&pieces, &params);
            bvh.assert_well_formed(&pieces);
            for p in &points {
                check_point(&bvh, &pieces, *p, sector_loose);
            }
            // Points at the ends of arcs (the seam included) lie on bounds: found.
            for b in pieces.bounds.iter().take(20).filter(|b| !b.theta.is_full()) {
                let h = 0.5 * (b.h[0] + b.h[1]);
                let r = 0.5 * (b.r[0] + b.r[1]);
                check_point(&bvh, &pieces, DVec3::new(r, b.theta.start(), h), sector_loose);
                check_point(&bvh, &pieces, DVec3::new(r, b.theta.end(), h), sector_loose);
            }
        }
    }
}

/// The bits of the stored form of the union of `bounds`' linear boxes, and of the union of
/// their stored forms' corners: the build takes the second for the first.
fn union_two_ways<B: BvhBounds>(bounds: &[B]) -> ([u32; 6], [u32; 6]) {
    let frame = B::frame_of(&B::union_all(bounds));
    let lin = bounds
        .iter()
        .fold(Aabb::EMPTY, |u, b| u.union(&b.linearize(&frame)));
    let direct = B::compact(&lin, &frame);
    let (mut lo, mut hi) = ([f32::INFINITY; 3], [f32::NEG_INFINITY; 3]);
    for b in bounds {
        let (l, h) = B::compact_corners(&B::compact(&b.linearize(&frame), &frame));
        for a in 0..3 {
            lo[a] = lo[a].min(l[a]);
            hi[a] = hi[a].max(h[a]);
        }
    }
    let corners = B::compact_from_corners(lo, hi);
    // The corners give back the stored form they came from.
    let (l, h) = B::compact_corners(&direct);
    assert_eq!(
        B::compact_bits(&B::compact_from_corners(l, h)),
        B::compact_bits(&direct)
    );
    (B::compact_bits(&direct), B::compact_bits(&corners))
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(256))]

    #[test]
    fn stored_box_of_a_union_is_the_union_of_stored_corners(
        mut bounds in prop::collection::vec(arb_box(), 0..20),
        far in prop_oneof![Just(0.0f64), Just(1e6f64)],
        empty in any::<bool>(),
    ) {
        for b in &mut bounds {
            *b = Aabb::new(b.min + far, b.max + far);
        }
        if empty {
            bounds.push(Aabb::EMPTY);
        }
        let (direct, corners) = union_two_ways(&bounds);
        prop_assert_eq!(direct, corners);
    }

    #[test]
    fn stored_sector_of_a_union_is_the_union_of_stored_corners(
        mut bounds in prop::collection::vec(arb_sector(), 0..20),
        empty in any::<bool>(),
    ) {
        if empty {
            bounds.push(CylBounds::EMPTY);
        }
        let (direct, corners) = union_two_ways(&bounds);
        prop_assert_eq!(direct, corners);
    }
}

/// The ray's interval in `b` on `[t0, t1]` by the textbook slabs (a zero direction component
/// tests the origin), `None` where it misses.
fn ray_in_box(b: &Aabb, o: DVec3, d: DVec3, t0: f64, t1: f64) -> Option<(f64, f64)> {
    let (mut lo, mut hi) = (t0, t1);
    for a in 0..3 {
        if d[a] == 0.0 {
            if o[a] < b.min[a] || o[a] > b.max[a] {
                return None;
            }
        } else {
            let (s, e) = ((b.min[a] - o[a]) / d[a], (b.max[a] - o[a]) / d[a]);
            lo = lo.max(s.min(e));
            hi = hi.min(s.max(e));
        }
    }
    (lo <= hi).then_some((lo, hi))
}

/// A direction component: any, or a zero of either sign (rays parallel to box faces).
fn arb_component() -> impl Strategy<Value = f64> {
    prop_oneof![-1.0f64..1.0, Just(0.0), Just(-0.0)]
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    /// `first_along` finds the first box a ray meets, as brute force does: never later (the
    /// stored boxes are rounded outwards and padded), and its answer lies on its piece's box
    /// (within that rounding). Rays parallel to the boxes' faces, and along them (the origin
    /// on a face's plane), included.
    #[test]
    fn rays_meet_the_first_box_brute_force_meets(
        bounds in prop::collection::vec(arb_box(), 1..200),
        rays in prop::collection::vec(
            (prop::array::uniform3(-12.0f64..12.0), [arb_component(), arb_component(), arb_component()], any::<prop::sample::Index>(), 0usize..4),
            1..30,
        ),
        t1 in prop_oneof![Just(f64::INFINITY), 1.0f64..40.0],
    ) {
        let pieces = pieces_of(bounds);
        for (_, params) in BvhParams::PRESETS {
            let bvh = build_bvh(&pieces, &params);
            for (o, d, pick, snap) in &rays {
                let (mut o, d) = (DVec3::from_array(*o), DVec3::from_array(*d));
                if d.length() < 1e-3 {
                    continue;
                }
                // Snap the origin onto a box's face plane along one axis.
                if *snap < 3 {
                    o[*snap] = pick.get(&pieces.bounds).min[*snap];
                }
                let want = pieces
                    .bounds
                    .iter()
                    .filter_map(|b| ray_in_box(b, o, d, 0.0, t1))
                    .map(|s| s.0)
                    .fold(f64::INFINITY, f64::min);
                let mut counters = Counters::default();
                let got = bvh.first_along(o, d, 0.0, t1, &mut counters, |_, lo, hi| Some((lo, hi)));
                if want.is_finite() {
                    let (e, _, _) = got.expect("a box the ray meets is found");
                    prop_assert!(e <= want + 1e-9, "{e} after {want}");
                }
                if let Some((e, x, cell)) = got {
                    prop_assert!(e <= x && e.is_finite() && x.is_finite());
                    let p = o + d * e;
                    let near = pieces.bounds.iter().zip(&pieces.cells).any(|(b, &c)| {
                        c == cell && b.padded(1e-5 * (1.0 + b.diagonal())).contains(p)
                    });
                    prop_assert!(near, "entry {p} is on no box of cell {cell}");
                }
            }
        }
    }
}

#[test]
fn empty_and_degenerate_pieces_do_not_break_the_build() {
    let empty: Pieces<Aabb> = Pieces::default();
    for (_, params) in BvhParams::PRESETS {
        let bvh = build_bvh(&empty, &params);
        bvh.assert_well_formed(&empty);
        assert_eq!(
            bvh.find(DVec3::ZERO, &mut Counters::default(), |_| true),
            None
        );
        assert_eq!(bvh.stats().nodes, 0);
    }
    // Identical boxes (no centroid spread), empty boxes and NaN boxes mixed.
    let mut bounds = vec![Aabb::new(DVec3::ZERO, DVec3::ONE); 40];
    bounds.push(Aabb::EMPTY);
    bounds.push(Aabb::new(DVec3::NAN, DVec3::ONE));
    let pieces = pieces_of(bounds);
    for (_, params) in BvhParams::PRESETS {
        let bvh = build_bvh(&pieces, &params);
        bvh.assert_well_formed(&pieces);
        assert_eq!(offered(&bvh, DVec3::splat(0.5)).len(), 40);
        assert!(offered(&bvh, DVec3::splat(1.5)).is_empty());
    }
    let sectors = pieces_of(vec![
        CylBounds::EMPTY,
        CylBounds {
            r: [0.0, 1.0],
            theta: ThetaInterval::FULL,
            h: [0.0, 1.0],
            straddles_axis: true,
        },
    ]);
    let bvh = build_bvh(&sectors, &BvhParams::default());
    bvh.assert_well_formed(&sectors);
    assert_eq!(offered(&bvh, DVec3::new(0.0, 0.0, 0.5)).len(), 1);
}

// ---------------------------------------------------------------- meshes

/// A structured hexahedral mesh from a point function on an `ni × nj × nk` lattice of cells;
/// `wrap_j` joins the last j layer to the first (a full ring).
fn structured(
    ni: usize,
    nj: usize,
    nk: usize,
    wrap_j: bool,
    point: impl Fn(f64, f64, f64) -> DVec3,
) -> Mesh {
    let pj = if wrap_j { nj } else { nj + 1 };
    let id = |i: usize, j: usize, k: usize| ((k * pj + j % pj) * (ni + 1) + i) as u32;
    let mut points = Vec::new();
    for k in 0..=nk {
        for j in 0..pj {
            for i in 0..=ni {
                points.push(point(
                    i as f64 / ni as f64,
                    j as f64 / nj as f64,
                    k as f64 / nk as f64,
                ));
            }
        }
    }
    let mut cells = Vec::new();
    for k in 0..nk {
        for j in 0..nj {
            for i in 0..ni {
                cells.push(cylvol::io::structured::cell_ids(i, j, k, id));
            }
        }
    }
    let kinds = vec![CellKind::Hexahedron; cells.len()];
    Mesh::from_parts(MeshParts {
        points,
        cells,
        kinds,
        point_data: Vec::new(),
        cell_data: Vec::new(),
    })
    .expect("valid test mesh")
}

/// An annular sector about z: r in [1, 2], θ from `t0` over `width`, z in [0, 1].
fn sector_mesh(t0: f64, width: f64, wrap: bool) -> Mesh {
    structured(4, 24, 3, wrap, move |u, v, w| {
        let r = 1.0 + u;
        let t = t0 + width * v;
        DVec3::new(r * t.cos(), r * t.sin(), w)
    })
}

/// A block `[-1, 1]² × [0, 1]` about the z axis: cells straddle and touch the axis.
fn block_on_axis(n: usize) -> Mesh {
    structured(n, n, 2, false, |u, v, w| {
        DVec3::new(2.0 * u - 1.0, 2.0 * v - 1.0, w)
    })
}

fn shifted(mesh: &Mesh, by: DVec3) -> Mesh {
    let mut parts = mesh.clone().into_parts();
    for p in &mut parts.points {
        *p += by;
    }
    Mesh::from_parts(parts).expect("shifted mesh")
}

/// Tiny deterministic generator for test points.
struct Lcg(u64);
impl Lcg {
    fn next(&mut self) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }
}

/// Points inside random cells, at random cell corners, and anywhere in the mesh's box.
fn sample_points(mesh: &Mesh, count: usize, seed: u64) -> Vec<DVec3> {
    let mut rng = Lcg(seed);
    let b = mesh.bounds();
    let lo = DVec3::new(b[0], b[2], b[4]);
    let hi = DVec3::new(b[1], b[3], b[5]);
    let pad = (hi - lo) * 0.05;
    let n = mesh.cell_count();
    (0..count)
        .map(|i| {
            let c = ((rng.next() * n as f64) as usize).min(n - 1);
            match i % 4 {
                0 | 1 => {
                    let u = DVec3::new(rng.next(), rng.next(), rng.next());
                    map(&mesh.cell_corners(c), u)
                }
                2 => mesh.cell_corners(c)[(rng.next() * 8.0) as usize % 8],
                _ => {
                    let u = DVec3::new(rng.next(), rng.next(), rng.next());
                    lo - pad + (hi - lo + 2.0 * pad) * u
                }
            }
        })
        .collect()
}

/// The BVH finds a cell exactly when brute force over all cells does, and the cell it returns
/// contains the point.
fn check_mesh_bvh<B: BvhBounds>(
    name: &str,
    mesh: &Mesh,
    pieces: &Pieces<B>,
    coords: Coordinates,
    points: &[DVec3],
    brute: &[bool],
) {
    for (preset, params) in BvhParams::PRESETS {
        let bvh = build_bvh(pieces, &params);
        bvh.assert_well_formed(pieces);
        let mut counters = Counters::default();
        for (p, &expected) in points.iter().zip(brute) {
            let found = bvh.find(coords.of(*p), &mut counters, |c| {
                locate_in_cell(&mesh.cell_corners(c as usize), *p, None).is_some()
            });
            assert_eq!(
                found.is_some(),
                expected,
                "{name} ({preset}): BVH and brute force disagree at {p:?}"
            );
            if let Some(c) = found {
                assert!(locate_in_cell(&mesh.cell_corners(c as usize), *p, None).is_some());
            }
        }
    }
}

fn check_mesh(name: &str, mesh: &Mesh, axis: Axis, seam: bool, count: usize) {
    let points = sample_points(mesh, count, 7);
    let brute: Vec<bool> = points
        .iter()
        .map(|p| {
            (0..mesh.cell_count())
                .any(|c| locate_in_cell(&mesh.cell_corners(c), *p, None).is_some())
        })
        .collect();
    assert!(
        brute.iter().filter(|b| **b).count() >= count / 2,
        "{name}: too few points inside"
    );
    let cart = space::cartesian_pieces(mesh);
    check_mesh_bvh(name, mesh, &cart, Coordinates::Cartesian, &points, &brute);
    let frame = CylFrame::new(axis.origin, axis.direction).expect("frame");
    let pieces = space::cylindrical_pieces(mesh, &frame, space::DEFAULT_STRADDLE_SECTORS);
    let (frame, pieces) = if seam {
        space::seam_frame(&axis, pieces).expect("seam frame")
    } else {
        (frame, pieces)
    };
    check_mesh_bvh(
        name,
        mesh,
        &pieces,
        Coordinates::Cylindrical(frame),
        &points,
        &brute,
    );
}

fn z_axis(origin: DVec3) -> Axis {
    Axis {
        origin,
        direction: DVec3::Z,
    }
}

#[test]
fn pump_datasets() {
    for d in [
        Dataset::PumpInlet,
        Dataset::PumpRotor,
        Dataset::PumpDiffuser,
    ] {
        let mesh = generate(d, 8_000).expect("dataset");
        let axis = cylvol::axis::detect(&mesh);
        check_mesh(d.name(), &mesh, axis, true, 300);
    }
}

#[test]
fn sectors_across_the_seams_and_a_full_ring() {
    // Across ±π, without rotating the seam away (pieces cross it) and with.
    let across_pi = sector_mesh(PI - 0.6, 1.2, false);
    check_mesh("across ±π", &across_pi, z_axis(DVec3::ZERO), false, 300);
    check_mesh(
        "across ±π, rotated",
        &across_pi,
        z_axis(DVec3::ZERO),
        true,
        200,
    );
    let across_0 = sector_mesh(-0.6, 1.2, false);
    check_mesh("across 0", &across_0, z_axis(DVec3::ZERO), false, 300);
    let ring = sector_mesh(0.1, TAU, true);
    check_mesh("full ring", &ring, z_axis(DVec3::ZERO), true, 400);
}

#[test]
fn cells_on_the_axis() {
    // Odd: the axis runs through a cell; even: along cell edges.
    check_mesh("block 5", &block_on_axis(5), z_axis(DVec3::ZERO), true, 300);
    check_mesh("block 4", &block_on_axis(4), z_axis(DVec3::ZERO), true, 300);
}

#[test]
fn mesh_far_from_the_origin() {
    let by = DVec3::new(1e6, -1e6, 1e6);
    let ring = shifted(&sector_mesh(0.1, TAU, true), by);
    check_mesh("ring moved 1e6", &ring, z_axis(by), true, 300);
    let rotor = shifted(&generate(Dataset::PumpRotor, 5_000).expect("rotor"), by);
    let axis = cylvol::axis::detect(&rotor);
    check_mesh("rotor moved 1e6", &rotor, axis, true, 200);
    // The stored bounds stay tight: the surface area matches the unshifted BVH's.
    let near = space::cartesian_pieces(&sector_mesh(0.1, TAU, true));
    let far = space::cartesian_pieces(&ring);
    let (a, b) = (
        build_bvh(&near, &BvhParams::default()).stats().surface_area,
        build_bvh(&far, &BvhParams::default()).stats().surface_area,
    );
    assert!((a - b).abs() <= 1e-3 * a, "near {a}, far {b}");
}

fn plot3d(name: &str) -> Mesh {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data")
        .join(name);
    cylvol::io::read_file(&path, &Default::default()).expect("PLOT3D mesh")
}

#[test]
fn plot3d_meshes() {
    for name in ["postxyz.bin", "combxyz.bin"] {
        let mesh = plot3d(name);
        let axis = cylvol::axis::detect(&mesh);
        check_mesh(name, &mesh, axis, true, 120);
    }
}

#[test]
fn cylindrical_bvh_has_less_surface_on_a_ring() {
    let mesh = generate(Dataset::PumpRotor, 20_000).expect("rotor");
    let axis = z_axis(DVec3::ZERO);
    let cart = build_bvh(&space::cartesian_pieces(&mesh), &BvhParams::default());
    let frame = CylFrame::new(axis.origin, axis.direction).expect("frame");
    let pieces = space::cylindrical_pieces(&mesh, &frame, space::DEFAULT_STRADDLE_SECTORS);
    let (_, pieces) = space::seam_frame(&axis, pieces).expect("seam");
    let cyl = build_bvh(&pieces, &BvhParams::default());
    let (c, y) = (cart.stats(), cyl.stats());
    assert!(y.surface_area < c.surface_area, "cyl {y:?} vs cart {c:?}");
    let ring = sector_mesh(0.1, TAU, true);
    let cart = build_bvh(&space::cartesian_pieces(&ring), &BvhParams::default());
    let pieces = space::cylindrical_pieces(&ring, &frame, space::DEFAULT_STRADDLE_SECTORS);
    let cyl = build_bvh(&pieces, &BvhParams::default());
    assert!(cyl.stats().surface_area < cart.stats().surface_area);
}
