//! Detection of the machine axis from the rotational structure of the cells' edges.
//!
//! # Method
//! A turbomachine mesh is laid out about its axis: some grid lines run circumferentially,
//! along circles about the axis, and the others lie in meridional planes (radial, axial, or
//! along a cone or a curved liner). So about the true axis each cell edge `a → b` is either
//! **circumferential** (its ends share the radius `r` and the axial position `h`) or
//! **meridional** (its ends share θ, i.e. it has no displacement
//! `t = d · (w_a × w_b) / max(r_a, r_b)` out of the meridional plane, `w` being a point's
//! offset from the axis normal to it). Each edge's relative residual is
//!
//! ```text
//!     c_e = min((Δr² + Δh²), t²) / |b − a|²      (in [0, 1]; 0 for an exact edge)
//! ```
//!
//! and a candidate line is scored on the twelve edges of a deterministic sample of cells
//! (zero-length edges of collapsed cells skipped) by the robust (Cauchy) loss
//! `Σ ln(1 + c_e / σ²)`, with `σ` = 10⁻³ for meridional and 5·10⁻² for circumferential
//! edges. The loss is robust so that cells which are not swept (blades twisted in θ, the
//! interpolated interior of a block) count only logarithmically while exact edges dominate;
//! circumferential edges are trusted less because interior circumferential lines of real
//! meshes are often interpolated chords that bulge (the combustor's interior arcs fit circles
//! about lines tilted by up to 20°), while its meridional surfaces stay planar to 0.02°.
//! A first version scored how tightly cells fit cylindrical (r, θ, h) boxes, as the plan
//! suggested; it found the mixer and the LOX post but not the combustor, whose meridional
//! grid runs along a cone about 30° off the axis: a line 19° off fits those skewed cells'
//! boxes better (box fit 1.38 against 1.72 about the true axis).
//!
//! The search has 4 degrees of freedom (2 for the direction, 2 for the origin in the plane
//! normal to it):
//! 1. Start directions: the x, y and z axes and the principal axes of the sampled cell
//!    centres (duplicates within 1° dropped).
//! 2. For each, a scan of origins in the normal plane — a 7 × 7 grid over the projected
//!    bounding box, then rings of 16 points out to 32 times its half-extent, so the axis of a
//!    thin sector far outside its mesh is found too — on a coarse sub-sample (the first
//!    [`COARSE_CELLS`] cells of the sample).
//! 3. Levenberg–Marquardt (iteratively reweighted for the robust loss, each edge's class
//!    fixed while the Jacobian is taken) from the best scan point of every direction on the
//!    coarse sub-sample. A mesh extruded along some direction (the mixer, the LOX post) is
//!    also swept exactly about lines infinitely far away, so the refined lines are compared
//!    by their **cylindrical box fit** (below) among those whose inlier fraction is at least
//!    half the best one: a true axis makes (r, θ, h) boxes tight, a line far away does not.
//!    The chosen line is refined again on the full sample ([`SAMPLE_CELLS`] cells).
//!
//! All geometry is relative to the mesh's bounding-box centre, so a mesh moved 10⁶ units
//! away gives the same axis. The sample is the golden-ratio sequence of cell indices
//! (`⌊frac(0.5 + kφ) · n⌋`), spread over the whole mesh without aliasing the strides of a
//! structured grid; any prefix of it is itself an even sub-sample.
//!
//! # The score: is there a clear axis?
//! An edge is an **inlier** when `c_e ≤` [`INLIER_TOLERANCE`]². A straight mesh (a Cartesian
//! block, any extrusion) is "swept" about a line infinitely far away, whose circles become
//! straight lines along some direction `t` normal to the axis; the **inliers at infinity**
//! are the same fraction with `Δr² + Δh²` replaced by `|e|² − (e·t)²` and `t²` by `(e·t)²`,
//! maximised over `t`. The **gain** is inliers ÷ inliers at infinity (the latter floored at
//! one edge): how much better the finite axis explains the edges than a straight sweep. An
//! axis is **clear** when the gain is at least [`CLEAR_AXIS_GAIN`] and at least
//! [`MIN_CLEAR_INLIERS`] of the edges are inliers. A Cartesian cube has all its edges inliers
//! at infinity, so a gain of at most 1: no clear axis.
//!
//! # Measured
//! With VTK's readers feeding [`Mesh::from_parts`](crate::Mesh::from_parts) (release build; angle to the true axis,
//! distance of the detected origin from the true line ÷ bounding-box diagonal, inliers,
//! inliers at infinity):
//!
//! | mesh | angle | offset | inliers | at infinity | clear |
//! |---|---|---|---|---|---|
//! | OpenFOAM mixer (z) | 0.00004° | 5.1·10⁻⁵ | 0.98 | 0.36 | yes |
//! | LOX post (z) | < 10⁻⁵° | 1.4·10⁻⁹ | 1.00 | 0.34 | yes |
//! | combustor (x) | 0.40° | 6.2·10⁻² | 0.70 | 0.11 | yes |
//! | `hexa.vtk` cube | — | — | 1.00 | 1.00 | no |
//!
//! The same meshes moved by (10⁶, −10⁶, 10⁶) give the same lines. The combustor's line lies
//! 1.5 units (5 % of its radius) towards the sector from the x axis: an 18° sector fixes
//! the radial position of its axis only through its 18° of curvature, and its interior lines
//! are not exact arcs. A 3.42 M-cell twisted ring takes about 150 ms of CPU time in all
//! (the sample makes the cost independent of the mesh size, apart from one pass over the
//! points for the bounds); the scans run on rayon's threads.
//!
//! The report also gives box fits: the geometric mean over the sample of (box volume ÷ cell
//! volume) for cylindrical boxes about the axis and for axis-aligned boxes in the x, y, z
//! frame the Cartesian structures use (1 is a perfect fit; larger is looser; each cell's log
//! ratio clamped to [ln 0.5, ln 10⁴]).

use glam::DVec3;
use rayon::prelude::*;

use super::optimize::{solve4, symmetric_eigen};
use super::Axis;
use crate::mesh::topology::EDGES;
use crate::Mesh;

/// The least gain (inliers ÷ inliers at infinity) of a clear axis.
pub const CLEAR_AXIS_GAIN: f64 = 2.0;

/// The least inlier fraction of a clear axis.
pub const MIN_CLEAR_INLIERS: f64 = 0.25;

/// The relative residual at or below which an edge is an inlier.
pub const INLIER_TOLERANCE: f64 = 1e-2;

/// Cells in the full sample (all cells of a smaller mesh).
pub const SAMPLE_CELLS: usize = 4096;

/// Cells in the coarse sub-sample used for the scan and the first local searches.
pub const COARSE_CELLS: usize = 512;

/// Robust-loss scale of meridional edges.
const SIGMA_MERIDIONAL: f64 = 1e-3;

/// Robust-loss scale of circumferential edges.
const SIGMA_CIRCUMFERENTIAL: f64 = 5e-2;

const METHOD: &str = "robust rotational edge fit (polar scan + IRLS Levenberg-Marquardt)";

const LN_LOW: f64 = -std::f64::consts::LN_2;
const LN_HIGH: f64 = 9.210340371976184; // ln 1e4

/// What axis detection found and how sure it is.
#[derive(Clone, Debug, PartialEq)]
pub struct Detection {
    /// The axis [`detect`] returns: `best_fit` when `clear`, otherwise the coordinate axis
    /// along which the bounding box is longest (z on ties, then y) through the box centre.
    pub axis: Axis,
    /// The line that fits the cells best, clear or not. Its origin is the point nearest the
    /// bounding-box centre.
    pub best_fit: Axis,
    /// Fraction of sampled edges that are circumferential or meridional about `best_fit`
    /// within [`INLIER_TOLERANCE`].
    pub inliers: f64,
    /// The same fraction for the best straight sweep normal to `best_fit` (a line at
    /// infinity).
    pub inliers_at_infinity: f64,
    /// `inliers / inliers_at_infinity` (the latter floored at one edge).
    pub gain: f64,
    /// Whether `gain ≥` [`CLEAR_AXIS_GAIN`] and `inliers ≥` [`MIN_CLEAR_INLIERS`].
    pub clear: bool,
    /// Root mean square over sampled edges of the relative residual `√c_e` about `best_fit`.
    pub residual: f64,
    /// Geometric mean of (cylindrical box volume about `best_fit` ÷ cell volume).
    pub cylindrical_fit: f64,
    /// Geometric mean of (x, y, z-aligned box volume ÷ cell volume).
    pub cartesian_fit: f64,
    /// Number of start directions tried.
    pub candidates: usize,
    /// Number of evaluations over the (coarse or full) sample.
    pub evaluations: usize,
    /// Number of cells in the sample.
    pub sampled_cells: usize,
    /// A short name of the method.
    pub method: &'static str,
}

/// Detects the axis the mesh turns about (see [`Detection::axis`] for what is returned when
/// no axis is clear).
///
/// ```
/// use cylvol::{axis, Mesh, MeshParts, CellKind};
/// use glam::DVec3;
/// // A ring of 36 × 4 × 2 hexahedra about z, r 1..2, h 0..1.
/// let (nr, nt, nh) = (5usize, 36usize, 3usize);
/// let mut points = Vec::new();
/// for k in 0..nh { for j in 0..nt { for i in 0..nr {
///     let (r, t) = (1.0 + i as f64 / 4.0, j as f64 * std::f64::consts::TAU / 36.0);
///     points.push(DVec3::new(r * t.cos(), r * t.sin(), k as f64 * 0.5));
/// }}}
/// let id = |i: usize, j: usize, k: usize| (i + nr * (j % nt + nt * k)) as u32;
/// let mut cells = Vec::new();
/// for k in 0..nh - 1 { for j in 0..nt { for i in 0..nr - 1 {
///     cells.push(cylvol::io::structured::cell_ids(i, j, k, id));
/// }}}
/// let kinds = vec![CellKind::Hexahedron; cells.len()];
/// let mesh = Mesh::from_parts(MeshParts { points, cells, kinds, ..Default::default() }).unwrap();
/// let a = axis::detect(&mesh);
/// assert!(a.direction.dot(DVec3::Z) > 0.9999);
/// assert!(a.distance_to(DVec3::ZERO) < 1e-3);
/// ```
pub fn detect(mesh: &Mesh) -> Axis {
    detect_with_report(mesh).axis
}

/// The root mean square relative edge residual `√c_e` of the mesh's cells about `axis` (see
/// the module docs; 0 for a mesh swept exactly about it), over the same sample detection
/// uses, e.g. to judge an axis given by the user. `NaN` if no cell has a positive volume.
pub fn residual_about(mesh: &Mesh, axis: &Axis) -> f64 {
    let b = mesh.bounds();
    let centre = DVec3::new(b[0] + b[1], b[2] + b[3], b[4] + b[5]) * 0.5;
    let sample = Sample::new(mesh, centre, SAMPLE_CELLS);
    if sample.len() == 0 {
        return f64::NAN;
    }
    let d = axis.direction.normalize_or_zero();
    sample.stats(sample.len(), axis.origin - centre, d).1
}

/// Cells' corners relative to the local origin, each edge's reciprocal length (0 for a
/// zero-length edge), each edge's vector times that (about a unit vector; zero for a
/// zero-length edge) with its squared length, for the straight sweeps, and the logarithm of
/// the cells' volumes.
struct Sample {
    corners: Vec<[DVec3; 8]>,
    inv_len: Vec<[f64; 12]>,
    unit_edges: Vec<[(DVec3, f64); 12]>,
    ln_volume: Vec<f64>,
}

/// An edge's class about a line: which of its residuals is smaller.
#[derive(Clone, Copy, PartialEq)]
enum Class {
    Circumferential,
    Meridional,
    Degenerate,
}

impl Sample {
    fn new(mesh: &Mesh, centre: DVec3, max_cells: usize) -> Sample {
        let n = mesh.cell_count();
        let points = mesh.points();
        let cells = mesh.cells();
        let take = n.min(max_cells);
        let mut s = Sample {
            corners: Vec::with_capacity(take),
            inv_len: Vec::with_capacity(take),
            unit_edges: Vec::with_capacity(take),
            ln_volume: Vec::with_capacity(take),
        };
        const PHI: f64 = 0.618_033_988_749_894_9;
        for k in 0..take {
            let c = if n <= max_cells {
                k
            } else {
                (((0.5 + k as f64 * PHI).fract() * n as f64) as usize).min(n - 1)
            };
            let Some(cell) = cells.get(c) else { continue };
            let mut x = [DVec3::ZERO; 8];
            let mut ok = true;
            for (slot, &id) in x.iter_mut().zip(cell) {
                match points.get(id as usize) {
                    Some(p) => *slot = *p - centre,
                    None => ok = false,
                }
            }
            let v = hex_volume(&x);
            if !(ok && v.is_finite() && v > 0.0) {
                continue;
            }
            let inv = EDGES.map(|[a, b]| {
                let l = (x[b] - x[a]).length();
                // Edges shorter than 10⁻⁹ of the cell are collapsed ones.
                if l > 1e-9 * v.cbrt() && (1.0 / l).is_finite() {
                    1.0 / l
                } else {
                    0.0
                }
            });
            let mut unit = [(DVec3::ZERO, 0.0); 12];
            for (e, &[a, b]) in EDGES.iter().enumerate() {
                let u = (x[b] - x[a]) * inv[e];
                unit[e] = (u, u.length_squared());
            }
            s.corners.push(x);
            s.inv_len.push(inv);
            s.unit_edges.push(unit);
            s.ln_volume.push(v.ln());
        }
        s
    }

    fn len(&self) -> usize {
        self.corners.len()
    }

    /// Each edge's relative `[Δr, Δh, t]` about the line through `o` along unit `d`, and its
    /// class.
    fn edge_terms(&self, i: usize, o: DVec3, d: DVec3) -> [([f64; 3], Class); 12] {
        let mut r = [0.0; 8];
        let mut h = [0.0; 8];
        let mut w = [DVec3::ZERO; 8];
        for (k, p) in self.corners[i].iter().enumerate() {
            let q = *p - o;
            h[k] = q.dot(d);
            w[k] = q - d * h[k];
            r[k] = w[k].length();
        }
        let inv = &self.inv_len[i];
        let mut out = [([0.0; 3], Class::Degenerate); 12];
        for (e, &[a, b]) in EDGES.iter().enumerate() {
            let s = inv[e];
            if s == 0.0 {
                continue;
            }
            let rm = r[a].max(r[b]);
            let t = if rm > 0.0 {
                d.dot(w[a].cross(w[b])) / rm
            } else {
                0.0
            };
            let v = [(r[b] - r[a]) * s, (h[b] - h[a]) * s, t * s];
            let class = if v[0] * v[0] + v[1] * v[1] <= v[2] * v[2] {
                Class::Circumferential
            } else {
                Class::Meridional
            };
            out[e] = (v, class);
        }
        out
    }

    /// An edge's squared residual over its σ² (the `q` of its robust loss `ln(1 + q)`).
    fn edge_q(v: &[f64; 3], class: Class) -> f64 {
        match class {
            Class::Circumferential => {
                (v[0] * v[0] + v[1] * v[1]) / (SIGMA_CIRCUMFERENTIAL * SIGMA_CIRCUMFERENTIAL)
            }
            Class::Meridional => v[2] * v[2] / (SIGMA_MERIDIONAL * SIGMA_MERIDIONAL),
            Class::Degenerate => 0.0,
        }
    }

    /// The robust loss of cell `i`'s edges, `Σ ln(1 + q)`, taken as the logarithm of the
    /// product of the `1 + q` (one logarithm a cell: each `q` is at most about 4·10⁶, as the
    /// residuals are relative, so the product of twelve stays far within range).
    fn cell_loss(&self, i: usize, o: DVec3, d: DVec3) -> f64 {
        self.edge_terms(i, o, d)
            .iter()
            .map(|(v, c)| 1.0 + Self::edge_q(v, *c))
            .product::<f64>()
            .ln()
    }

    /// The robust loss over the first `n` cells about the line of `chart` (its base line, at
    /// `x = 0`), with the normal equations of a reweighted Gauss–Newton step in the chart's
    /// four parameters (see [`Normal`]), from one pass over the cells. The cells are taken
    /// in chunks of a fixed size, in parallel, and the chunks' sums added in order: the
    /// same bits whatever the threads.
    fn normal_equations(&self, n: usize, chart: &Chart) -> Normal {
        const CHUNK: usize = 256;
        let n = n.min(self.len());
        let chunks: Vec<Normal> = (0..n.div_ceil(CHUNK))
            .into_par_iter()
            .map(|k| {
                let mut sum = Normal::ZERO;
                for i in k * CHUNK..((k + 1) * CHUNK).min(n) {
                    self.add_cell_normal(i, chart, &mut sum);
                }
                sum
            })
            .collect();
        chunks.iter().fold(Normal::ZERO, |a, b| a.plus(b))
    }

    /// Adds cell `i`'s edges to `sum` (see [`Sample::normal_equations`]). The derivatives are
    /// analytic. With `q` a corner's offset from the base line's origin `o` and `d` its
    /// direction: `h = q·d`, `w = q − d h`, `r = |w|`, `û = w / r`; moving the origin by `δo`
    /// (normal to `d`) and the direction by `δd` (normal to `d`, to first order) moves
    /// `h` by `q·δd` (`δo·d = 0`) and `r` by `−û·δo − h û·δd`; a meridional edge's
    /// `t = N / m`, `N = d·(q_a × q_b)`, `m = max(r_a, r_b)`, moves by `(δN − t δm) / m` with
    /// `δN = δd·(q_a × q_b) + δo·(d × (q_b − q_a))`. The chart's parameters are `δd = e1 x₀ +
    /// e2 x₁` and `δo = (e1 x₂ + e2 x₃) · scale`.
    fn add_cell_normal(&self, i: usize, chart: &Chart, sum: &mut Normal) {
        let (o, d) = (chart.origin, chart.direction);
        let (e1, e2, scale) = (chart.e1, chart.e2, chart.scale);
        let mut q = [DVec3::ZERO; 8];
        let mut h = [0.0; 8];
        let mut w = [DVec3::ZERO; 8];
        let mut r = [0.0; 8];
        // Per corner: û·e1, û·e2, q·e1, q·e2.
        let mut proj = [[0.0; 4]; 8];
        for (k, p) in self.corners[i].iter().enumerate() {
            q[k] = *p - o;
            h[k] = q[k].dot(d);
            w[k] = q[k] - d * h[k];
            r[k] = w[k].length();
            let u = if r[k] > 0.0 { w[k] / r[k] } else { DVec3::ZERO };
            proj[k] = [u.dot(e1), u.dot(e2), q[k].dot(e1), q[k].dot(e2)];
        }
        // The derivative of a corner's r in the four parameters.
        let dr = |k: usize| {
            [
                -h[k] * proj[k][0],
                -h[k] * proj[k][1],
                -scale * proj[k][0],
                -scale * proj[k][1],
            ]
        };
        let mut product = 1.0;
        for (e, &[a, b]) in EDGES.iter().enumerate() {
            let s = self.inv_len[i][e];
            if s == 0.0 {
                continue;
            }
            let rm = r[a].max(r[b]);
            let t = if rm > 0.0 {
                d.dot(w[a].cross(w[b])) / rm
            } else {
                0.0
            };
            let v = [(r[b] - r[a]) * s, (h[b] - h[a]) * s, t * s];
            if v[0] * v[0] + v[1] * v[1] <= v[2] * v[2] {
                // Circumferential: Δr and Δh over σ.
                let f = s / SIGMA_CIRCUMFERENTIAL;
                let res = [v[0] / SIGMA_CIRCUMFERENTIAL, v[1] / SIGMA_CIRCUMFERENTIAL];
                let (ra, rb) = (dr(a), dr(b));
                let j_r: [f64; 4] = std::array::from_fn(|k| (rb[k] - ra[k]) * f);
                let j_h = [
                    (proj[b][2] - proj[a][2]) * f,
                    (proj[b][3] - proj[a][3]) * f,
                    0.0,
                    0.0,
                ];
                let q2 = res[0] * res[0] + res[1] * res[1];
                product *= 1.0 + q2;
                sum.add(&j_r, res[0], 1.0 / (1.0 + q2));
                sum.add(&j_h, res[1], 1.0 / (1.0 + q2));
            } else {
                // Meridional: t over σ.
                let res = v[2] / SIGMA_MERIDIONAL;
                let q2 = res * res;
                product *= 1.0 + q2;
                if rm > 0.0 {
                    let f = s / SIGMA_MERIDIONAL;
                    let cross = q[a].cross(q[b]);
                    let edge = d.cross(q[b] - q[a]);
                    let dn = [
                        e1.dot(cross),
                        e2.dot(cross),
                        scale * e1.dot(edge),
                        scale * e2.dot(edge),
                    ];
                    let dm = if r[a] > r[b] { dr(a) } else { dr(b) };
                    let j_t: [f64; 4] = std::array::from_fn(|k| (dn[k] - t * dm[k]) / rm * f);
                    sum.add(&j_t, res, 1.0 / (1.0 + q2));
                }
            }
        }
        sum.cost += product.ln();
    }

    /// Mean over the first `n` cells of the robust loss of their edges.
    fn robust_cost(&self, n: usize, o: DVec3, d: DVec3) -> f64 {
        let n = n.min(self.len());
        (0..n).map(|i| self.cell_loss(i, o, d)).sum::<f64>() / n.max(1) as f64
    }

    /// Inlier fraction and RMS relative residual of the edges of the first `n` cells.
    fn stats(&self, n: usize, o: DVec3, d: DVec3) -> (f64, f64) {
        let n = n.min(self.len());
        let (mut edges, mut inliers, mut sum) = (0usize, 0usize, 0.0);
        for i in 0..n {
            for (v, class) in self.edge_terms(i, o, d) {
                let c = match class {
                    Class::Circumferential => v[0] * v[0] + v[1] * v[1],
                    Class::Meridional => v[2] * v[2],
                    Class::Degenerate => continue,
                };
                edges += 1;
                sum += c;
                if c <= INLIER_TOLERANCE * INLIER_TOLERANCE {
                    inliers += 1;
                }
            }
        }
        let e = edges.max(1) as f64;
        (inliers as f64 / e, (sum / e).sqrt())
    }

    /// Inlier count and edge count of a straight sweep along unit `t` (the limit of a line
    /// moved to infinity, its circles becoming lines along `t`).
    fn straight_inliers(&self, n: usize, t: DVec3) -> (usize, usize) {
        let n = n.min(self.len());
        let tol2 = INLIER_TOLERANCE * INLIER_TOLERANCE;
        let (mut edges, mut inliers) = (0usize, 0usize);
        for (i, unit) in self.unit_edges[..n].iter().enumerate() {
            for (e, &(u, len2)) in unit.iter().enumerate() {
                if self.inv_len[i][e] == 0.0 {
                    continue;
                }
                let along = u.dot(t);
                let across = (len2 - along * along).max(0.0);
                edges += 1;
                if across.min(along * along) <= tol2 {
                    inliers += 1;
                }
            }
        }
        (inliers, edges)
    }

    /// Geometric mean of cylindrical box ÷ cell volume about the line over the first `n`
    /// cells (clamped logs).
    fn cylindrical_fit(&self, n: usize, o: DVec3, d: DVec3) -> f64 {
        let n = n.min(self.len());
        let sum: f64 = self.corners[..n]
            .iter()
            .zip(&self.ln_volume)
            .map(|(c, lv)| (ln_cylindrical_volume(c, o, d) - lv).clamp(LN_LOW, LN_HIGH))
            .sum();
        (sum / n.max(1) as f64).exp()
    }

    /// Geometric mean of x, y, z-aligned box ÷ cell volume (clamped logs).
    fn cartesian_fit(&self) -> f64 {
        let sum: f64 = self
            .corners
            .iter()
            .zip(&self.ln_volume)
            .map(|(c, lv)| {
                let lo = c.iter().fold(DVec3::INFINITY, |m, p| m.min(*p));
                let hi = c.iter().fold(DVec3::NEG_INFINITY, |m, p| m.max(*p));
                let e = (hi - lo).max(DVec3::splat(f64::MIN_POSITIVE));
                (e.x.ln() + e.y.ln() + e.z.ln() - lv).clamp(LN_LOW, LN_HIGH)
            })
            .sum();
        (sum / self.len().max(1) as f64).exp()
    }

    fn centroids(&self) -> impl Iterator<Item = DVec3> + '_ {
        self.corners
            .iter()
            .map(|c| c.iter().copied().sum::<DVec3>() / 8.0)
    }
}

/// Volume of a hexahedron (VTK order) as six tetrahedra about its 0–6 diagonal; exact for
/// planar faces, zero contributions from the collapsed corners of other kinds.
fn hex_volume(x: &[DVec3; 8]) -> f64 {
    const TETS: [[usize; 2]; 6] = [[1, 2], [2, 3], [3, 7], [7, 4], [4, 5], [5, 1]];
    let d = x[6] - x[0];
    TETS.iter()
        .map(|&[a, b]| (x[a] - x[0]).cross(x[b] - x[0]).dot(d))
        .sum::<f64>()
        .abs()
        / 6.0
}

/// ln of the cylindrical box volume of the corners about the line through `o` along unit `d`.
fn ln_cylindrical_volume(c: &[DVec3; 8], o: DVec3, d: DVec3) -> f64 {
    let mut w = [DVec3::ZERO; 8];
    let mut r = [0.0f64; 8];
    let (mut hmin, mut hmax) = (f64::INFINITY, f64::NEG_INFINITY);
    let (mut rmin, mut rmax) = (f64::INFINITY, 0.0f64);
    let mut kmax = 0;
    let mut wsum = DVec3::ZERO;
    for k in 0..8 {
        let q = c[k] - o;
        let h = q.dot(d);
        let wk = q - d * h;
        let rk = wk.length();
        hmin = hmin.min(h);
        hmax = hmax.max(h);
        rmin = rmin.min(rk);
        if rk > rmax {
            rmax = rk;
            kmax = k;
        }
        w[k] = wk;
        r[k] = rk;
        wsum += wk;
    }
    let dh = hmax - hmin;
    if rmax <= 0.0 || dh <= 0.0 {
        return LN_HIGH + 1.0;
    }
    // Angles are measured from the direction of the corners' mean (or the farthest corner),
    // so no cell that the line misses crosses the ±π cut.
    let wc = wsum.length();
    let u = if wc > 1e-6 * rmax {
        wsum / wc
    } else {
        w[kmax] / rmax
    };
    let t = d.cross(u);
    let eps = 1e-9 * rmax;
    let (mut smin, mut smax) = (f64::INFINITY, f64::NEG_INFINITY);
    let mut front = true;
    for k in 0..8 {
        if r[k] <= eps {
            continue;
        }
        let x = w[k].dot(u);
        if x <= 0.0 {
            front = false;
            break;
        }
        let s = w[k].dot(t) / x;
        smin = smin.min(s);
        smax = smax.max(s);
    }
    let dtheta = if front {
        // All corners within ±π/2 of u: tan is monotonic there, one atan per cell.
        let den = 1.0 + smax * smin;
        if den > 0.0 {
            ((smax - smin) / den).atan()
        } else {
            smax.atan() - smin.atan()
        }
    } else {
        let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
        for k in 0..8 {
            if r[k] <= eps {
                continue;
            }
            let a = w[k].dot(t).atan2(w[k].dot(u));
            lo = lo.min(a);
            hi = hi.max(a);
        }
        hi - lo
    };
    let area = if dtheta > std::f64::consts::PI {
        // The line passes through the cell: a full disc.
        std::f64::consts::PI * rmax * rmax
    } else {
        0.5 * (rmax - rmin) * (rmax + rmin) * dtheta
    };
    if area > 0.0 {
        area.ln() + dh.ln()
    } else {
        LN_HIGH + 1.0
    }
}

/// Two unit vectors completing `d` to an orthonormal frame.
fn plane_basis(d: DVec3) -> (DVec3, DVec3) {
    let (u, v, _) = Axis {
        origin: DVec3::ZERO,
        direction: d,
    }
    .frame();
    (u, v)
}

/// A reweighted Gauss–Newton step's ingredients at a line: the robust loss `Σ ln(1 + q)`
/// over the edges, and the normal equations `a = Σ w J Jᵀ`, `g = Σ w J ρ` over their
/// residual components `ρ` (over σ) with gradients `J` in the chart's four parameters and
/// weights `w = 1 / (1 + q)`.
#[derive(Clone, Copy)]
struct Normal {
    cost: f64,
    a: [[f64; 4]; 4],
    g: [f64; 4],
}

impl Normal {
    const ZERO: Normal = Normal {
        cost: 0.0,
        a: [[0.0; 4]; 4],
        g: [0.0; 4],
    };

    /// Adds one residual component `rho` with gradient `j` and weight `w`.
    #[inline]
    fn add(&mut self, j: &[f64; 4], rho: f64, w: f64) {
        for (row, &jr) in self.a.iter_mut().zip(j) {
            for (x, &jc) in row.iter_mut().zip(j) {
                *x += w * jr * jc;
            }
        }
        for (x, &jr) in self.g.iter_mut().zip(j) {
            *x += w * jr * rho;
        }
    }

    fn plus(&self, o: &Normal) -> Normal {
        let mut out = *self;
        out.cost += o.cost;
        for (row, orow) in out.a.iter_mut().zip(&o.a) {
            for (x, y) in row.iter_mut().zip(orow) {
                *x += y;
            }
        }
        for (x, y) in out.g.iter_mut().zip(&o.g) {
            *x += y;
        }
        out
    }
}

/// A line parametrised for local search about a base line: two direction tilts (radians)
/// and two origin offsets (in units of `scale`) in the base line's normal plane.
#[derive(Clone, Copy)]
struct Chart {
    origin: DVec3,
    direction: DVec3,
    e1: DVec3,
    e2: DVec3,
    scale: f64,
}

impl Chart {
    fn new(origin: DVec3, direction: DVec3, scale: f64) -> Chart {
        let (e1, e2) = plane_basis(direction);
        Chart {
            origin,
            direction,
            e1,
            e2,
            scale,
        }
    }

    fn line(&self, x: &[f64; 4]) -> (DVec3, DVec3) {
        let d = (self.direction + self.e1 * x[0] + self.e2 * x[1]).normalize();
        let o = self.origin + (self.e1 * x[2] + self.e2 * x[3]) * self.scale;
        (o, d)
    }
}

/// Levenberg–Marquardt on the robust loss from the line `(o, d)` on the first `n` cells,
/// iteratively reweighted: each step solves the damped normal equations of
/// [`Sample::normal_equations`] (each edge weighted by `1 / (1 + q)`, `q` its scaled squared
/// residual, and its class held fixed, at the current line), and is taken where it lowers the
/// loss. Returns the refined line and the number of passes over the sample.
fn refine(
    sample: &Sample,
    n: usize,
    o: DVec3,
    d: DVec3,
    scale: f64,
    max_iter: usize,
) -> (DVec3, DVec3, usize) {
    let mut chart = Chart::new(o, d, scale);
    let mut current = sample.normal_equations(n, &chart);
    let mut evals = 1usize;
    let mut lambda = 1e-3;
    for _iter in 0..max_iter {
        let Normal { cost, a, g } = current;
        let mut accepted = false;
        let mut step_norm = 0.0;
        while lambda < 1e12 {
            let mut damped = a;
            for (i, row) in damped.iter_mut().enumerate() {
                row[i] += lambda * a[i][i].max(1e-12);
            }
            let Some(delta) = solve4(damped, g.map(|v| -v)) else {
                lambda *= 10.0;
                continue;
            };
            let (o2, d2) = chart.line(&delta);
            let moved = Chart::new(o2, d2, scale);
            let trial = sample.normal_equations(n, &moved);
            evals += 1;
            if trial.cost.is_finite() && trial.cost < cost {
                step_norm = delta.iter().map(|v| v.abs()).fold(0.0, f64::max);
                let improvement = cost - trial.cost;
                chart = moved;
                current = trial;
                let converged = improvement <= 1e-12 * cost.max(1e-300);
                lambda = (lambda / 3.0).max(1e-9);
                accepted = !converged;
                break;
            }
            lambda *= 4.0;
        }
        // Stop at convergence, or when the line runs away (a straight sweep, see the docs).
        if !accepted || step_norm < 1e-12 || chart.origin.length() > 1e3 * scale {
            break;
        }
    }
    (chart.origin, chart.direction, evals)
}

/// The report when no cell could be scored: the fallback axis, no fits.
fn undetected(fallback: Axis, sampled_cells: usize) -> Detection {
    Detection {
        axis: fallback,
        best_fit: fallback,
        inliers: f64::NAN,
        inliers_at_infinity: f64::NAN,
        gain: f64::NAN,
        clear: false,
        residual: f64::NAN,
        cylindrical_fit: f64::NAN,
        cartesian_fit: f64::NAN,
        candidates: 0,
        evaluations: 0,
        sampled_cells,
        method: METHOD,
    }
}

/// Detects the machine axis and reports how well it fits (see the module docs for the
/// method and the meaning of the inliers, the gain and the fits).
pub fn detect_with_report(mesh: &Mesh) -> Detection {
    let b = mesh.bounds();
    let lo = DVec3::new(b[0], b[2], b[4]);
    let hi = DVec3::new(b[1], b[3], b[5]);
    let centre = (lo + hi) * 0.5;
    let extent = hi - lo;
    let size = extent.length().max(f64::MIN_POSITIVE);
    let fallback = Axis {
        origin: centre,
        direction: if extent.z >= extent.x && extent.z >= extent.y {
            DVec3::Z
        } else if extent.y >= extent.x {
            DVec3::Y
        } else {
            DVec3::X
        },
    };
    let sample = Sample::new(mesh, centre, SAMPLE_CELLS);
    let n_full = sample.len();
    let n_coarse = n_full.min(COARSE_CELLS);
    if n_full == 0 {
        return undetected(fallback, 0);
    }
    let mut evaluations = 0usize;

    // Principal axes of the sampled cell centres.
    let mean = sample.centroids().sum::<DVec3>() / n_full as f64;
    let mut cov = [[0.0; 3]; 3];
    for p in sample.centroids() {
        let q = (p - mean).to_array();
        for (i, row) in cov.iter_mut().enumerate() {
            for (j, v) in row.iter_mut().enumerate() {
                *v += q[i] * q[j];
            }
        }
    }
    let (_, vecs) = symmetric_eigen(cov);
    let principal = [0, 1, 2].map(|k| DVec3::new(vecs[0][k], vecs[1][k], vecs[2][k]));
    let mut directions: Vec<DVec3> = Vec::new();
    let cos_1deg = 1f64.to_radians().cos();
    for d in [DVec3::X, DVec3::Y, DVec3::Z].into_iter().chain(principal) {
        let d = d.normalize_or_zero();
        if d != DVec3::ZERO && directions.iter().all(|e| e.dot(d).abs() < cos_1deg) {
            directions.push(d);
        }
    }

    // Scan of origins in each direction's normal plane, on the coarse sample: a grid over
    // the projected bounding box (its centre included), then rings outside it.
    const ANGLES: usize = 16;
    const GRID: usize = 7;
    const RINGS: [f64; 7] = [1.5, 2.0, 3.0, 4.0, 8.0, 16.0, 32.0];
    let mut starts: Vec<(DVec3, DVec3)> = Vec::new();
    for &d in &directions {
        let (e1, e2) = plane_basis(d);
        let (mut a0, mut a1) = (f64::INFINITY, f64::NEG_INFINITY);
        let (mut b0, mut b1) = (f64::INFINITY, f64::NEG_INFINITY);
        for k in 0..8 {
            let corner = DVec3::new(
                if k & 1 == 0 { lo.x } else { hi.x },
                if k & 2 == 0 { lo.y } else { hi.y },
                if k & 4 == 0 { lo.z } else { hi.z },
            ) - centre;
            let (a, b) = (corner.dot(e1), corner.dot(e2));
            a0 = a0.min(a);
            a1 = a1.max(a);
            b0 = b0.min(b);
            b1 = b1.max(b);
        }
        let half = ((a1 - a0).max(b1 - b0) * 0.5).max(size * 1e-3);
        let mut points = Vec::with_capacity(GRID * GRID + ANGLES * RINGS.len());
        for i in 0..GRID {
            for j in 0..GRID {
                let fa = i as f64 / (GRID - 1) as f64;
                let fb = j as f64 / (GRID - 1) as f64;
                points.push(e1 * (a0 + fa * (a1 - a0)) + e2 * (b0 + fb * (b1 - b0)));
            }
        }
        for rho in RINGS {
            for j in 0..ANGLES {
                let phi = j as f64 * std::f64::consts::TAU / ANGLES as f64;
                points.push((e1 * phi.cos() + e2 * phi.sin()) * (rho * half));
            }
        }
        // Scored in parallel, the best taken in order (deterministic).
        let costs: Vec<f64> = points
            .par_iter()
            .map(|&o| sample.robust_cost(n_coarse, o, d))
            .collect();
        evaluations += points.len();
        let mut best = (f64::INFINITY, DVec3::ZERO);
        for (&v, &o) in costs.iter().zip(&points) {
            if v < best.0 {
                best = (v, o);
            }
        }
        starts.push((best.1, d));
    }

    // Local refinement of every start on the coarse sample; among the lines that explain
    // the edges about as well as the best, the one whose cylindrical boxes fit best wins
    // (lines far away sweep extruded meshes too, see the module docs).
    let refined: Vec<(f64, f64, DVec3, DVec3, usize)> = starts
        .par_iter()
        .map(|&(o, d)| {
            let (o, d, n) = refine(&sample, n_coarse, o, d, size, 15);
            let inliers = sample.stats(n_coarse, o, d).0;
            let fit = sample.cylindrical_fit(n_coarse, o, d);
            (inliers, fit, o, d, n + 2)
        })
        .collect();
    evaluations += refined.iter().map(|c| c.4).sum::<usize>();
    let top = refined.iter().map(|c| c.0).fold(0.0, f64::max);
    let Some(&(_, _, o, d, _)) = refined
        .iter()
        .filter(|c| c.0 >= 0.5 * top)
        .min_by(|a, b| a.1.total_cmp(&b.1))
    else {
        return undetected(fallback, n_full);
    };
    let (o, d, n) = refine(&sample, n_full, o, d, size, 12);
    evaluations += n;
    let (inliers, residual) = sample.stats(n_full, o, d);

    // Inliers at infinity: the best straight sweep along a direction normal to d, scanned
    // on the coarse sample every 1°, then counted on the full sample at the best angle and
    // at eight angles around it.
    let (u, v) = plane_basis(d);
    let along = |phi: f64| u * phi.cos() + v * phi.sin();
    const STEPS: usize = 180;
    let step = std::f64::consts::PI / STEPS as f64;
    let coarse: Vec<usize> = (0..STEPS)
        .into_par_iter()
        .map(|j| sample.straight_inliers(n_coarse, along(j as f64 * step)).0)
        .collect();
    let best_j = (0..STEPS)
        .max_by_key(|&j| (coarse[j], std::cmp::Reverse(j)))
        .unwrap_or(0);
    let sweeps: Vec<(usize, usize)> = (-4i32..=4)
        .into_par_iter()
        .map(|k| sample.straight_inliers(n_full, along((best_j as f64 + k as f64 / 4.0) * step)))
        .collect();
    evaluations += STEPS + 9;
    let mut straight = (0usize, 1usize);
    for s in sweeps {
        if s.0 > straight.0 {
            straight = s;
        }
        straight.1 = s.1.max(1);
    }
    let inliers_at_infinity = straight.0 as f64 / straight.1 as f64;
    let gain = inliers / (straight.0.max(1) as f64 / straight.1 as f64);
    let clear = gain >= CLEAR_AXIS_GAIN && inliers >= MIN_CLEAR_INLIERS;
    let best_fit = match Axis::new(o + centre, d) {
        Ok(a) => a.through_nearest(centre),
        Err(_) => fallback,
    };
    Detection {
        axis: if clear { best_fit } else { fallback },
        best_fit,
        inliers,
        inliers_at_infinity,
        gain,
        clear,
        residual,
        cylindrical_fit: sample.cylindrical_fit(n_full, o, d),
        cartesian_fit: sample.cartesian_fit(),
        candidates: directions.len(),
        evaluations,
        sampled_cells: n_full,
        method: METHOD,
    }
}
