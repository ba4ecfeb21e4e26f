//! Meshes for the integration tests: the hard cases (seams, the axis, collapsed and skewed cells) built in code, and seeded
//! points inside, on the faces of, and around a mesh.
#![allow(dead_code)]

use std::f64::consts::{PI, TAU};

use cylvol::geometry::cylindrical::CylFrame;
use cylvol::geometry::trilinear;
use cylvol::io::structured::hexahedra;
use cylvol::{CellKind, DataArray, Mesh, MeshParts};
use glam::DVec3;

/// The real meshes the tests carry, in `tests/data/`.
pub fn data(name: &str) -> std::path::PathBuf {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data")
        .join(name)
}

/// The library's seeded generator, with the two draws the tests need.
pub struct Rng(cylvol::accel::probe::SplitMix64);

impl Rng {
    pub fn new(seed: u64) -> Rng {
        Rng(cylvol::accel::probe::SplitMix64::new(seed))
    }
    /// Uniform in [0, 1).
    pub fn unit(&mut self) -> f64 {
        self.0.unit()
    }
    pub fn below(&mut self, n: usize) -> usize {
        (self.0.next_u64() % n as u64) as usize
    }
}

/// A structured block of an annular sector `[r0, r1] × [t0, t1] × [0, height]` about `frame`,
/// `nr × nt × nh` cells, with a pressure-like point scalar. With `close_ring` the last θ column
/// reuses the first column's points (a closed full ring); otherwise a full ring from −π to π
/// gets a duplicated seam (coincident, separate points).
#[allow(clippy::too_many_arguments)]
pub fn sector(
    frame: &CylFrame,
    r: [f64; 2],
    t: [f64; 2],
    height: f64,
    n: [usize; 3],
    close_ring: bool,
) -> Mesh {
    let [nr, nt, nh] = n;
    let (ni, nj, nk) = (nr + 1, nt + 1, nh + 1);
    let mut points = Vec::with_capacity(ni * nj * nk);
    for k in 0..nk {
        for j in 0..nj {
            for i in 0..ni {
                let rr = r[0] + (r[1] - r[0]) * i as f64 / nr as f64;
                let tt = t[0] + (t[1] - t[0]) * j as f64 / nt as f64;
                let hh = height * k as f64 / nh as f64;
                points.push(frame.from_cylindrical(rr, tt, hh));
            }
        }
    }
    let mut cells = hexahedra([ni, nj, nk], &points);
    if close_ring {
        // Map the last column's points onto the first column's.
        let last = |id: u32| {
            let id = id as usize;
            let (i, j, k) = (id % ni, (id / ni) % nj, id / (ni * nj));
            if j == nt {
                (i + ni * nj * k) as u32
            } else {
                id as u32
            }
        };
        for c in &mut cells {
            *c = c.map(last);
        }
    }
    finish(
        points,
        cells.clone(),
        vec![CellKind::Hexahedron; cells.len()],
        frame,
    )
}

/// An O-grid cylinder about `frame`: wedges with an edge on the axis in the centre, then
/// `rings` rings of hexahedra, `nt` around, `nh` high.
pub fn o_grid_with_axis_wedges(
    frame: &CylFrame,
    radius: f64,
    nt: usize,
    rings: usize,
    nh: usize,
) -> Mesh {
    let per_level = 1 + nt * rings;
    let id = |k: usize, ring: usize, j: usize| -> u32 {
        // ring 0 is the axis point; ring ≥ 1 has nt points.
        (k * per_level
            + if ring == 0 {
                0
            } else {
                1 + (ring - 1) * nt + j % nt
            }) as u32
    };
    let mut points = Vec::new();
    for k in 0..=nh {
        let h = k as f64 / nh as f64;
        points.push(frame.from_cylindrical(0.0, 0.0, h));
        for ring in 1..=rings {
            for j in 0..nt {
                let t = -PI + TAU * j as f64 / nt as f64 + 0.1 * ring as f64;
                points.push(frame.from_cylindrical(radius * ring as f64 / rings as f64, t, h));
            }
        }
    }
    let mut cells = Vec::new();
    let mut kinds = Vec::new();
    for k in 0..nh {
        for j in 0..nt {
            // Wedge: triangle (axis, ring1 j, ring1 j+1) at k and k+1, in VTK's numbering
            // (the base turns away from the top by the right-hand rule).
            let w = [
                id(k, 0, 0),
                id(k, 1, j + 1),
                id(k, 1, j),
                id(k + 1, 0, 0),
                id(k + 1, 1, j + 1),
                id(k + 1, 1, j),
            ];
            cells.push(CellKind::Wedge.collapse(&w));
            kinds.push(CellKind::Wedge);
            for ring in 1..rings {
                cells.push([
                    id(k, ring, j),
                    id(k, ring + 1, j),
                    id(k, ring + 1, j + 1),
                    id(k, ring, j + 1),
                    id(k + 1, ring, j),
                    id(k + 1, ring + 1, j),
                    id(k + 1, ring + 1, j + 1),
                    id(k + 1, ring, j + 1),
                ]);
                kinds.push(CellKind::Hexahedron);
            }
        }
    }
    finish(points, cells, kinds, frame)
}

fn finish(
    points: Vec<DVec3>,
    cells: Vec<[u32; 8]>,
    kinds: Vec<CellKind>,
    frame: &CylFrame,
) -> Mesh {
    let pressure = points
        .iter()
        .map(|p| {
            let (r, t, h) = frame.to_cylindrical(*p);
            r * r + 0.3 * (3.0 * t).sin() + 0.5 * h
        })
        .collect();
    let mut parts = MeshParts {
        points,
        cells,
        kinds,
        point_data: vec![DataArray::scalar("pressure", pressure)],
        cell_data: vec![],
    };
    // Orient: the builders above may produce mirrored cells depending on the frame.
    for (c, kind) in parts.cells.iter_mut().zip(&parts.kinds) {
        let corners = c.map(|i| parts.points[i as usize]);
        if cylvol::mesh::validate::cell_volume(&corners) < 0.0 && *kind == CellKind::Hexahedron {
            *c = [c[4], c[5], c[6], c[7], c[0], c[1], c[2], c[3]];
        }
    }
    Mesh::from_parts(parts).expect("test mesh is valid")
}

/// The same mesh with every point moved by `offset`.
pub fn moved(mesh: &Mesh, offset: DVec3) -> Mesh {
    let mut parts = mesh.clone().into_parts();
    for p in &mut parts.points {
        *p += offset;
    }
    Mesh::from_parts(parts).expect("moved mesh is valid")
}

/// Seeded points: `n` inside random cells, `n` on random cell faces (edges and vertices
/// included), `n` in the mesh's box enlarged by 10 % (mostly around it).
pub fn sample_points(mesh: &Mesh, n: usize, seed: u64) -> Vec<DVec3> {
    let mut rng = Rng::new(seed);
    let mut out = Vec::with_capacity(3 * n);
    for _ in 0..n {
        let c = rng.below(mesh.cell_count());
        let p = DVec3::new(rng.unit(), rng.unit(), rng.unit());
        out.push(trilinear::map(&mesh.cell_corners(c), p));
    }
    for _ in 0..n {
        let c = rng.below(mesh.cell_count());
        let mut p = [rng.unit(), rng.unit(), rng.unit()];
        let axis = rng.below(3);
        p[axis] = (rng.below(2)) as f64;
        if rng.below(4) == 0 {
            // An edge or a vertex.
            let second = (axis + 1 + rng.below(2)) % 3;
            p[second] = (rng.below(2)) as f64;
            if rng.below(2) == 0 {
                p[3 - axis - second] = (rng.below(2)) as f64;
            }
        }
        out.push(trilinear::map(&mesh.cell_corners(c), DVec3::from_array(p)));
    }
    let b = mesh.bounds();
    let lo = DVec3::new(b[0], b[2], b[4]);
    let hi = DVec3::new(b[1], b[3], b[5]);
    let pad = (hi - lo) * 0.1;
    for _ in 0..n {
        let t = DVec3::new(rng.unit(), rng.unit(), rng.unit());
        out.push(lo - pad + (hi - lo + 2.0 * pad) * t);
    }
    out
}

/// The face neighbours the CLI gives the fast path ([`cylvol::render::face_neighbours`]):
/// seams welded, open faces checked against a Cartesian BVH. Asserts the mesh is closed (no
/// hanging faces), so the boundary searches take the local path.
#[allow(dead_code)]
pub fn closed_neighbours(mesh: &Mesh) -> cylvol::render::Topology {
    use cylvol::accel::{Accel, AccelParams, StructureKind};
    let accel = Accel::build(
        mesh,
        StructureKind::CartBvh,
        &cylvol::axis::Axis::Z,
        &AccelParams::default(),
    )
    .expect("build");
    let n = cylvol::render::face_neighbours(mesh, &accel);
    assert!(n.is_closed(), "hanging faces: {:?}", n.hanging_faces());
    n
}

/// VTK's Python: Debian's `python3-vtk9` belongs to this interpreter.
pub const VTK_PYTHON: &str = "/usr/bin/python3";

/// Whether [`VTK_PYTHON`] imports `vtk` (asked once per test program); a note on standard
/// error says the comparisons with VTK are skipped where it does not.
pub fn vtk_python_available() -> bool {
    static HAVE: std::sync::OnceLock<bool> = std::sync::OnceLock::new();
    *HAVE.get_or_init(|| {
        let ok = std::process::Command::new(VTK_PYTHON)
            .args(["-c", "import vtk"])
            .output()
            .is_ok_and(|o| o.status.success());
        if !ok {
            eprintln!(
                "note: `{VTK_PYTHON} -c 'import vtk'` failed; skipping the comparison with VTK"
            );
        }
        ok
    })
}

/// Runs `script` with `args` in [`VTK_PYTHON`] and gives its standard output; a script that
/// fails fails the test with its standard error.
pub fn vtk_python(script: &str, args: &[&str]) -> String {
    let out = std::process::Command::new(VTK_PYTHON)
        .arg("-c")
        .arg(script)
        .args(args)
        .output()
        .unwrap_or_else(|e| panic!("run {VTK_PYTHON}: {e}"));
    assert!(
        out.status.success(),
        "python failed: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8(out.stdout).expect("utf-8 output")
}
