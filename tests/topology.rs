//! Face adjacency (`cylvol::mesh::topology`): hand-built meshes with known neighbours (a block
//! of hexahedra, a wedge/pyramid/tetrahedron mix, O-grids with collapsed cells on the axis,
//! rings with shared and with duplicated seam points, a non-manifold face), the synthetic
//! datasets and the real meshes checked for symmetry and against a brute-force map, and a
//! proptest on random structured blocks with cells removed.

use std::collections::{BTreeSet, HashMap};
use std::f64::consts::TAU;
use std::path::Path;

use cylvol::datasets::{self, Dataset};
use cylvol::mesh::topology::{face_vertices, FaceNeighbours, NONE};
use cylvol::{CellKind, Mesh, MeshParts};
use glam::DVec3;
use proptest::prelude::*;

/// VTK's hexahedron faces (checked against VTK itself in `face_order_is_vtks`).
const VTK_FACES: [[usize; 4]; 6] = [
    [0, 4, 7, 3],
    [1, 2, 6, 5],
    [0, 1, 5, 4],
    [3, 7, 6, 2],
    [0, 3, 2, 1],
    [4, 5, 6, 7],
];

fn mesh(points: Vec<DVec3>, cells: Vec<[u32; 8]>, kinds: Vec<CellKind>) -> Mesh {
    Mesh::from_parts(MeshParts {
        points,
        cells,
        kinds,
        ..MeshParts::default()
    })
    .expect("valid test mesh")
}

/// The distinct point ids of a face, by a route independent of the library's `FaceKey`.
fn id_set(cell: &[u32; 8], face: usize) -> Vec<u32> {
    VTK_FACES[face]
        .iter()
        .map(|&s| cell[s])
        .collect::<BTreeSet<_>>()
        .into_iter()
        .collect()
}

/// What a brute-force map of id sets says: the neighbour table and the boundary and
/// non-manifold face counts.
fn brute_force(mesh: &Mesh) -> (Vec<u32>, usize, usize) {
    let mut map: HashMap<Vec<u32>, Vec<(usize, usize)>> = HashMap::new();
    for (c, cell) in mesh.cells().iter().enumerate() {
        for f in 0..6 {
            let key = id_set(cell, f);
            if key.len() >= 3 {
                map.entry(key).or_default().push((c, f));
            }
        }
    }
    let mut table = vec![NONE; mesh.cell_count() * 6];
    let (mut boundary, mut nonmanifold) = (0, 0);
    for faces in map.values() {
        match faces.as_slice() {
            [_] => boundary += 1,
            [(ca, fa), (cb, fb)] if ca != cb => {
                table[ca * 6 + fa] = *cb as u32;
                table[cb * 6 + fb] = *ca as u32;
            }
            _ => nonmanifold += faces.len(),
        }
    }
    (table, boundary, nonmanifold)
}

/// Sorted distinct corner positions of a face.
fn positions(mesh: &Mesh, c: usize, f: usize) -> Vec<DVec3> {
    let mut p: Vec<DVec3> = id_set(&mesh.cells()[c], f)
        .into_iter()
        .map(|i| mesh.points()[i as usize])
        .collect();
    p.sort_by(|a, b| a.to_array().partial_cmp(&b.to_array()).unwrap());
    p.dedup();
    p
}

/// Symmetry: if `a`'s neighbour across `f` is `b`, exactly one face `g` of `b` has neighbour
/// `a`, and the two faces share their point ids (or, for seam faces, their positions within
/// `tolerance`, and both are marked seams). Returns the number of neighbour links.
fn check_symmetric(mesh: &Mesh, adj: &FaceNeighbours, tolerance: f64) -> usize {
    assert_eq!(adj.cell_count(), mesh.cell_count());
    assert_eq!(adj.raw().len(), mesh.cell_count() * 6);
    let cells = mesh.cells();
    let mut links = 0;
    for a in 0..mesh.cell_count() {
        let nb = adj.neighbours(a as u32);
        for (f, &n) in nb.iter().enumerate() {
            assert_eq!(adj.neighbour(a as u32, f), (n != NONE).then_some(n));
            if n == NONE {
                assert!(!adj.is_seam(a as u32, f));
                continue;
            }
            links += 1;
            let b = n as usize;
            assert_ne!(a, b, "cell {a} is its own neighbour");
            let back: Vec<usize> = (0..6)
                .filter(|&g| adj.neighbours(b as u32)[g] == a as u32)
                .filter(|&g| {
                    if adj.is_seam(a as u32, f) {
                        adj.is_seam(b as u32, g)
                            && positions(mesh, a, f)
                                .iter()
                                .zip(positions(mesh, b, g))
                                .all(|(p, q)| p.distance(q) <= tolerance)
                            && positions(mesh, a, f).len() == positions(mesh, b, g).len()
                    } else {
                        id_set(&cells[a], f) == id_set(&cells[b], g)
                    }
                })
                .collect();
            assert_eq!(
                back.len(),
                1,
                "cell {a} face {f} → {b}: matching faces back {back:?}"
            );
            let key = id_set(&cells[a], f);
            assert!(key.len() >= 3, "degenerate face {a}/{f} has a neighbour");
        }
    }
    links
}

/// Checks a mesh against the brute-force map; returns the adjacency.
fn check_against_brute_force(mesh: &Mesh) -> FaceNeighbours {
    let adj = FaceNeighbours::build(mesh);
    let (table, boundary, nonmanifold) = brute_force(mesh);
    assert_eq!(adj.boundary_face_count(), boundary);
    assert_eq!(adj.nonmanifold_faces(), nonmanifold);
    assert_eq!(adj.seam_faces(), 0);
    assert!(
        adj.raw() == table.as_slice(),
        "table differs from brute force"
    );
    let links = check_symmetric(mesh, &adj, 0.0);
    let degenerate = mesh
        .cells()
        .iter()
        .flat_map(|c| (0..6).map(move |f| id_set(c, f).len()))
        .filter(|&n| n < 3)
        .count();
    assert_eq!(adj.degenerate_face_count(), degenerate);
    // Every face is exactly one of: linked, boundary, non-manifold, degenerate.
    assert_eq!(
        links + boundary + nonmanifold + degenerate,
        mesh.cell_count() * 6
    );
    assert_eq!(
        adj.bytes(),
        24 * mesh.cell_count() + std::mem::size_of_val(&adj)
    );
    adj
}

/// A structured block of `n[0] × n[1] × n[2]` cells, u along x, v along y, w along z, with the
/// kept cells where `keep(i, j, k)`; returns the mesh and each kept cell's (i, j, k).
fn block(
    n: [usize; 3],
    jitter: &dyn Fn(usize) -> DVec3,
    keep: &dyn Fn(usize, usize, usize) -> bool,
) -> (Mesh, Vec<[usize; 3]>) {
    let [ni, nj, nk] = n;
    let mut points = Vec::new();
    for k in 0..=nk {
        for j in 0..=nj {
            for i in 0..=ni {
                let p = DVec3::new(i as f64, j as f64, k as f64);
                points.push(p + jitter(points.len()));
            }
        }
    }
    let id = |i: usize, j: usize, k: usize| (i + (ni + 1) * (j + (nj + 1) * k)) as u32;
    let mut cells = Vec::new();
    let mut where_ = Vec::new();
    for k in 0..nk {
        for j in 0..nj {
            for i in 0..ni {
                if keep(i, j, k) {
                    cells.push(cylvol::io::structured::cell_ids(i, j, k, id));
                    where_.push([i, j, k]);
                }
            }
        }
    }
    let kinds = vec![CellKind::Hexahedron; cells.len()];
    (mesh(points, cells, kinds), where_)
}

/// The neighbours a structured block must have: across face u = 0 the cell at i − 1, and so on.
fn expected_structured(where_: &[[usize; 3]]) -> (Vec<u32>, usize) {
    let index: HashMap<[usize; 3], u32> = where_
        .iter()
        .enumerate()
        .map(|(c, &ijk)| (ijk, c as u32))
        .collect();
    let mut table = Vec::new();
    let mut boundary = 0;
    for &[i, j, k] in where_ {
        let around = [
            i.checked_sub(1).map(|i| [i, j, k]),
            Some([i + 1, j, k]),
            j.checked_sub(1).map(|j| [i, j, k]),
            Some([i, j + 1, k]),
            k.checked_sub(1).map(|k| [i, j, k]),
            Some([i, j, k + 1]),
        ];
        for a in around {
            let n = a.and_then(|a| index.get(&a).copied()).unwrap_or(NONE);
            boundary += usize::from(n == NONE);
            table.push(n);
        }
    }
    (table, boundary)
}

#[test]
fn face_order_is_vtks() {
    for (f, faces) in VTK_FACES.iter().enumerate() {
        assert_eq!(face_vertices(f), *faces);
    }
    let script = "import vtk\nh=vtk.vtkHexahedron()\nfor i in range(8): h.GetPointIds().SetId(i,i)\nfor f in range(6):\n  c=h.GetFace(f); print(*[c.GetPointId(j) for j in range(4)])";
    match std::process::Command::new("/usr/bin/python3")
        .args(["-c", script])
        .output()
    {
        Ok(out) if out.status.success() => {
            let text = String::from_utf8_lossy(&out.stdout);
            let vtk: Vec<[usize; 4]> = text
                .lines()
                .map(|l| {
                    let v: Vec<usize> = l.split_whitespace().map(|x| x.parse().unwrap()).collect();
                    [v[0], v[1], v[2], v[3]]
                })
                .collect();
            assert_eq!(vtk, (0..6).map(face_vertices).collect::<Vec<_>>());
        }
        _ => eprintln!(
            "note: VTK's Python is not available; face order checked against the table only"
        ),
    }
}

#[test]
fn two_by_two_by_two_block() {
    let (mesh, where_) = block([2, 2, 2], &|_| DVec3::ZERO, &|_, _, _| true);
    let adj = check_against_brute_force(&mesh);
    let (table, boundary) = expected_structured(&where_);
    assert_eq!(adj.raw(), table.as_slice());
    assert_eq!(boundary, 24);
    assert_eq!(adj.boundary_face_count(), 24);
    // Each cell of a 2×2×2 block is a corner: three neighbours, three boundary faces.
    for c in 0..8 {
        assert_eq!(adj.neighbours(c).iter().filter(|&&n| n != NONE).count(), 3);
    }
    // Cell 0 at (0,0,0): u = 1 → (1,0,0) = 1, v = 1 → (0,1,0) = 2, w = 1 → (0,0,1) = 4.
    assert_eq!(adj.neighbours(0), [NONE, 1, NONE, 2, NONE, 4]);
    assert_eq!(adj.neighbours(7), [6, NONE, 5, NONE, 3, NONE]);
    assert_eq!(adj.neighbours(8), [NONE; 6], "out of range reads as none");
    assert_eq!(adj.neighbour(0, 6), None);
    // Geometric pass finds nothing more on a conforming block.
    let welded = FaceNeighbours::build_with_tolerance(&mesh, FaceNeighbours::seam_tolerance(&mesh));
    assert_eq!(welded, adj);
}

/// A hexahedron with a pyramid on top, a wedge beside it, tetrahedra on a pyramid triangle and
/// on a wedge triangle, and a tetrahedron under the hexahedron whose triangle has three of the
/// hexahedron's bottom quad's four points (so must not match it).
#[test]
fn wedge_pyramid_tetrahedron_mix() {
    let p = |x: f64, y: f64, z: f64| DVec3::new(x, y, z);
    let points = vec![
        p(0.0, 0.0, 0.0),   // 0 b0
        p(1.0, 0.0, 0.0),   // 1 b1
        p(1.0, 1.0, 0.0),   // 2 b2
        p(0.0, 1.0, 0.0),   // 3 b3
        p(0.0, 0.0, -1.0),  // 4 b4
        p(1.0, 0.0, -1.0),  // 5 b5
        p(1.0, 1.0, -1.0),  // 6 b6
        p(0.0, 1.0, -1.0),  // 7 b7
        p(0.5, 0.5, 1.0),   // 8 apex
        p(0.5, -1.0, 0.5),  // 9 tet on the pyramid
        p(2.0, 0.0, -1.0),  // 10 wedge, y = 0
        p(2.0, 1.0, -1.0),  // 11 wedge, y = 1
        p(1.3, -1.0, -0.7), // 12 tet on the wedge
        p(0.7, 0.3, -2.0),  // 13 tet under the hexahedron
    ];
    let hex = [4, 5, 6, 7, 0, 1, 2, 3];
    let pyramid = CellKind::Pyramid.collapse(&[0, 1, 2, 3, 8]);
    let tet_pyramid = CellKind::Tetrahedron.collapse(&[0, 1, 8, 9]);
    // Wedge: triangle (b5, b1, 10) at y = 0, (b6, b2, 11) at y = 1; its quad (b5, b1, b2, b6)
    // is the hexahedron's x = 1 face. In VTK's numbering (the base turns away from the top).
    let wedge = CellKind::Wedge.collapse(&[5, 10, 1, 6, 11, 2]);
    let tet_wedge = CellKind::Tetrahedron.collapse(&[5, 10, 1, 12]);
    let tet_under = CellKind::Tetrahedron.collapse(&[4, 6, 5, 13]);
    let cells = vec![hex, pyramid, tet_pyramid, wedge, tet_wedge, tet_under];
    let kinds = vec![
        CellKind::Hexahedron,
        CellKind::Pyramid,
        CellKind::Tetrahedron,
        CellKind::Wedge,
        CellKind::Tetrahedron,
        CellKind::Tetrahedron,
    ];
    let mesh = mesh(points, cells, kinds);
    let adj = check_against_brute_force(&mesh);
    let n = NONE;
    // Hexahedron: u = 1 (x = 1) → wedge, w = 1 (z = 0) → pyramid; w = 0 (bottom quad) is not
    // the tetrahedron's triangle.
    assert_eq!(adj.neighbours(0), [n, 3, n, n, n, 1]);
    // Pyramid: base (w = 0) → hexahedron, v = 0 triangle (b0, b1, apex) → its tetrahedron;
    // w = 1 is the apex (degenerate).
    assert_eq!(adj.neighbours(1), [n, n, 2, n, 0, n]);
    // Tetrahedron on the pyramid: its w = 0 triangle (b0, b1, apex).
    assert_eq!(adj.neighbours(2), [n, n, n, n, 1, n]);
    // Wedge: v = 0 quad (b5, b1, b2, b6) → hexahedron; w = 0 triangle (b5, b1, 10) → its tet.
    assert_eq!(adj.neighbours(3), [n, n, 0, n, 4, n]);
    assert_eq!(adj.neighbours(4), [n, n, n, n, 3, n]);
    assert_eq!(adj.neighbours(5), [n; 6]);
    // Degenerate faces: wedge 1, pyramid 1, tetrahedra 2 each.
    assert_eq!(adj.degenerate_face_count(), 1 + 1 + 3 * 2);
    assert_eq!(adj.nonmanifold_faces(), 0);
}

/// Three cells on one face: none of them is matched, all three are counted.
#[test]
fn three_cells_on_one_face_are_nonmanifold() {
    let (m, _) = block([1, 1, 2], &|_| DVec3::ZERO, &|_, _, _| true);
    let mut parts = m.into_parts();
    parts.cells.push(parts.cells[1]);
    parts.kinds.push(CellKind::Hexahedron);
    let mesh = mesh(parts.points, parts.cells, parts.kinds);
    let adj = check_against_brute_force(&mesh);
    // Cell 0's top face is both copies' bottom face: three faces on one key, none matched.
    assert_eq!(adj.nonmanifold_faces(), 3);
    assert_eq!(adj.neighbours(0), [NONE; 6]);
    // The two copies share their five other faces pairwise.
    assert_eq!(adj.neighbours(1), [2, 2, 2, 2, NONE, 2]);
    assert_eq!(adj.neighbours(2), [1, 1, 1, 1, NONE, 1]);
}

/// A full O-grid ring around the z axis: `nt` sectors, `nr` radial cells, `nh` levels. The
/// cells on the axis are wedges (`axis = Wedge`, VTK's wedge collapsed) or hexahedra with their
/// u = 0 face collapsed onto the axis edge (`axis = Hexahedron`, as a structured O-grid with a
/// singular line stores them). `duplicate_seam` gives the θ = 2π points their own ids.
fn o_grid(nr: usize, nt: usize, nh: usize, axis: CellKind, duplicate_seam: bool) -> Mesh {
    let ntp = if duplicate_seam { nt + 1 } else { nt };
    let mut points = Vec::new();
    // Point (i ≥ 1, j, k) and the axis point of level k.
    for k in 0..=nh {
        points.push(DVec3::new(0.0, 0.0, k as f64 * 0.3));
        for j in 0..ntp {
            for i in 1..=nr {
                let t = TAU * j as f64 / nt as f64;
                let r = 0.2 * i as f64 + 0.01 * (i * i) as f64;
                points.push(DVec3::new(r * t.cos(), r * t.sin(), k as f64 * 0.3));
            }
        }
    }
    let per_level = 1 + ntp * nr;
    let id = |i: usize, j: usize, k: usize| -> u32 {
        let base = per_level * k;
        let j = if duplicate_seam { j } else { j % nt };
        (if i == 0 {
            base
        } else {
            base + 1 + j * nr + (i - 1)
        }) as u32
    };
    let mut cells = Vec::new();
    let mut kinds = Vec::new();
    for k in 0..nh {
        for j in 0..nt {
            for i in 0..nr {
                let hex = cylvol::io::structured::cell_ids(i, j, k, id);
                if i == 0 && axis == CellKind::Wedge {
                    cells.push(
                        CellKind::Wedge.collapse(&[hex[0], hex[2], hex[1], hex[4], hex[6], hex[5]]),
                    );
                    kinds.push(CellKind::Wedge);
                } else {
                    cells.push(hex);
                    kinds.push(CellKind::Hexahedron);
                }
            }
        }
    }
    mesh(points, cells, kinds)
}

#[test]
fn o_grid_with_collapsed_axis_cells() {
    let (nr, nt, nh) = (3, 8, 2);
    for axis in [CellKind::Wedge, CellKind::Hexahedron] {
        let mesh = o_grid(nr, nt, nh, axis, false);
        let adj = check_against_brute_force(&mesh);
        // Boundary: outer wall, bottom and top. Nothing at the seam, nothing on the axis.
        assert_eq!(adj.boundary_face_count(), nt * nh + 2 * nt * nr, "{axis}");
        // One degenerate face per axis cell (the wedge's v = 1 edge, or the hexahedron's u = 0
        // axis edge, which all `nt` cells of a level share and which is still never matched).
        assert_eq!(adj.degenerate_face_count(), nt * nh, "{axis}");
        assert_eq!(adj.nonmanifold_faces(), 0, "{axis}");
        // Every axis cell has both circumferential neighbours and the radial one outside.
        for c in (0..mesh.cell_count()).filter(|c| c % nr == 0) {
            let nb = adj.neighbours(c as u32);
            let linked = nb.iter().filter(|&&n| n != NONE).count();
            let levels = [c / (nr * nt) > 0, c / (nr * nt) < nh - 1];
            let expected = 3 + levels.iter().filter(|&&b| b).count();
            assert_eq!(linked, expected, "{axis} cell {c}: {nb:?}");
        }
    }
}

#[test]
fn ring_seam_shared_versus_duplicated() {
    let (nr, nt, nh) = (3, 12, 2);
    for axis in [CellKind::Wedge, CellKind::Hexahedron] {
        let shared = o_grid(nr, nt, nh, axis, false);
        let duplicated = o_grid(nr, nt, nh, axis, true);
        let by_ids = check_against_brute_force(&shared);
        assert_eq!(by_ids.boundary_face_count(), nt * nh + 2 * nt * nr);

        // By ids, the duplicated seam is open: both sides are boundary.
        let open = check_against_brute_force(&duplicated);
        assert_eq!(
            open.boundary_face_count(),
            by_ids.boundary_face_count() + 2 * nr * nh
        );
        // The geometric pass closes it, and gives exactly the shared-seam table.
        let tolerance = FaceNeighbours::seam_tolerance(&duplicated);
        let welded = FaceNeighbours::build_with_tolerance(&duplicated, tolerance);
        assert_eq!(welded.raw(), by_ids.raw(), "{axis}");
        assert_eq!(welded.seam_faces(), 2 * nr * nh);
        assert_eq!(welded.boundary_face_count(), by_ids.boundary_face_count());
        assert_eq!(
            welded.degenerate_face_count(),
            by_ids.degenerate_face_count()
        );
        check_symmetric(&duplicated, &welded, tolerance);
        // The seam faces are the v = 0 faces of sector 0 and the v = 1 faces of the last one.
        // (A wedge on the axis has its θ_{j+1} side at u = 0, not v = 1.)
        for c in 0..duplicated.cell_count() {
            let j = (c / nr) % nt;
            let end = if c % nr == 0 && axis == CellKind::Wedge {
                0
            } else {
                3
            };
            for f in 0..6 {
                let seam = (f == 2 && j == 0) || (f == end && j == nt - 1);
                assert_eq!(welded.is_seam(c as u32, f), seam, "cell {c} face {f}");
            }
        }
        // No tolerance, no second pass; a tolerance too small to reach the next point on the
        // ring still joins the coincident seam and nothing else.
        assert_eq!(FaceNeighbours::build_with_tolerance(&duplicated, 0.0), open);
        assert_eq!(
            FaceNeighbours::build_with_tolerance(&duplicated, f64::NAN),
            open
        );
        assert_eq!(
            FaceNeighbours::build_with_tolerance(&duplicated, 1e-3).raw(),
            by_ids.raw()
        );
    }
}

/// The seam pass does not join faces that are merely near: a gap wider than the tolerance.
#[test]
fn seam_pass_respects_tolerance() {
    let (m, _) = block([2, 1, 1], &|_| DVec3::ZERO, &|_, _, _| true);
    // Split the block at x = 1 into two cells with their own points, the second moved by `gap`.
    let split = |gap: f64| {
        let parts = m.clone().into_parts();
        let mut points = parts.points.clone();
        let mut cells = parts.cells.clone();
        for slot in cells[1].iter_mut() {
            let id = *slot as usize;
            if parts.points[id].x == 1.0 {
                points.push(parts.points[id] + DVec3::new(gap, 0.0, 0.0));
                *slot = (points.len() - 1) as u32;
            } else {
                points[id].x += gap;
            }
        }
        mesh(points, cells, parts.kinds)
    };
    let touching = split(0.0);
    let apart = split(1e-6);
    let t = FaceNeighbours::build_with_tolerance(&touching, 1e-9);
    assert_eq!(t.neighbours(0)[1], 1);
    assert_eq!(t.neighbours(1)[0], 0);
    assert_eq!(t.seam_faces(), 2);
    let a = FaceNeighbours::build_with_tolerance(&apart, 1e-9);
    assert_eq!(a.seam_faces(), 0);
    assert_eq!(a.raw(), &[NONE; 12][..]);
    assert_eq!(
        FaceNeighbours::build_with_tolerance(&apart, 1e-5).seam_faces(),
        2
    );
}

#[test]
fn synthetic_datasets() {
    for dataset in Dataset::ALL {
        let mesh = datasets::generate(dataset, 20_000).unwrap();
        let adj = check_against_brute_force(&mesh);
        // The datasets are conforming with shared seam points: the geometric pass adds nothing.
        let welded =
            FaceNeighbours::build_with_tolerance(&mesh, FaceNeighbours::seam_tolerance(&mesh));
        assert_eq!(welded, adj, "{dataset}");
        // Deterministic for any thread count.
        let one = rayon::ThreadPoolBuilder::new()
            .num_threads(1)
            .build()
            .unwrap()
            .install(|| FaceNeighbours::build(&mesh));
        assert_eq!(one, adj, "{dataset}");
        eprintln!(
            "{dataset}: {} cells, {} boundary faces, {} degenerate, {} non-manifold",
            mesh.cell_count(),
            adj.boundary_face_count(),
            adj.degenerate_face_count(),
            adj.nonmanifold_faces()
        );
        assert!(adj.boundary_face_count() > 0);
    }
}

fn real(name: &str) -> Mesh {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data")
        .join(name);
    cylvol::io::read_file(&path, &Default::default()).unwrap()
}

#[test]
fn real_meshes() {
    for name in ["mixer.vtk", "postxyz.bin", "combxyz.bin", "hexa.vtk"] {
        let mesh = real(name);
        let adj = check_against_brute_force(&mesh);
        let tolerance = FaceNeighbours::seam_tolerance(&mesh);
        let welded = FaceNeighbours::build_with_tolerance(&mesh, tolerance);
        let links = check_symmetric(&mesh, &welded, tolerance);
        assert_eq!(
            welded.boundary_face_count() + welded.seam_faces(),
            adj.boundary_face_count()
        );
        eprintln!(
            "{name}: {} cells, {} links, boundary {} by ids, {} seam faces joined by position",
            mesh.cell_count(),
            links,
            adj.boundary_face_count(),
            welded.seam_faces()
        );
        if name == "postxyz.bin" {
            // 38×76×38 points: j = 74 and 75 coincide with j = 0. By ids the seam is open; the
            // geometric pass joins the last (zero-thickness) layer's j = 75 faces to the first
            // layer's j = 0 faces: 37 × 37 pairs.
            assert_eq!(welded.seam_faces(), 2 * 37 * 37);
        } else {
            assert_eq!(welded.seam_faces(), 0, "{name}");
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(48))]
    #[test]
    fn random_blocks_with_cells_removed(
        ni in 1usize..6,
        nj in 1usize..6,
        nk in 1usize..5,
        seed in any::<u64>(),
        removal in 0.0f64..0.6,
    ) {
        let hash = |x: u64| {
            let mut z = x.wrapping_add(seed).wrapping_mul(0x9E37_79B9_7F4A_7C15);
            z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
            z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
            z ^ (z >> 31)
        };
        let unit = |x: u64| (hash(x) >> 11) as f64 / (1u64 << 53) as f64;
        let jitter = |p: usize| {
            let b = 3 * p as u64;
            DVec3::new(unit(b) - 0.5, unit(b + 1) - 0.5, unit(b + 2) - 0.5) * 0.3
        };
        let keep = |i: usize, j: usize, k: usize| {
            let idx = (i + 7 * (j + 7 * k)) as u64;
            unit(1_000_003 + idx) >= removal || (i, j, k) == (0, 0, 0)
        };
        let (mesh, where_) = block([ni, nj, nk], &jitter, &keep);
        let adj = check_against_brute_force(&mesh);
        let (table, boundary) = expected_structured(&where_);
        prop_assert_eq!(adj.raw(), table.as_slice());
        prop_assert_eq!(adj.boundary_face_count(), boundary);
        prop_assert_eq!(adj.degenerate_face_count(), 0);
        let welded = FaceNeighbours::build_with_tolerance(&mesh, 1e-9);
        prop_assert_eq!(welded, adj);
    }
}

/// The cell holding `p`, by testing every cell (the reference for the boundary check).
fn brute_force_cell(mesh: &Mesh, p: DVec3) -> Option<u32> {
    (0..mesh.cell_count())
        .find(|&c| cylvol::geometry::containment::contains(&mesh.cell_corners(c), p))
        .map(|c| c as u32)
}

/// Two unit cubes stacked in z, the upper one either conforming (sharing the lower one's top
/// face) or split into two wedges along the diagonal of that face, or shifted by half a cell
/// in x (a face against two half faces, as at a non-conforming interface).
fn stacked(upper: &str) -> Mesh {
    let mut points: Vec<DVec3> = (0..12)
        .map(|n| DVec3::new((n % 2) as f64, ((n / 2) % 2) as f64, (n / 4) as f64))
        .collect();
    let lower = [0, 1, 3, 2, 4, 5, 7, 6];
    let (cells, kinds) = match upper {
        "hexahedron" => (
            vec![lower, [4, 5, 7, 6, 8, 9, 11, 10]],
            vec![CellKind::Hexahedron; 2],
        ),
        "wedges" => (
            vec![
                lower,
                // Stored collapsed as CellKind says: VTK's wedges [4, 6, 5, 8, 10, 9], [5, 6, 7, 9, 10, 11].
                [4, 5, 6, 6, 8, 9, 10, 10],
                [5, 7, 6, 6, 9, 11, 10, 10],
            ],
            vec![CellKind::Hexahedron, CellKind::Wedge, CellKind::Wedge],
        ),
        _ => {
            // The upper cube's own points, moved by half a cell in x.
            let base = points.len() as u32;
            for n in 0..8 {
                points.push(DVec3::new(
                    (n % 2) as f64 + 0.5,
                    ((n / 2) % 2) as f64,
                    (n / 4) as f64 + 1.0,
                ));
            }
            let b = |k: u32| base + k;
            (
                vec![lower, [b(0), b(1), b(3), b(2), b(4), b(5), b(7), b(6)]],
                vec![CellKind::Hexahedron; 2],
            )
        }
    };
    Mesh::from_parts(MeshParts {
        points,
        cells,
        kinds,
        ..MeshParts::default()
    })
    .expect("mesh")
}

#[test]
fn boundary_check_finds_hanging_faces_and_only_them() {
    let mut conforming = FaceNeighbours::build(&stacked("hexahedron"));
    assert_eq!(conforming.hanging_faces(), None);
    assert!(!conforming.is_closed(), "unchecked is not closed");
    let mesh = stacked("hexahedron");
    assert_eq!(
        conforming.check_boundary(&mesh, |p| brute_force_cell(&mesh, p)),
        0
    );
    assert!(conforming.is_closed());

    // The lower cube's top face (a quad) meets two triangles: no neighbour by ids, mesh beyond.
    let mesh = stacked("wedges");
    let mut n = FaceNeighbours::build(&mesh);
    assert_eq!(n.neighbours(0)[5], NONE);
    assert_eq!(n.check_boundary(&mesh, |p| brute_force_cell(&mesh, p)), 3);
    assert!(!n.is_closed());

    // Shifted by half a cell: the lower top face and the upper bottom face overlap by half.
    let mesh = stacked("shifted");
    let mut n = FaceNeighbours::build(&mesh);
    assert_eq!(n.check_boundary(&mesh, |p| brute_force_cell(&mesh, p)), 2);
    assert!(!n.is_closed());
}

/// `render::face_neighbours` (the check filtered by the boundary surface, through a
/// structure) finds the hanging faces the brute-force check finds: none on the conforming
/// stack, three against two wedges, two on the half-shifted stack, through every structure.
#[test]
fn face_neighbours_find_the_hanging_faces() {
    use cylvol::accel::{Accel, AccelParams, StructureKind};
    for (kind, expected) in [("hexahedron", 0), ("wedges", 3), ("shifted", 2)] {
        let mesh = stacked(kind);
        let mut plain =
            FaceNeighbours::build_with_tolerance(&mesh, FaceNeighbours::seam_tolerance(&mesh));
        assert_eq!(
            plain.check_boundary(&mesh, |p| brute_force_cell(&mesh, p)),
            expected,
            "{kind}"
        );
        for structure in StructureKind::ALL {
            let accel = Accel::build(
                &mesh,
                structure,
                &cylvol::axis::Axis::Z,
                &AccelParams::default(),
            )
            .expect("build");
            let t = cylvol::render::face_neighbours(&mesh, &accel);
            assert_eq!(t.hanging_faces(), Some(expected), "{kind} {structure}");
        }
    }
}
