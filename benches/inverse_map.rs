//! Inverse-map throughput and accuracy: the library's f64 inverse against a minimal Newton in
//! f64 and in f32 on coordinates rebased to a local origin, for cells near the origin and 10⁶
//! away. Prints an accuracy table (parametric and physical error against the known answer)
//! before timing, so the choice "store f64 or rebase to f32" can be made from one run.
//!
//! The cells: 256 distorted cells of size 0.01 (a 100³ mesh of a unit domain: corners perturbed
//! by up to 15 %, twisted up to ±20°), scattered in the unit domain, which is placed at the
//! origin or at (10⁶, 10⁶, 10⁶). Targets are the images of known random parameters.

use criterion::{black_box, criterion_group, criterion_main, Criterion, Throughput};
use cylvol::geometry::inverse::invert;
use cylvol::geometry::trilinear::{map, CORNER_PARAMETERS};
use glam::{DMat3, DVec3, Mat3, Vec3};

const N: usize = 256;
const H: f64 = 0.01;

/// A small deterministic generator (xorshift), so the bench needs no extra crate.
struct Rng(u64);
impl Rng {
    fn next(&mut self) -> f64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }
    fn vec(&mut self) -> DVec3 {
        DVec3::new(self.next(), self.next(), self.next())
    }
}

struct Case {
    cells: Vec<[DVec3; 8]>,
    targets: Vec<DVec3>,
    truth: Vec<DVec3>,
    /// The mesh-wide origin (the domain centre) for the mesh-rebased f32 path.
    mesh_origin: DVec3,
}

fn case(offset: f64) -> Case {
    let mut rng = Rng(0x9E37_79B9_7F4A_7C15);
    let base = DVec3::splat(offset);
    let mut cells = Vec::with_capacity(N);
    let mut targets = Vec::with_capacity(N);
    let mut truth = Vec::with_capacity(N);
    for _ in 0..N {
        let at = base + rng.vec() * (1.0 - H);
        let twist = (rng.next() - 0.5) * 40f64.to_radians();
        let cell = CORNER_PARAMETERS.map(|c| {
            let p = DVec3::from_array(c) + (rng.vec() - 0.5) * 0.3;
            let a = twist * p.z;
            let q = p - DVec3::new(0.5, 0.5, 0.0);
            let q = DVec3::new(
                q.x * a.cos() - q.y * a.sin(),
                q.x * a.sin() + q.y * a.cos(),
                q.z,
            );
            at + q * H
        });
        let p = rng.vec();
        truth.push(p);
        targets.push(map(&cell, p));
        cells.push(cell);
    }
    Case {
        cells,
        targets,
        truth,
        mesh_origin: base + DVec3::splat(0.5),
    }
}

/// A minimal undamped Newton (from the centre, stop on a small step), the same code for f32
/// and f64, on corners given relative to corner 0.
macro_rules! minimal_newton {
    ($name:ident, $v:ty, $m:ty, $s:ty, $tol:expr) => {
        fn $name(rel: &[$v; 8], t: $v) -> $v {
            let mut p = <$v>::splat(0.5);
            for _ in 0..20 {
                let (u, v, w) = (p.x, p.y, p.z);
                let (iu, iv, iw) = (1.0 - u, 1.0 - v, 1.0 - w);
                let n: [$s; 8] = [
                    iu * iv * iw,
                    u * iv * iw,
                    u * v * iw,
                    iu * v * iw,
                    iu * iv * w,
                    u * iv * w,
                    u * v * w,
                    iu * v * w,
                ];
                let d: [$v; 8] = [
                    <$v>::new(-iv * iw, -iu * iw, -iu * iv),
                    <$v>::new(iv * iw, -u * iw, -u * iv),
                    <$v>::new(v * iw, u * iw, -u * v),
                    <$v>::new(-v * iw, iu * iw, -iu * v),
                    <$v>::new(-iv * w, -iu * w, iu * iv),
                    <$v>::new(iv * w, -u * w, u * iv),
                    <$v>::new(v * w, u * w, u * v),
                    <$v>::new(-v * w, iu * w, iu * v),
                ];
                let mut x = <$v>::ZERO;
                let (mut ju, mut jv, mut jw) = (<$v>::ZERO, <$v>::ZERO, <$v>::ZERO);
                for i in 0..8 {
                    x += rel[i] * n[i];
                    ju += rel[i] * d[i].x;
                    jv += rel[i] * d[i].y;
                    jw += rel[i] * d[i].z;
                }
                let step = <$m>::from_cols(ju, jv, jw).inverse() * (x - t);
                p -= step;
                if step.abs().max_element() < $tol {
                    break;
                }
            }
            p
        }
    };
}
minimal_newton!(newton_f64, DVec3, DMat3, f64, 1e-12);
minimal_newton!(newton_f32, Vec3, Mat3, f32, 1e-6);

/// f32 corners relative to corner 0 plus the f64 origin they are relative to.
fn rebase_cell(cell: &[DVec3; 8]) -> (DVec3, [Vec3; 8]) {
    let o = cell[0];
    (o, cell.map(|c| (c - o).as_vec3()))
}

/// f32 corners relative to one mesh-wide origin.
fn rebase_mesh(cell: &[DVec3; 8], origin: DVec3) -> [Vec3; 8] {
    cell.map(|c| (c - origin).as_vec3())
}

fn f64_minimal(cell: &[DVec3; 8], t: DVec3) -> DVec3 {
    let o = cell[0];
    newton_f64(&cell.map(|c| c - o), t - o)
}

fn f32_cell(stored: &(DVec3, [Vec3; 8]), t: DVec3) -> DVec3 {
    newton_f32(&stored.1, (t - stored.0).as_vec3()).as_dvec3()
}

fn f32_mesh(stored: &[Vec3; 8], origin: DVec3, t: DVec3) -> DVec3 {
    let o = stored[0];
    newton_f32(&stored.map(|c| c - o), (t - origin).as_vec3() - o).as_dvec3()
}

fn f32_absolute(cell: &[DVec3; 8], t: DVec3) -> DVec3 {
    let c = cell.map(|c| c.as_vec3());
    let o = c[0];
    newton_f32(&c.map(|x| x - o), t.as_vec3() - o).as_dvec3()
}

fn report(label: &str, c: &Case, f: impl Fn(usize) -> DVec3) {
    let (mut pmax, mut psum, mut xmax) = (0.0f64, 0.0, 0.0f64);
    for i in 0..N {
        let p = f(i);
        let e = if p.is_finite() {
            (p - c.truth[i]).abs().max_element()
        } else {
            f64::INFINITY
        };
        pmax = pmax.max(e);
        psum += e;
        let x = if p.is_finite() {
            (map(&c.cells[i], p) - c.targets[i]).length()
        } else {
            f64::INFINITY
        };
        xmax = xmax.max(x);
    }
    eprintln!(
        "{label:<28} param error max {pmax:9.2e} mean {:9.2e}   physical error max {xmax:9.2e} ({:8.1e} of the cell size)",
        psum / N as f64,
        xmax / H
    );
}

fn bench(cr: &mut Criterion) {
    for (name, offset) in [("origin", 0.0), ("1e6", 1e6)] {
        let c = case(offset);
        let cell32: Vec<_> = c.cells.iter().map(rebase_cell).collect();
        let mesh32: Vec<_> = c
            .cells
            .iter()
            .map(|x| rebase_mesh(x, c.mesh_origin))
            .collect();
        eprintln!("accuracy, cells at {name} ({N} cells of size {H}):");
        report("  f64 library invert", &c, |i| {
            invert(&c.cells[i], c.targets[i], None)
                .param()
                .unwrap_or(DVec3::NAN)
        });
        report("  f64 minimal Newton", &c, |i| {
            f64_minimal(&c.cells[i], c.targets[i])
        });
        report("  f32 rebased per cell", &c, |i| {
            f32_cell(&cell32[i], c.targets[i])
        });
        report("  f32 rebased to mesh centre", &c, |i| {
            f32_mesh(&mesh32[i], c.mesh_origin, c.targets[i])
        });
        report("  f32 absolute (no rebase)", &c, |i| {
            f32_absolute(&c.cells[i], c.targets[i])
        });

        let mut g = cr.benchmark_group(format!("inverse_map/{name}"));
        g.throughput(Throughput::Elements(N as u64));
        g.bench_function("f64_library", |b| {
            b.iter(|| {
                for i in 0..N {
                    black_box(invert(
                        black_box(&c.cells[i]),
                        black_box(c.targets[i]),
                        None,
                    ));
                }
            })
        });
        g.bench_function("f64_minimal", |b| {
            b.iter(|| {
                for i in 0..N {
                    black_box(f64_minimal(black_box(&c.cells[i]), black_box(c.targets[i])));
                }
            })
        });
        g.bench_function("f32_rebased_cell", |b| {
            b.iter(|| {
                for (stored, t) in cell32.iter().zip(&c.targets) {
                    black_box(f32_cell(black_box(stored), black_box(*t)));
                }
            })
        });
        g.bench_function("f32_rebased_mesh", |b| {
            b.iter(|| {
                for (stored, t) in mesh32.iter().zip(&c.targets) {
                    black_box(f32_mesh(black_box(stored), c.mesh_origin, black_box(*t)));
                }
            })
        });
        g.finish();
    }
}

criterion_group!(benches, bench);
criterion_main!(benches);
