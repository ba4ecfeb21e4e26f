//! Two-level grids: candidates against brute force over the boxes (Cartesian and cylindrical),
//! point location against brute force over all cells on small and real meshes (sectors across
//! θ = ±π and θ = 0, a full ring, cells on the axis, a far-away mesh), well-formedness, presets.

use std::collections::BTreeSet;
use std::f64::consts::PI;
use std::path::Path;

use cylvol::accel::grid::{build_grid, CandidateOrder, GridParams, TwoLevelGrid};
use cylvol::accel::space::{self, Coordinates, Pieces};
use cylvol::accel::Counters;
use cylvol::datasets::{generate, Dataset};
use cylvol::geometry::bounds::Aabb;
use cylvol::geometry::containment::locate_in_cell;
use cylvol::geometry::cylindrical::{CylBounds, CylFrame, ThetaInterval};
use cylvol::geometry::trilinear::map;
use cylvol::{CellKind, Mesh, MeshParts};
use glam::DVec3;
use proptest::prelude::*;

// ---------------------------------------------------------------------------------------------
// Candidates against brute force over boxes.

/// The cells `find` offers with an accept that always refuses, checked for duplicates.
fn offered(grid: &TwoLevelGrid, q: DVec3) -> (BTreeSet<u32>, Counters) {
    let mut counters = Counters::default();
    let mut seen = Vec::new();
    let found = grid.find(q, &mut counters, |c| {
        seen.push(c);
        false
    });
    assert_eq!(found, None);
    let set: BTreeSet<u32> = seen.iter().copied().collect();
    assert_eq!(set.len(), seen.len(), "a cell was offered twice: {seen:?}");
    assert_eq!(seen, grid.candidates(q), "find and candidates disagree");
    (set, counters)
}

/// Checks the candidates of `q` against brute force: every cell with a box containing `q` is
/// offered, every cell offered has a box touching `q`'s leaf cell, and every cell whose box
/// overlaps the leaf cell's interior is offered.
fn check_candidates(grid: &TwoLevelGrid, pieces: &Pieces<Aabb>, q: DVec3) {
    let containing: BTreeSet<u32> = pieces
        .bounds
        .iter()
        .zip(&pieces.cells)
        .filter(|(b, _)| b.contains(q))
        .map(|(_, &c)| c)
        .collect();
    let (set, counters) = offered(grid, q);
    assert!(
        containing.is_subset(&set),
        "q {q:?}: cells {containing:?} contain it but {set:?} were offered"
    );
    match grid.leaf_cell_bounds(q) {
        None => {
            assert!(set.is_empty());
            assert!(
                containing.is_empty(),
                "q {q:?} in boxes but found no leaf cell"
            );
            assert_eq!(counters.leaf_visits, 0);
        }
        Some(leaf) => {
            assert_eq!((counters.internal_visits, counters.leaf_visits), (1, 1));
            let slack = 1e-9 * (grid.domain().diagonal() + grid.domain().max.abs().max_element());
            let touching: BTreeSet<u32> = pieces
                .bounds
                .iter()
                .zip(&pieces.cells)
                .filter(|(b, _)| b.overlaps(&leaf.padded(slack)))
                .map(|(_, &c)| c)
                .collect();
            let inner = Aabb::new(leaf.min + slack, leaf.max - slack);
            let overlapping: BTreeSet<u32> = pieces
                .bounds
                .iter()
                .zip(&pieces.cells)
                .filter(|(b, _)| !inner.is_empty() && b.overlaps(&inner))
                .map(|(_, &c)| c)
                .collect();
            assert!(
                set.is_subset(&touching),
                "q {q:?}: offered {set:?}, touching {touching:?}"
            );
            assert!(
                overlapping.is_subset(&set),
                "q {q:?}: overlapping {overlapping:?}, offered {set:?}"
            );
        }
    }
    if !grid.domain().contains(q) {
        assert_eq!(counters, Counters::default(), "work outside the domain");
    }
}

fn arb_box(lo: [f64; 3], hi: [f64; 3]) -> impl Strategy<Value = Aabb> {
    let axis = |a: f64, b: f64| (a..b, 0.0..(b - a) * 0.3);
    (axis(lo[0], hi[0]), axis(lo[1], hi[1]), axis(lo[2], hi[2])).prop_map(
        move |((x, dx), (y, dy), (z, dz))| {
            Aabb::new(
                DVec3::new(x, y, z),
                DVec3::new(
                    (x + dx).min(hi[0]),
                    (y + dy).min(hi[1]),
                    (z + dz).min(hi[2]),
                ),
            )
        },
    )
}

fn arb_params() -> impl Strategy<Value = GridParams> {
    (0.01f64..4.0, 0.1f64..12.0, any::<bool>()).prop_map(|(top_density, leaf_density, share)| {
        GridParams {
            top_density,
            leaf_density,
            order: if share {
                CandidateOrder::LargestShare
            } else {
                CandidateOrder::Cells
            },
        }
    })
}

/// Pieces with some cells owning two pieces.
fn arb_pieces(lo: [f64; 3], hi: [f64; 3]) -> impl Strategy<Value = Pieces<Aabb>> {
    prop::collection::vec((arb_box(lo, hi), 0u32..40), 1..80).prop_map(|v| {
        let (bounds, cells) = v.into_iter().unzip();
        Pieces { bounds, cells }
    })
}

/// Points: corners and centres of boxes (boundaries) and random ones, some outside.
fn points_of(pieces: &Pieces<Aabb>, extra: &[DVec3]) -> Vec<DVec3> {
    let mut pts: Vec<DVec3> = extra.to_vec();
    for b in pieces.bounds.iter().take(10) {
        pts.extend([
            b.min,
            b.max,
            b.center(),
            DVec3::new(b.min.x, b.max.y, b.center().z),
        ]);
    }
    pts
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(96))]

    #[test]
    fn cartesian_candidates_match_brute_force(
        pieces in arb_pieces([-3.0, 0.0, 10.0], [5.0, 2.0, 11.0]),
        params in arb_params(),
        extra in prop::collection::vec((-4.0f64..6.0, -0.5f64..2.5, 9.8f64..11.2), 40),
    ) {
        let grid = build_grid(Coordinates::Cartesian, &pieces, &params);
        grid.assert_well_formed(&pieces);
        let extra: Vec<DVec3> = extra.into_iter().map(|(x, y, z)| DVec3::new(x, y, z)).collect();
        for q in points_of(&pieces, &extra) {
            check_candidates(&grid, &pieces, q);
        }
    }

    #[test]
    fn cylindrical_candidates_match_brute_force(
        pieces in arb_pieces([0.0, -PI, -1.0], [3.0, PI, 1.0]),
        params in arb_params(),
        extra in prop::collection::vec((-0.2f64..3.2, -3.2f64..3.2, -1.2f64..1.2), 40),
    ) {
        let frame = CylFrame::new(DVec3::ZERO, DVec3::Z).unwrap();
        let grid = build_grid(Coordinates::Cylindrical(frame), &pieces, &params);
        grid.assert_well_formed(&pieces);
        let extra: Vec<DVec3> = extra.into_iter().map(|(x, y, z)| DVec3::new(x, y, z)).collect();
        for q in points_of(&pieces, &extra) {
            check_candidates(&grid, &pieces, q);
        }
    }

    /// Sectors (some across the seam, some full circles at the axis) through `linear_boxes`:
    /// a Cartesian point inside a sector finds its cell.
    #[test]
    fn sectors_through_linear_boxes(
        sectors in prop::collection::vec(
            (0.0f64..2.0, 0.0f64..1.0, -PI..PI, 0.0f64..2.5, -1.0f64..1.0, 0.0f64..0.5, 0u32..30, prop::bool::weighted(0.1)),
            1..60),
        points in prop::collection::vec((-3.0f64..3.0, -3.0f64..3.0, -1.1f64..1.6), 60),
        params in arb_params(),
    ) {
        let mut cyl = Pieces::default();
        for (r0, dr, t0, dt, h0, dh, cell, full) in sectors {
            cyl.bounds.push(CylBounds {
                r: if full { [0.0, r0 + dr] } else { [r0, r0 + dr] },
                theta: if full { ThetaInterval::FULL } else { ThetaInterval::new(t0, dt) },
                h: [h0, h0 + dh],
                straddles_axis: full,
            });
            cyl.cells.push(cell);
        }
        let frame = CylFrame::new(DVec3::new(0.5, -0.25, 0.0), DVec3::new(0.1, 0.2, 1.0)).unwrap();
        let boxes = space::linear_boxes(&cyl);
        let coords = Coordinates::Cylindrical(frame);
        let grid = build_grid(coords, &boxes, &params);
        grid.assert_well_formed(&boxes);
        for (x, y, z) in points {
            let p = DVec3::new(x, y, z);
            // The sectors hold (r, θ, h); the grid is queried in (r, φ, h).
            let (r, theta, h) = frame.to_cylindrical(p);
            let q = coords.query(p);
            let brute: BTreeSet<u32> = cyl
                .bounds
                .iter()
                .zip(&cyl.cells)
                .filter(|(b, _)| b.contains(r, theta, h))
                .map(|(_, &c)| c)
                .collect();
            let (set, _) = offered(&grid, q);
            prop_assert!(brute.is_subset(&set), "p {:?} q {:?}: in {:?}, offered {:?}", p, q, brute, set);
            check_candidates(&grid, &boxes, q);
        }
    }
}

#[test]
fn empty_and_degenerate_inputs() {
    let mut counters = Counters::default();
    let none = Pieces::default();
    let g = build_grid(Coordinates::Cartesian, &none, &GridParams::default());
    g.assert_well_formed(&none);
    assert_eq!(g.find(DVec3::ZERO, &mut counters, |_| true), None);
    assert_eq!(g.stats().references, 0);

    // NaN and empty boxes are left out; a flat box and a point box still work.
    let pieces = Pieces {
        bounds: vec![
            Aabb::new(DVec3::NAN, DVec3::ONE),
            Aabb::EMPTY,
            Aabb::new(DVec3::ZERO, DVec3::new(1.0, 1.0, 0.0)),
            Aabb::new(DVec3::splat(0.5), DVec3::new(0.5, 0.5, 0.0)),
            Aabb::new(DVec3::new(0.25, 0.25, 0.0), DVec3::new(0.25, 0.25, 0.0)),
        ],
        cells: vec![0, 1, 2, 3, 4],
    };
    for (_, params) in GridParams::PRESETS {
        let g = build_grid(Coordinates::Cartesian, &pieces, &params);
        g.assert_well_formed(&pieces);
        assert!(g.candidates(DVec3::new(0.25, 0.25, 0.0)).contains(&4));
        assert_eq!(
            g.find(DVec3::new(0.7, 0.2, 0.0), &mut counters, |c| c == 2),
            Some(2)
        );
        assert!(g.candidates(DVec3::new(0.7, 0.2, 1e-3)).is_empty());
        assert!(g.candidates(DVec3::NAN).is_empty());
    }
    let before = counters;
    assert_eq!(
        build_grid(Coordinates::Cartesian, &pieces, &GridParams::PAPER).find(
            DVec3::new(2.0, 0.0, 0.0),
            &mut counters,
            |_| true
        ),
        None
    );
    assert_eq!(counters, before, "a query outside the domain did work");
}

/// Densities far beyond any preset (as a careless caller of the C ABI may pass) are lowered
/// to the grid's memory budget — per piece 16 top cells, 64 leaf cells and 512 references, a
/// few thousand cells and a million references whatever the pieces — instead of allocating
/// gigabytes (the C ABI fuzz target found a 3 GB allocation for twelve hexahedra). The grid
/// still holds every piece where it reaches.
#[test]
fn absurd_densities_stay_within_the_memory_budget() {
    // Twelve unit boxes in a row, and one box over them all (it reaches every grid cell).
    let mut bounds: Vec<Aabb> = (0..12)
        .map(|i| {
            Aabb::new(
                DVec3::new(i as f64, 0.0, 0.0),
                DVec3::new(i as f64 + 1.0, 1.0, 1.0),
            )
        })
        .collect();
    bounds.push(Aabb::new(DVec3::ZERO, DVec3::new(12.0, 1.0, 1.0)));
    let pieces = Pieces {
        cells: (0..bounds.len() as u32).collect(),
        bounds,
    };
    for (top_density, leaf_density) in [(1e12, 1e12), (1.0, 1e15), (1e9, 1.0), (1e-12, 1e300)] {
        let params = GridParams {
            top_density,
            leaf_density,
            ..GridParams::DEFAULT
        };
        let g = build_grid(Coordinates::Cartesian, &pieces, &params);
        g.assert_well_formed(&pieces);
        let stats = g.stats();
        let n = pieces.bounds.len();
        assert!(
            stats.top_cells <= 16 * n + (1 << 12),
            "{params:?}: {stats:?}"
        );
        assert!(
            stats.leaf_cells <= 64 * n + (1 << 16),
            "{params:?}: {stats:?}"
        );
        assert!(
            stats.references <= 512 * n + (1 << 20),
            "{params:?}: {stats:?}"
        );
        assert!(stats.bytes < 64 << 20, "{params:?}: {stats:?}");
        let mut counters = Counters::default();
        assert_eq!(
            g.find(DVec3::new(7.5, 0.5, 0.5), &mut counters, |c| c == 7),
            Some(7)
        );
        assert!(g.candidates(DVec3::new(7.5, 0.5, 0.5)).contains(&12));
    }
}

/// Grid cells follow the pieces' mean shape: stretching every piece and the space they lie in
/// along an axis gives the same grid (the same cells, references and candidates), where cubic
/// grid cells would be cut across the stretched pieces. A lattice of 16 × 8 × 4 unit cubes,
/// and the same lattice stretched 8× along x and ¼ along z (powers of two, so exactly), at
/// densities that give several leaf cells per top cell.
#[test]
fn grid_cells_follow_the_pieces_shape() {
    let lattice = |scale: DVec3| {
        let mut bounds = Vec::new();
        for i in 0..16 {
            for j in 0..8 {
                for k in 0..4 {
                    let lo = DVec3::new(i as f64, j as f64, k as f64);
                    bounds.push(Aabb::new(lo * scale, (lo + DVec3::ONE) * scale));
                }
            }
        }
        Pieces {
            cells: (0..bounds.len() as u32).collect(),
            bounds,
        }
    };
    let params = GridParams {
        top_density: 1.0 / 16.0,
        leaf_density: 0.5,
        ..GridParams::DEFAULT
    };
    let scale = DVec3::new(8.0, 1.0, 0.25);
    let cubes = build_grid(Coordinates::Cartesian, &lattice(DVec3::ONE), &params);
    let stretched_pieces = lattice(scale);
    let stretched = build_grid(Coordinates::Cartesian, &stretched_pieces, &params);
    stretched.assert_well_formed(&stretched_pieces);
    let (a, b) = (cubes.stats(), stretched.stats());
    assert!(a.leaf_cells > a.top_cells, "{a:?}");
    assert_eq!(
        (a.top_cells, a.leaf_cells, a.references),
        (b.top_cells, b.leaf_cells, b.references)
    );
    let mut rng = Rng(0x5eed);
    let mut offered_cubes = 0;
    for _ in 0..500 {
        let q = DVec3::new(16.0 * rng.next(), 8.0 * rng.next(), 4.0 * rng.next());
        let here = cubes.candidates(q);
        assert_eq!(here, stretched.candidates(q * scale), "at {q}");
        offered_cubes += here.len();
    }
    // Unit cubes in grid cells shaped like them: a point is offered the few cubes its leaf
    // cell meets (at most 8 on average here), not a slab of them.
    assert!(offered_cubes <= 8 * 500, "{offered_cubes} candidates");
}

/// With [`CandidateOrder::LargestShare`] a leaf cell offers its candidates largest share
/// first: with leaf cells smaller than a lattice's cubes, a point's first candidate is the
/// cube that holds it (its box covers the leaf cell), ahead of the cubes whose boxes only
/// touch the leaf cell — which come first in cell order (the default), wherever they have
/// smaller ids.
#[test]
fn candidates_come_largest_share_first() {
    let mut bounds = Vec::new();
    for i in 0..8 {
        for j in 0..8 {
            for k in 0..8 {
                let lo = DVec3::new(i as f64, j as f64, k as f64);
                bounds.push(Aabb::new(lo, lo + DVec3::ONE));
            }
        }
    }
    let pieces = Pieces {
        cells: (0..bounds.len() as u32).collect(),
        bounds,
    };
    let params = GridParams {
        top_density: 1.0 / 8.0,
        leaf_density: 27.0,
        order: CandidateOrder::LargestShare,
    };
    let by_share = build_grid(Coordinates::Cartesian, &pieces, &params);
    by_share.assert_well_formed(&pieces);
    let by_cell = build_grid(
        Coordinates::Cartesian,
        &pieces,
        &GridParams {
            order: CandidateOrder::Cells,
            ..params
        },
    );
    let mut rng = Rng(0xfeed);
    let (mut first_holds, mut total) = (0, 0);
    for _ in 0..2000 {
        let q = DVec3::new(8.0 * rng.next(), 8.0 * rng.next(), 8.0 * rng.next());
        let offered = by_share.candidates(q);
        assert!(offered
            .iter()
            .any(|&c| pieces.bounds[c as usize].contains(q)));
        // The same candidates either way; in cell order, sorted.
        let mut sorted = offered.to_vec();
        sorted.sort_unstable();
        assert_eq!(by_cell.candidates(q), sorted);
        total += 1;
        if pieces.bounds[offered[0] as usize].contains(q) {
            first_holds += 1;
        }
    }
    assert!(first_holds * 10 >= total * 9, "{first_holds} of {total}");
}

// ---------------------------------------------------------------------------------------------
// Point location on meshes against brute force over all cells.

/// Small xorshift generator (deterministic samples).
struct Rng(u64);
impl Rng {
    fn next(&mut self) -> f64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }
    fn below(&mut self, n: usize) -> usize {
        ((self.next() * n as f64) as usize).min(n - 1)
    }
}

/// Points: inside random cells (trilinear map of random parameters, including on faces and
/// corners), and uniformly in the padded bounding box (some outside the mesh).
fn sample_points(mesh: &Mesh, count: usize, seed: u64) -> Vec<DVec3> {
    let mut rng = Rng(seed | 1);
    let b = mesh.bounds();
    let lo = DVec3::new(b[0], b[2], b[4]);
    let hi = DVec3::new(b[1], b[3], b[5]);
    let pad = (hi - lo) * 0.05;
    (0..count)
        .map(|i| {
            if i % 2 == 0 {
                let c = rng.below(mesh.cell_count());
                let mut u = DVec3::new(rng.next(), rng.next(), rng.next());
                if i % 10 == 0 {
                    u.x = (u.x * 2.0).round() / 2.0; // faces and edges
                }
                map(&mesh.cell_corners(c), u)
            } else {
                let t = DVec3::new(rng.next(), rng.next(), rng.next());
                lo - pad + (hi - lo + 2.0 * pad) * t
            }
        })
        .collect()
}

/// Grids of both kinds for `mesh`, with the pieces they were built from.
fn grids(
    mesh: &Mesh,
    params: &GridParams,
    cyl_frame: Option<CylFrame>,
) -> Vec<(String, TwoLevelGrid, Pieces<Aabb>)> {
    let cart = space::cartesian_pieces(mesh);
    let cart_grid = build_grid(Coordinates::Cartesian, &cart, params);
    let axis = cylvol::axis::detect(mesh);
    let frame = CylFrame::new(axis.origin, axis.direction).unwrap();
    let pieces = space::cylindrical_pieces(mesh, &frame, space::DEFAULT_STRADDLE_SECTORS);
    let (seam, pieces) = space::seam_frame(&axis, pieces).unwrap();
    let boxes = space::linear_boxes(&pieces);
    let cyl_grid = build_grid(Coordinates::Cylindrical(seam), &boxes, params);
    let mut out = vec![
        ("cartesian".to_string(), cart_grid, cart),
        ("cylindrical".to_string(), cyl_grid, boxes),
    ];
    if let Some(f) = cyl_frame {
        // A given frame, without moving the seam into a gap.
        let pieces = space::cylindrical_pieces(mesh, &f, space::DEFAULT_STRADDLE_SECTORS);
        let boxes = space::linear_boxes(&pieces);
        out.push((
            "cylindrical, fixed frame".to_string(),
            build_grid(Coordinates::Cylindrical(f), &boxes, params),
            boxes,
        ));
    }
    out
}

/// The grid finds a cell holding `p` exactly when brute force does, and the cell holds `p`.
fn check_location(
    name: &str,
    mesh: &Mesh,
    params: &GridParams,
    frame: Option<CylFrame>,
    points: usize,
) {
    let boxes = space::cartesian_pieces(mesh);
    let pts = sample_points(mesh, points, 0x9e37_79b9_7f4a_7c15);
    for (kind, grid, pieces) in grids(mesh, params, frame) {
        grid.assert_well_formed(&pieces);
        let coords = grid.coordinates();
        let mut counters = Counters::default();
        let (mut inside, mut tests) = (0usize, 0u64);
        for &p in &pts {
            let brute = (0..mesh.cell_count()).find(|&c| {
                boxes.bounds[c].contains(p)
                    && locate_in_cell(&mesh.cell_corners(c), p, None).is_some()
            });
            let found = grid.find(coords.query(p), &mut counters, |c| {
                tests += 1;
                locate_in_cell(&mesh.cell_corners(c as usize), p, None).is_some()
            });
            assert_eq!(
                found.is_some(),
                brute.is_some(),
                "{name} {kind} {params:?}: p {p:?}: grid found {found:?}, brute force {brute:?}"
            );
            if let Some(c) = found {
                inside += 1;
                assert!(locate_in_cell(&mesh.cell_corners(c as usize), p, None).is_some());
            }
        }
        assert!(
            inside > points / 3,
            "{name}: too few points inside ({inside})"
        );
        let s = grid.stats();
        eprintln!(
            "{name:>16} {kind:<26} cells {:>7} grid cells {:>8} refs {:>8} bytes/cell {:>6.1} tests/inside point {:.2}",
            mesh.cell_count(),
            s.grid_cells,
            s.references,
            s.bytes as f64 / mesh.cell_count() as f64,
            tests as f64 / inside as f64
        );
    }
}

fn data(file: &str) -> Option<Mesh> {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data")
        .join(file);
    if !path.exists() {
        eprintln!("skipping {file}: not found");
        return None;
    }
    Some(cylvol::io::read_file(&path, &Default::default()).unwrap())
}

/// A structured mesh of an annular sector about z: `nr × nt × nh` cells, r ∈ [r0, r1],
/// θ from `t0` over `dt` (a full ring when `dt = 2π`, its last column sharing the first's
/// points), h ∈ [0, 1], translated by `offset`. With `r0 = 0` the innermost cells are wedges
/// on the axis.
#[allow(clippy::too_many_arguments)]
fn ring(
    r0: f64,
    r1: f64,
    nr: usize,
    t0: f64,
    dt: f64,
    nt: usize,
    nh: usize,
    offset: DVec3,
) -> Mesh {
    let full = (dt - 2.0 * PI).abs() < 1e-12;
    let nti = if full { nt } else { nt + 1 };
    let mut points = Vec::new();
    let idx = |i: usize, j: usize, k: usize| ((k * nti + j % nti) * (nr + 1) + i) as u32;
    for k in 0..=nh {
        for j in 0..nti {
            for i in 0..=nr {
                let r = r0 + (r1 - r0) * i as f64 / nr as f64;
                let t = t0 + dt * j as f64 / nt as f64;
                // A slight twist so cells are curved and skewed.
                let t = t + 0.05 * (k as f64 / nh as f64) * (r / r1);
                points.push(offset + DVec3::new(r * t.cos(), r * t.sin(), k as f64 / nh as f64));
            }
        }
    }
    let mut cells = Vec::new();
    let mut kinds = Vec::new();
    for k in 0..nh {
        for j in 0..nt {
            for i in 0..nr {
                let q = |kk: usize| {
                    [
                        idx(i, j, kk),
                        idx(i + 1, j, kk),
                        idx(i + 1, j + 1, kk),
                        idx(i, j + 1, kk),
                    ]
                };
                let (b, t) = (q(k), q(k + 1));
                if i == 0 && r0 == 0.0 {
                    // The wedge VTK numbers [axis, p_j+1, p_j] × 2, stored as CellKind says.
                    cells.push([b[0], b[1], b[2], b[2], t[0], t[1], t[2], t[2]]);
                    kinds.push(CellKind::Wedge);
                } else {
                    cells.push([b[0], b[1], b[2], b[3], t[0], t[1], t[2], t[3]]);
                    kinds.push(CellKind::Hexahedron);
                }
            }
        }
    }
    Mesh::from_parts(MeshParts {
        points,
        cells,
        kinds,
        ..Default::default()
    })
    .unwrap()
}

fn z_frame_at(origin: DVec3) -> Option<CylFrame> {
    CylFrame::new(origin, DVec3::Z)
}

#[test]
fn pump_datasets_all_presets() {
    for d in Dataset::ALL {
        let mesh = generate(d, 8_000).unwrap();
        for (preset, params) in GridParams::PRESETS {
            let n = if preset == "default" { 1_500 } else { 300 };
            check_location(&format!("{d} {preset}"), &mesh, &params, None, n);
        }
    }
}

#[test]
fn sector_across_the_seam() {
    // 150° to 210°: crosses θ = ±π in the z frame (checked with and without the seam frame).
    let mesh = ring(
        1.0,
        2.0,
        6,
        150f64.to_radians(),
        60f64.to_radians(),
        30,
        5,
        DVec3::ZERO,
    );
    check_location(
        "seam sector",
        &mesh,
        &GridParams::DEFAULT,
        z_frame_at(DVec3::ZERO),
        1_500,
    );
    check_location(
        "seam sector",
        &mesh,
        &GridParams::COMPACT,
        z_frame_at(DVec3::ZERO),
        400,
    );
}

#[test]
fn sector_across_zero() {
    let mesh = ring(
        0.5,
        2.0,
        8,
        -30f64.to_radians(),
        60f64.to_radians(),
        30,
        5,
        DVec3::ZERO,
    );
    check_location(
        "zero sector",
        &mesh,
        &GridParams::DEFAULT,
        z_frame_at(DVec3::ZERO),
        1_500,
    );
}

#[test]
fn full_ring() {
    let mesh = ring(1.0, 1.5, 4, 0.3, 2.0 * PI, 90, 6, DVec3::ZERO);
    check_location(
        "full ring",
        &mesh,
        &GridParams::DEFAULT,
        z_frame_at(DVec3::ZERO),
        1_500,
    );
    check_location(
        "full ring",
        &mesh,
        &GridParams::FAST,
        z_frame_at(DVec3::ZERO),
        400,
    );
}

#[test]
fn cells_on_the_axis() {
    // A disk with wedges around the axis.
    let mesh = ring(0.0, 1.0, 6, 0.0, 2.0 * PI, 24, 4, DVec3::ZERO);
    check_location(
        "axis disk",
        &mesh,
        &GridParams::DEFAULT,
        z_frame_at(DVec3::ZERO),
        1_500,
    );
    // The O-grid pipe: core cells straddle the axis.
    let inlet = generate(Dataset::PumpInlet, 5_000).unwrap();
    check_location(
        "O-grid inlet",
        &inlet,
        &GridParams::DEFAULT,
        z_frame_at(DVec3::ZERO),
        1_500,
    );
}

#[test]
fn far_away_mesh() {
    let off = DVec3::splat(1e6);
    let mesh = ring(1.0, 2.0, 6, 0.0, 2.0 * PI, 60, 5, off);
    check_location(
        "far ring",
        &mesh,
        &GridParams::DEFAULT,
        z_frame_at(off),
        1_500,
    );
    let rotor = generate(Dataset::PumpRotor, 6_000).unwrap();
    let mut parts = rotor.into_parts();
    for p in &mut parts.points {
        *p += off;
    }
    let moved = Mesh::from_parts(parts).unwrap();
    check_location("far rotor", &moved, &GridParams::DEFAULT, None, 1_000);
}

#[test]
fn real_meshes() {
    for file in ["postxyz.bin", "combxyz.bin"] {
        if let Some(mesh) = data(file) {
            check_location(file, &mesh, &GridParams::DEFAULT, None, 600);
            check_location(file, &mesh, &GridParams::COMPACT, None, 200);
        }
    }
}

/// What two grids must share to be the same build: the resolution, the counts and every
/// point's candidates in order.
fn fingerprint(grid: &TwoLevelGrid, points: &[DVec3]) -> (String, Vec<Vec<u32>>) {
    let s = grid.stats();
    let sizes = format!(
        "{:?} {:?} {} {} {}",
        grid.domain(),
        grid.top_resolution(),
        s.top_cells,
        s.leaf_cells,
        s.references
    );
    let coords = grid.coordinates();
    (
        sizes,
        points
            .iter()
            .map(|&p| grid.candidates(coords.query(p)).to_vec())
            .collect(),
    )
}

/// A build does not depend on the number of threads or on how the work was split: on the
/// Cartesian cube, whose pieces' mean extent divides its extent exactly (so that the
/// resolution sits on a rounding boundary), the grids built in pools of 1 to 8 threads, ten
/// times each, are the same.
#[test]
fn builds_are_the_same_whatever_the_threads() {
    let Some(mesh) = data("hexa.vtk") else {
        return;
    };
    let points = sample_points(&mesh, 400, 7);
    let build = || {
        grids(&mesh, &GridParams::DEFAULT, None)
            .iter()
            .map(|(kind, grid, _)| (kind.clone(), fingerprint(grid, &points)))
            .collect::<Vec<_>>()
    };
    let first = build();
    for threads in 1..=8 {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        for _ in 0..10 {
            let again = pool.install(build);
            for ((kind, a), (_, b)) in first.iter().zip(&again) {
                assert_eq!(a.0, b.0, "{kind} grid, {threads} threads");
                assert!(
                    a.1 == b.1,
                    "{kind} grid, {threads} threads: candidates differ"
                );
            }
        }
    }
}
