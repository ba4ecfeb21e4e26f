//! The inverse of the trilinear map: the parametric coordinates `(u, v, w)` of a physical point
//! in a (possibly collapsed, twisted, skewed or needle-thin) hexahedron.
//!
//! # Method
//! 1. **Rebase.** Everything is computed relative to corner 0 (`xᵢ − x₀`, `target − x₀`), so a
//!    cell 10⁶ units from the origin is solved with the precision of its own size.
//! 2. **Damped Newton.** From the guess (or the cell centre), `Δp = −J⁻¹ r` with the residual
//!    `r = x(p) − target`; where `J` is singular (collapsed edges and apexes) the step is the
//!    Levenberg–Marquardt one, `(JᵀJ + μI) Δp = −Jᵀ r`. A backtracking line search halves the
//!    step until `|r|` decreases. Iterates stay in the search box `[−1, 2]³` (the cell extended
//!    by its own size on every side). The first time a step meets that box, the target is
//!    checked against the convex hull of the corners (as in 3): outside it, the answer is
//!    [`InverseFailure::NotFound`] at once. Such a target lies far outside a thin cell, its
//!    preimage beyond the box, where the clamped iterates would only creep along the box.
//! 3. **Fallback.** If Newton does not converge, or converges outside the cell across a fold of
//!    the map (where a root inside the cell may hide), the cell's parameter cube is subdivided
//!    recursively; a sub-cube is rejected when the box of its eight mapped corners (which holds
//!    it: a sub-cube of a trilinear map is a trilinear cell) does not hold the target, and Newton
//!    is run from the centre of every sub-cube that survives.
//!    Before subdividing, a target outside the convex hull of the corners (which holds the
//!    cell), by more than `1e-8` of the cell size along one of the six face normals, is
//!    reported outside at once: the Newton root outside the cell if there is one, else
//!    [`InverseFailure::NotFound`].
//! 4. **Verify.** A result is returned only if it maps back to the target within the
//!    acceptance tolerance; otherwise the call reports why it failed. A wrong answer is never
//!    returned.
//!
//! # Tolerances (all relative to the cell size `L`, the diagonal of its corners' box)
//! - [`STOP_TOLERANCE`] `= 1e-14`: Newton stops once `|r| ≤ 1e-14 L`, a few ulps of the
//!   rebased coordinates — the parametric error is then at most `1e-14 L · ‖J⁻¹‖`, i.e. `1e-11`
//!   even for a needle with aspect 1:1000.
//! - [`ACCEPT_TOLERANCE`] `= 1e-10`: a result whose residual is larger is not returned. Newton
//!   only ends between the two when it stagnates at rounding level, which happens where `J` is
//!   singular (the target at a collapsed apex, where convergence is linear).
//! - [`PreparedCell::locate`], for containment tests that go on to interpolate (the fast
//!   path's march), may stop Newton before `STOP_TOLERANCE`: once the residual is within
//!   `ACCEPT_TOLERANCE`, the next step is at most [`LOCATE_STEP`] `= 1e-9` in each coordinate
//!   and the coordinates lie inside the cell by more than [`LOCATE_MARGIN`] `= 1e-6`.
//! - [`DEGENERATE_TOLERANCE`] `= 1e-12`: a cell whose `|det J|` at the corners and centre is at
//!   most `1e-12 L³` everywhere (flat, a line or a point) is not inverted.

use glam::{DMat3, DVec3};
use std::ops::AddAssign;

use super::bounds::cell_bounds;
use super::trilinear::{corner_jacobian_determinants, relative_corners, Monomials};

/// Newton stops once the physical residual is at most this times the cell size.
pub const STOP_TOLERANCE: f64 = 1e-14;
/// A solution is returned only if its physical residual is at most this times the cell size.
pub const ACCEPT_TOLERANCE: f64 = 1e-10;
/// A cell whose largest `|det J|` (corners and centre) is at most this times `L³` is degenerate.
pub const DEGENERATE_TOLERANCE: f64 = 1e-12;
/// Newton iterates stay in `[−SEARCH_MARGIN, 1 + SEARCH_MARGIN]³`.
pub const SEARCH_MARGIN: f64 = 1.0;
/// Parametric slack within which a result counts as inside the cell when deciding whether to
/// search the cell for another root (the same value as the containment tolerance).
pub const INSIDE_SLACK: f64 = 1e-9;
/// [`PreparedCell::locate`] may stop Newton once its next step is at most this long in each
/// parametric coordinate.
pub const LOCATE_STEP: f64 = 1e-9;
/// [`PreparedCell::locate`] may stop Newton only with the coordinates inside the cell by more
/// than this in each.
pub const LOCATE_MARGIN: f64 = 1e-6;

const MAX_NEWTON_ITERATIONS: u32 = 60;
const MAX_HALVINGS: u32 = 16;
const SUB_NEWTON_ITERATIONS: u32 = 12;
const MAX_SUBDIVISION_DEPTH: u32 = 12;
const MAX_SUBCELLS: u64 = 4096;

/// The cost of one or many inversions, for callers that report work done.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct InverseStats {
    /// Calls to [`invert`].
    pub inversions: u64,
    /// Newton iterations (each a Jacobian evaluation and a 3×3 solve), fallback included.
    pub newton_iterations: u64,
    /// Evaluations of the forward map (line-search trials and checks).
    pub map_evaluations: u64,
    /// Inversions that needed the subdivision fallback.
    pub fallbacks: u64,
    /// Sub-cells examined by the fallback.
    pub subcells: u64,
    /// Inversions that returned a failure.
    pub failures: u64,
}

impl AddAssign for InverseStats {
    fn add_assign(&mut self, o: Self) {
        self.inversions += o.inversions;
        self.newton_iterations += o.newton_iterations;
        self.map_evaluations += o.map_evaluations;
        self.fallbacks += o.fallbacks;
        self.subcells += o.subcells;
        self.failures += o.failures;
    }
}

/// Why an inversion gave no parametric coordinates.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum InverseFailure {
    /// A corner, the target or the guess is NaN or infinite.
    NonFinite,
    /// The cell has no volume: its corners coincide or lie on a line or in a plane.
    Degenerate,
    /// No parameter maps to the target: Newton found none in the search box `[−1, 2]³`, and the
    /// exhaustive subdivision of the cell rejected every sub-cell. The target is outside the
    /// cell (by more than the acceptance tolerance).
    NotFound,
    /// Undecided: Newton did not converge and the subdivision budget ran out with sub-cells
    /// still holding the target in their boxes. Does not happen for valid cells in practice.
    NoConvergence,
}

impl std::fmt::Display for InverseFailure {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            InverseFailure::NonFinite => "non-finite corner, target or guess",
            InverseFailure::Degenerate => "degenerate cell (no volume)",
            InverseFailure::NotFound => "no parameter maps to the target",
            InverseFailure::NoConvergence => "inverse map did not converge",
        })
    }
}

/// A converged inverse: `x(param)` lies within `residual` of the target.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Solution {
    /// The parametric coordinates `(u, v, w)`; in `[0, 1]³` when the target is inside the cell,
    /// possibly outside otherwise.
    pub param: DVec3,
    /// `|x(param) − target|`, at most [`ACCEPT_TOLERANCE`] times the cell size.
    pub residual: f64,
}

/// The outcome of [`invert`] with its cost.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Inversion {
    /// The solution, or why there is none.
    pub outcome: Result<Solution, InverseFailure>,
    /// The work this inversion took.
    pub stats: InverseStats,
}

impl Inversion {
    /// The parametric coordinates, if the inversion converged.
    pub fn param(&self) -> Option<DVec3> {
        self.outcome.ok().map(|s| s.param)
    }
}

/// The corner slots of the six faces (VTK hexahedron face order).
const HULL_FACES: [[usize; 4]; 6] = [
    [0, 4, 7, 3],
    [1, 2, 6, 5],
    [0, 1, 5, 4],
    [3, 7, 6, 2],
    [0, 3, 2, 1],
    [4, 5, 6, 7],
];

/// The cell rebased to corner 0 with its size.
/// A cell made ready for inversion: its corners rebased to corner 0, the monomial
/// coefficients of its trilinear map, and its size. [`invert`] prepares the cell for each
/// target; a caller with several targets in one cell (the samples of a ray crossing it)
/// prepares it once and calls [`PreparedCell::invert`] for each, with the same results.
///
/// ```
/// use cylvol::geometry::inverse::{invert, PreparedCell};
/// use cylvol::geometry::trilinear::{map, CORNER_PARAMETERS};
/// use glam::DVec3;
/// let mut cell = CORNER_PARAMETERS.map(DVec3::from_array);
/// cell[6] += DVec3::new(0.3, 0.2, 0.1);
/// let prepared = PreparedCell::new(&cell).unwrap();
/// for p in [DVec3::new(0.2, 0.7, 0.9), DVec3::new(0.5, 0.1, 0.4)] {
///     let x = map(&cell, p);
///     assert_eq!(prepared.invert(x, None), invert(&cell, x, None));
/// }
/// ```
#[derive(Clone, Debug, Default)]
pub struct PreparedCell {
    x0: DVec3,
    rel: [DVec3; 8],
    poly: Monomials,
    size: f64,
}

impl PreparedCell {
    /// Prepares `corners`: [`InverseFailure::NonFinite`] if one is not finite,
    /// [`InverseFailure::Degenerate`] if they all coincide.
    pub fn new(corners: &[DVec3; 8]) -> Result<PreparedCell, InverseFailure> {
        let mut cell = PreparedCell::default();
        cell.prepare(corners)?;
        Ok(cell)
    }

    /// Prepares `corners` in place of the cell held (no prepared data is copied); on an error
    /// the cell held is not usable, and [`PreparedCell::invert`] reports it degenerate.
    pub fn prepare(&mut self, corners: &[DVec3; 8]) -> Result<(), InverseFailure> {
        self.prepare_frame(corners)?;
        self.poly = Monomials::new(&self.rel);
        Ok(())
    }

    /// The first part of [`PreparedCell::prepare`]: the corners rebased and the size, enough
    /// for the hull test; the monomials are left as they were.
    fn prepare_frame(&mut self, corners: &[DVec3; 8]) -> Result<(), InverseFailure> {
        self.size = 0.0;
        if corners.iter().any(|c| !c.is_finite()) {
            return Err(InverseFailure::NonFinite);
        }
        self.rel = relative_corners(corners);
        let size = cell_bounds(&self.rel).diagonal();
        if !(size > 0.0 && size.is_finite()) {
            return Err(InverseFailure::Degenerate);
        }
        self.x0 = corners[0];
        self.size = size;
        Ok(())
    }

    /// [`invert`] of `target` in this cell.
    pub fn invert(&self, target: DVec3, guess: Option<DVec3>) -> Inversion {
        self.inversion(target, guess, false)
    }

    /// [`PreparedCell::invert`] for deciding whether `target` lies in the cell and
    /// interpolating there: Newton may stop before [`STOP_TOLERANCE`] once the residual is
    /// within [`ACCEPT_TOLERANCE`], the next Newton step would move the coordinates by at most
    /// [`LOCATE_STEP`] in each (near the root that step is their error), and they lie inside
    /// the cell by more than [`LOCATE_MARGIN`]. The target is then in the cell beyond doubt,
    /// and its coordinates are within about `LOCATE_STEP` of the exact ones; this saves the
    /// last Newton iteration for most points inside a cell. Every other answer is
    /// [`PreparedCell::invert`]'s.
    ///
    /// ```
    /// use cylvol::geometry::inverse::PreparedCell;
    /// use cylvol::geometry::trilinear::{map, CORNER_PARAMETERS};
    /// use glam::DVec3;
    /// let mut cell = CORNER_PARAMETERS.map(DVec3::from_array);
    /// cell[6] += DVec3::new(0.3, 0.2, 0.1);
    /// let prepared = PreparedCell::new(&cell).unwrap();
    /// let p = DVec3::new(0.2, 0.7, 0.9);
    /// let q = prepared.locate(map(&cell, p), None).param().unwrap();
    /// assert!((q - p).abs().max_element() < 1e-8);
    /// ```
    pub fn locate(&self, target: DVec3, guess: Option<DVec3>) -> Inversion {
        self.inversion(target, guess, true)
    }

    fn inversion(&self, target: DVec3, guess: Option<DVec3>, early: bool) -> Inversion {
        self.inversion_hull(target, guess, early, false)
    }

    /// The inversion; with `hull_at_cube`, the corners' hull is tested the first time an
    /// iterate would leave the unit cube (rather than the search box).
    fn inversion_hull(
        &self,
        target: DVec3,
        guess: Option<DVec3>,
        early: bool,
        hull_at_cube: bool,
    ) -> Inversion {
        let mut stats = InverseStats {
            inversions: 1,
            ..Default::default()
        };
        let outcome = if !target.is_finite() || guess.is_some_and(|g| !g.is_finite()) {
            Err(InverseFailure::NonFinite)
        } else if self.size <= 0.0 || self.size.is_nan() {
            Err(InverseFailure::Degenerate)
        } else {
            solve(self, target, guess, (early, hull_at_cube), &mut stats)
        };
        if outcome.is_err() {
            stats.failures += 1;
        }
        Inversion { outcome, stats }
    }
}

struct Problem<'a> {
    cell: &'a PreparedCell,
    target: DVec3,
    stop: f64,
    accept: f64,
    /// Stop Newton early where the containment is settled ([`PreparedCell::locate`]).
    early: bool,
    /// Test the corners' hull the first time an iterate of the main search would leave the
    /// unit cube, not only where one meets the search box ([`locate_within_hull`]).
    hull_at_cube: bool,
}

struct NewtonEnd {
    param: DVec3,
    residual: f64,
    jacobian: DMat3,
    /// Newton stopped where an iterate met the search box, the target being outside the
    /// convex hull of the corners: no root in the cell.
    beyond_hull: bool,
}

fn in_cube(p: DVec3, lo: f64, hi: f64) -> bool {
    p.cmpge(DVec3::splat(lo)).all() && p.cmple(DVec3::splat(hi)).all()
}

/// Solve `J Δ = −r`, falling back to a Levenberg–Marquardt step where `J` is singular.
fn newton_step(j: &DMat3, r: DVec3) -> DVec3 {
    // Cramer's rule with the cofactors as cross products; det² compared with the product of
    // the squared column lengths avoids square roots.
    let (a, b, c) = (j.x_axis, j.y_axis, j.z_axis);
    let bc = b.cross(c);
    let det = a.dot(bc);
    let scale2 = a.length_squared() * b.length_squared() * c.length_squared();
    if det * det > 1e-20 * scale2 {
        let inv_det = 1.0 / det;
        let d = -DVec3::new(r.dot(bc), r.dot(c.cross(a)), r.dot(a.cross(b))) * inv_det;
        if d.is_finite() {
            return d;
        }
    }
    let jt = j.transpose();
    let jtj = jt * *j;
    let mu = 1e-10 * (jtj.x_axis.x + jtj.y_axis.y + jtj.z_axis.z) + f64::MIN_POSITIVE;
    let a = jtj + DMat3::from_diagonal(DVec3::splat(mu));
    let d = -(a.inverse() * (jt * r));
    if d.is_finite() {
        d
    } else {
        DVec3::ZERO
    }
}

/// Whether `target` lies outside the convex hull of the cell's corners (which holds the cell)
/// by more than `1e-8` of the cell size, by the slabs between the corners' extreme projections
/// on the six face normals (each the cross product of the face's diagonals). `true` means the
/// target is not in the cell; `false` says nothing.
///
/// ```
/// use cylvol::geometry::inverse::outside_hull;
/// use cylvol::geometry::trilinear::CORNER_PARAMETERS;
/// use glam::DVec3;
/// let cube = CORNER_PARAMETERS.map(DVec3::from_array);
/// assert!(outside_hull(&cube, DVec3::new(0.5, 0.5, 1.01)));
/// assert!(!outside_hull(&cube, DVec3::new(0.5, 0.5, 0.99)));
/// ```
pub fn outside_hull(corners: &[DVec3; 8], target: DVec3) -> bool {
    // A cell that cannot be prepared (non-finite or all one point) separates nothing.
    let mut cell = PreparedCell::default();
    cell.prepare_frame(corners).is_ok() && hull_separates(&cell.rel, cell.size, target - cell.x0)
}

/// [`outside_hull`] for corners relative to corner 0 and a target relative to it.
///
/// A face's slab separates the target when its projection `t` exceeds every corner's `v` by
/// the margin (`t > v + margin` for all eight, which is `t > max v + margin`, rounding being
/// monotone), or falls short of every one. The corners are compared one at a time and the
/// face is left at the first corner on each side of `t`: a target inside the hull, the usual
/// case, is settled for each face after a few corners rather than all eight.
fn hull_separates(rel: &[DVec3; 8], size: f64, target: DVec3) -> bool {
    let pad = 1e-8 * size;
    'faces: for f in HULL_FACES {
        let [a, b, c, d] = f.map(|k| rel[k]);
        let n = (c - a).cross(d - b);
        let len = n.length();
        if !(len > 0.0 && len.is_finite()) {
            continue;
        }
        let t = n.dot(target);
        let margin = pad * len;
        let (mut above, mut below) = (true, true);
        for x in rel {
            let v = n.dot(*x);
            above &= t > v + margin;
            below &= t < v - margin;
            if !(above || below) {
                continue 'faces;
            }
        }
        return true;
    }
    false
}

impl Problem<'_> {
    /// Whether the target lies outside the convex hull of the corners by more than `1e-8` of
    /// the cell size, by the slabs between the corners' extreme projections on the six face
    /// normals (each the cross product of the face's diagonals).
    fn outside_hull(&self) -> bool {
        hull_separates(&self.cell.rel, self.cell.size, self.target)
    }

    /// Damped Newton from `start`, iterates clamped to `[lo, hi]³`. The `main` search (over
    /// the whole cell, not a sub-cell of the fallback) may end early in two ways. The first
    /// time a step meets the search box the target is checked against the convex hull of the
    /// corners, and Newton stops if it lies outside ([`NewtonEnd::beyond_hull`]): such a
    /// target, far outside a thin cell, has its preimage beyond the search box, where the
    /// clamped iterates would creep along the box for many steps to no end. And for
    /// [`PreparedCell::locate`] it stops once the containment is settled.
    fn newton(
        &self,
        start: DVec3,
        lo: f64,
        hi: f64,
        max_iter: u32,
        main: bool,
        stats: &mut InverseStats,
    ) -> NewtonEnd {
        let mut hull_unchecked = main;
        let mut p = start.clamp(DVec3::splat(lo), DVec3::splat(hi));
        let (x, mut j) = self.cell.poly.map_and_jacobian(p);
        stats.map_evaluations += 1;
        let mut r = x - self.target;
        let mut rn = r.length();
        for _ in 0..max_iter {
            if rn <= self.stop {
                break;
            }
            let d = newton_step(&j, r);
            // For a containment test ([`PreparedCell::locate`]): the residual is acceptable,
            // the step that would refine the coordinates (the size of their error) is tiny,
            // and they lie inside the cell by far more than it.
            if self.early
                && main
                && rn <= self.accept
                && d.abs().max_element() <= LOCATE_STEP
                && in_cube(p, LOCATE_MARGIN, 1.0 - LOCATE_MARGIN)
            {
                break;
            }
            stats.newton_iterations += 1;
            let mut t = 1.0;
            let mut accepted = false;
            for _ in 0..=MAX_HALVINGS {
                let free = p + d * t;
                let q = free.clamp(DVec3::splat(lo), DVec3::splat(hi));
                if hull_unchecked && (q != free || (self.hull_at_cube && !in_cube(free, 0.0, 1.0)))
                {
                    hull_unchecked = false;
                    if self.outside_hull() {
                        return NewtonEnd {
                            param: p,
                            residual: rn,
                            jacobian: j,
                            beyond_hull: true,
                        };
                    }
                }
                let (xq, jq) = self.cell.poly.map_and_jacobian(q);
                stats.map_evaluations += 1;
                let rq = xq - self.target;
                let rqn = rq.length();
                if rqn < rn {
                    let moved = (q - p).abs().max_element();
                    p = q;
                    j = jq;
                    r = rq;
                    rn = rqn;
                    accepted = true;
                    if moved <= 1e-15 {
                        accepted = false; // stagnated at rounding level
                    }
                    break;
                }
                t *= 0.5;
            }
            if !accepted {
                break;
            }
        }
        NewtonEnd {
            param: p,
            residual: rn,
            jacobian: j,
            beyond_hull: false,
        }
    }

    /// Recursive subdivision of `[0, 1]³` (padded by the slack), Newton on the surviving
    /// sub-cells; the first solution inside the padded cube wins.
    fn subdivide(&self, stats: &mut InverseStats) -> Result<NewtonEnd, InverseFailure> {
        let lo0 = -INSIDE_SLACK;
        let size0 = 1.0 + 2.0 * INSIDE_SLACK;
        let mut stack: Vec<(DVec3, f64, u32)> = vec![(DVec3::splat(lo0), size0, 0)];
        let mut exhausted = false;
        let mut best: Option<NewtonEnd> = None;
        while let Some((lo, size, depth)) = stack.pop() {
            if stats.subcells >= MAX_SUBCELLS {
                exhausted = true;
                break;
            }
            stats.subcells += 1;
            let mut bmin = DVec3::splat(f64::INFINITY);
            let mut bmax = DVec3::splat(f64::NEG_INFINITY);
            for c in super::trilinear::CORNER_PARAMETERS {
                let x = self.cell.poly.map(lo + DVec3::from_array(c) * size);
                bmin = bmin.min(x);
                bmax = bmax.max(x);
            }
            stats.map_evaluations += 8;
            let pad = self.accept + 1e-12 * (bmax - bmin).max_element();
            if !(self.target.cmpge(bmin - pad).all() && self.target.cmple(bmax + pad).all()) {
                continue;
            }
            let centre = lo + DVec3::splat(0.5 * size);
            let end = self.newton(
                centre,
                -SEARCH_MARGIN,
                1.0 + SEARCH_MARGIN,
                SUB_NEWTON_ITERATIONS,
                false,
                stats,
            );
            if end.residual <= self.accept && in_cube(end.param, lo0, 1.0 + INSIDE_SLACK) {
                return Ok(end);
            }
            if end.residual <= self.accept && best.is_none() {
                best = Some(end);
            }
            if depth >= MAX_SUBDIVISION_DEPTH {
                exhausted = true;
                continue;
            }
            let half = 0.5 * size;
            for k in 0..8u32 {
                let off = DVec3::new((k & 1) as f64, ((k >> 1) & 1) as f64, ((k >> 2) & 1) as f64);
                stack.push((lo + off * half, half, depth + 1));
            }
        }
        match best {
            Some(b) => Ok(b),
            None if exhausted => Err(InverseFailure::NoConvergence),
            None => Err(InverseFailure::NotFound),
        }
    }
}

/// The parametric coordinates of `target` in the cell, by damped Newton with a subdivision
/// fallback (see the module documentation for the method and tolerances). `guess` is a
/// starting point (e.g. the previous sample's coordinates in the same cell); the centre
/// `(½, ½, ½)` otherwise.
///
/// When the target lies in the cell, the returned coordinates are in `[0, 1]³` (to rounding);
/// on a collapsed edge or apex, where many coordinates map to the same point, one of them. When
/// it lies outside, the result is a preimage outside `[0, 1]³` (in `[−1, 2]³`) or
/// [`InverseFailure::NotFound`].
///
/// ```
/// use cylvol::geometry::inverse::invert;
/// use cylvol::geometry::trilinear::{map, CORNER_PARAMETERS};
/// use glam::DVec3;
/// let mut cell = CORNER_PARAMETERS.map(DVec3::from_array);
/// cell[6] += DVec3::new(0.3, 0.2, 0.1);
/// let p = DVec3::new(0.2, 0.7, 0.9);
/// let inv = invert(&cell, map(&cell, p), None);
/// assert!((inv.param().unwrap() - p).length() < 1e-12);
/// assert!(inv.stats.newton_iterations < 10);
/// ```
pub fn invert(corners: &[DVec3; 8], target: DVec3, guess: Option<DVec3>) -> Inversion {
    // Non-finite input is reported as such before a degenerate cell.
    if !target.is_finite() || guess.is_some_and(|g| !g.is_finite()) {
        return failed(InverseFailure::NonFinite);
    }
    // Prepared in place (a moved `PreparedCell` costs a copy of 400 bytes per call).
    let mut cell = PreparedCell::default();
    match cell.prepare(corners) {
        Ok(()) => cell.invert(target, guess),
        Err(e) => failed(e),
    }
}

/// A point location's candidate test: [`PreparedCell::locate`] of `target` in the cell,
/// prepared here, except that a target outside the corners' hull ([`outside_hull`]) may be
/// answered [`InverseFailure::NotFound`] before the inversion ends.
///
/// Without a guess the target is often a structure's candidate outside the cell, where the
/// hull rejects it for the price of a few dot products, while the inverse map of such a point
/// may take many damped Newton steps; but for the candidate that holds the target, the hull
/// test is wasted work. So the hull is tested the first time an iterate of Newton from the
/// centre would leave the unit cube: a target in the cell, whose iterates usually stay in the
/// cube, is never hull-tested, and one outside, whose iterates must leave it to converge, is
/// hull-tested after one step. With a guess (a warm start, usually in the cell) the hull is
/// tested only where an iterate meets the search box, as [`PreparedCell::locate`] does.
/// Where the hull does not separate the target, the Newton steps are the same as
/// `locate`'s, so is the answer; where it does, the answer is `NotFound`.
///
/// ```
/// use cylvol::geometry::inverse::{locate_within_hull, InverseFailure, PreparedCell};
/// use cylvol::geometry::trilinear::CORNER_PARAMETERS;
/// use glam::DVec3;
/// let cube = CORNER_PARAMETERS.map(DVec3::from_array);
/// let inside = DVec3::new(0.5, 0.5, 0.99);
/// let prepared = PreparedCell::new(&cube).unwrap();
/// assert_eq!(locate_within_hull(&cube, inside, None), prepared.locate(inside, None));
/// let outside = locate_within_hull(&cube, DVec3::new(0.5, 0.5, 1.01), None);
/// assert_eq!(outside.outcome.unwrap_err(), InverseFailure::NotFound);
/// ```
pub fn locate_within_hull(corners: &[DVec3; 8], target: DVec3, guess: Option<DVec3>) -> Inversion {
    if !target.is_finite() || guess.is_some_and(|g| !g.is_finite()) {
        return failed(InverseFailure::NonFinite);
    }
    let mut cell = PreparedCell::default();
    if let Err(e) = cell.prepare(corners) {
        return failed(e);
    }
    cell.inversion_hull(target, guess, true, guess.is_none())
}

/// An inversion that failed before any work.
fn failed(e: InverseFailure) -> Inversion {
    Inversion {
        outcome: Err(e),
        stats: InverseStats {
            inversions: 1,
            failures: 1,
            ..Default::default()
        },
    }
}

fn solve(
    cell: &PreparedCell,
    target: DVec3,
    guess: Option<DVec3>,
    (early, hull_at_cube): (bool, bool),
    stats: &mut InverseStats,
) -> Result<Solution, InverseFailure> {
    let size = cell.size;
    let prob = Problem {
        cell,
        target: target - cell.x0,
        stop: STOP_TOLERANCE * size,
        accept: ACCEPT_TOLERANCE * size,
        early,
        hull_at_cube,
    };
    let start = guess.unwrap_or(DVec3::splat(0.5));
    let end = prob.newton(
        start,
        -SEARCH_MARGIN,
        1.0 + SEARCH_MARGIN,
        MAX_NEWTON_ITERATIONS,
        true,
        stats,
    );
    // A candidate test's target beyond the hull is not in the cell, whatever the cell: no
    // need to look for a degenerate one.
    if prob.hull_at_cube && end.beyond_hull {
        return Err(InverseFailure::NotFound);
    }
    // A degenerate (flat) cell has a singular Jacobian everywhere; checking it only when Newton
    // ends somewhere singular (or fails) keeps the check off the common path.
    if end.residual > prob.accept || super::trilinear::is_singular(&end.jacobian) {
        // The largest |det J| at the centre and at the corners (where J's columns are the
        // cell's edges from the corner: no evaluation of the map needed).
        let centre = prob
            .cell
            .poly
            .map_and_jacobian(DVec3::splat(0.5))
            .1
            .determinant()
            .abs();
        stats.map_evaluations += 1;
        let max_det = corner_jacobian_determinants(&prob.cell.rel)
            .into_iter()
            .map(f64::abs)
            .fold(centre, f64::max);
        if max_det <= DEGENERATE_TOLERANCE * size * size * size {
            return Err(InverseFailure::Degenerate);
        }
    }
    if end.beyond_hull {
        return Err(InverseFailure::NotFound);
    }
    let mut outside_root = None;
    if end.residual <= prob.accept {
        if in_cube(end.param, -INSIDE_SLACK, 1.0 + INSIDE_SLACK) {
            return Ok(Solution {
                param: end.param,
                residual: end.residual,
            });
        }
        // On a collapsed edge or apex other coordinates map to the same point: prefer the
        // clamped ones if they do.
        let clamped = end.param.clamp(DVec3::ZERO, DVec3::ONE);
        let rc = (prob.cell.poly.map(clamped) - prob.target).length();
        stats.map_evaluations += 1;
        if rc <= prob.accept {
            return Ok(Solution {
                param: clamped,
                residual: rc,
            });
        }
        // A root outside the cell. If the map does not fold between the cell and the root
        // (det J keeps its sign and stays away from zero), the root is the only one near the
        // cell and the target is outside.
        let det_root = end.jacobian.determinant();
        let det_centre = prob
            .cell
            .poly
            .map_and_jacobian(DVec3::splat(0.5))
            .1
            .determinant();
        stats.map_evaluations += 1;
        if det_root * det_centre > 0.0 && det_root.abs() > 1e-3 * det_centre.abs() {
            return Ok(Solution {
                param: end.param,
                residual: end.residual,
            });
        }
        outside_root = Some(end);
    }
    // The cell lies in the convex hull of its corners (the shape functions are non-negative
    // and sum to one on [0, 1]³): a target outside a slab of that hull has no preimage in the
    // cell, and the subdivision would only confirm it.
    if prob.outside_hull() {
        return match outside_root {
            Some(e) => Ok(Solution {
                param: e.param,
                residual: e.residual,
            }),
            None => Err(InverseFailure::NotFound),
        };
    }
    stats.fallbacks += 1;
    match prob.subdivide(stats) {
        Ok(e) if in_cube(e.param, -INSIDE_SLACK, 1.0 + INSIDE_SLACK) || outside_root.is_none() => {
            Ok(Solution {
                param: e.param,
                residual: e.residual,
            })
        }
        other => match outside_root {
            Some(e) => Ok(Solution {
                param: e.param,
                residual: e.residual,
            }),
            None => other.map(|e| Solution {
                param: e.param,
                residual: e.residual,
            }),
        },
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::containment::param_inside;
    use crate::geometry::trilinear::{map, CORNER_PARAMETERS};
    use proptest::prelude::*;

    /// The slab test as first written: each face's whole slab of corner projections, then
    /// the target against it.
    fn hull_separates_eager(rel: &[DVec3; 8], size: f64, target: DVec3) -> bool {
        let pad = 1e-8 * size;
        HULL_FACES.iter().any(|f| {
            let [a, b, c, d] = f.map(|k| rel[k]);
            let n = (c - a).cross(d - b);
            let len = n.length();
            if !(len > 0.0 && len.is_finite()) {
                return false;
            }
            let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
            for x in rel {
                let v = n.dot(*x);
                lo = lo.min(v);
                hi = hi.max(v);
            }
            let t = n.dot(target);
            t > hi + pad * len || t < lo - pad * len
        })
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(2048))]

        /// The lazy slab test answers as the eager one, for distorted cells (collapsed
        /// corners included) and targets inside, near and beyond them.
        #[test]
        fn lazy_hull_test_equals_eager(
            moves in proptest::array::uniform8(proptest::array::uniform3(-0.45f64..0.45)),
            collapse in proptest::option::of((0usize..8, 0usize..8)),
            target in proptest::array::uniform3(-0.6f64..1.6),
            scale in prop_oneof![Just(1.0), Just(1e-6), Just(1e6)],
        ) {
            let mut c = CORNER_PARAMETERS.map(DVec3::from_array);
            for (x, m) in c.iter_mut().zip(moves) {
                *x += DVec3::from_array(m);
            }
            if let Some((i, j)) = collapse {
                c[i] = c[j];
            }
            let c = c.map(|x| x * scale);
            let rel = relative_corners(&c);
            let size = 1.7 * scale;
            let t = DVec3::from_array(target) * scale - c[0];
            prop_assert_eq!(hull_separates(&rel, size, t), hull_separates_eager(&rel, size, t));
            // On a corner or a face centre, exactly: the margins decide.
            for x in [rel[6], (rel[1] + rel[2] + rel[5] + rel[6]) * 0.25] {
                prop_assert_eq!(hull_separates(&rel, size, x), hull_separates_eager(&rel, size, x));
            }
        }

        /// The candidate test answers as `PreparedCell::locate`, except `NotFound` for a
        /// target outside the corners' hull, for cells degenerate or not and any guess.
        #[test]
        fn locate_within_hull_is_locate_or_outside_hull(
            moves in proptest::array::uniform8(proptest::array::uniform3(-0.45f64..0.45)),
            collapse in 0usize..3,
            target in proptest::array::uniform3(-0.6f64..1.6),
            guess in proptest::option::of(proptest::array::uniform3(0.0f64..1.0)),
        ) {
            let mut c = CORNER_PARAMETERS.map(DVec3::from_array);
            for (x, m) in c.iter_mut().zip(moves) {
                *x += DVec3::from_array(m);
            }
            match collapse {
                1 => c = [c[0]; 8],
                2 => c[3] = DVec3::NAN,
                _ => {}
            }
            let (p, g) = (DVec3::from_array(target), guess.map(DVec3::from_array));
            let got = locate_within_hull(&c, p, g);
            let located = match PreparedCell::new(&c) {
                Ok(cell) => cell.locate(p, g),
                Err(e) => failed(e),
            };
            if g.is_none() && outside_hull(&c, p) {
                prop_assert_eq!(got.outcome, Err(InverseFailure::NotFound));
            } else {
                prop_assert_eq!(got.outcome, located.outcome);
            }
        }
    }

    fn cell() -> [DVec3; 8] {
        let mut c = CORNER_PARAMETERS.map(DVec3::from_array);
        c[6] += DVec3::new(0.3, 0.2, 0.25);
        c[1] += DVec3::new(0.1, -0.2, 0.05);
        c
    }

    #[test]
    fn converges_quadratically_and_counts() {
        let c = cell();
        let p = DVec3::new(0.1, 0.8, 0.35);
        let inv = invert(&c, map(&c, p), None);
        let s = inv.outcome.unwrap();
        assert!((s.param - p).length() < 1e-13);
        assert!(s.residual <= STOP_TOLERANCE * 2.0);
        assert_eq!(inv.stats.inversions, 1);
        assert_eq!(inv.stats.fallbacks, 0);
        assert!((1..=8).contains(&inv.stats.newton_iterations));
        // A good guess needs fewer iterations.
        let warm = invert(&c, map(&c, p), Some(p + DVec3::splat(1e-4)));
        assert!(warm.stats.newton_iterations < inv.stats.newton_iterations);
        let mut total = InverseStats::default();
        total += inv.stats;
        total += warm.stats;
        assert_eq!(total.inversions, 2);
    }

    #[test]
    fn far_from_origin_keeps_precision() {
        let c = cell().map(|x| x * 1e-3 + DVec3::new(1e6, -2e6, 3e6));
        let p = DVec3::new(0.6, 0.3, 0.9);
        let target = map(&c, p);
        let q = invert(&c, target, None).param().unwrap();
        // The target is rounded to ~2e-10 at 3e6; seen in a 1e-3 cell that is ~1e-6.
        assert!((q - p).abs().max_element() < 2e-6);
        assert!((map(&c, q) - target).length() <= 1e-9);
    }

    #[test]
    fn tetrahedron_apex_and_collapsed_edge() {
        // Tetrahedron stored as [0, 1, 2, 2, 3, 3, 3, 3].
        let v = [DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::Z];
        let c = [v[0], v[1], v[2], v[2], v[3], v[3], v[3], v[3]];
        for target in [v[3], (v[2] + v[3]) * 0.5, DVec3::new(0.2, 0.2, 0.2)] {
            let inv = invert(&c, target, None);
            let q = inv.param().expect("found");
            assert!(q.cmpge(DVec3::splat(-1e-9)).all() && q.cmple(DVec3::splat(1.0 + 1e-9)).all());
            assert!(
                (map(&c, q) - target).length() <= ACCEPT_TOLERANCE * 2.0,
                "{target}: {inv:?}"
            );
        }
    }

    #[test]
    fn outside_the_hull_needs_no_subdivision() {
        // A thin sheared slab: its box holds points far from the cell in parametric terms.
        let mut c = CORNER_PARAMETERS.map(|p| DVec3::new(p[0], p[1], 0.01 * p[2]));
        for (k, ck) in c.iter_mut().enumerate() {
            ck.z += 0.5 * ck.x + if k == 6 { 0.003 } else { 0.0 };
        }
        let target = DVec3::new(0.2, 0.5, 0.4);
        let inv = invert(&c, target, None);
        assert_eq!(inv.stats.fallbacks, 0);
        assert_eq!(inv.stats.subcells, 0);
        assert!(inv.param().map_or(true, |q| !in_cube(q, -1e-9, 1.0 + 1e-9)));
        // Inside points are still found.
        let p = DVec3::new(0.3, 0.6, 0.5);
        let q = invert(&c, map(&c, p), None).param().expect("inside");
        assert!((q - p).length() < 1e-9);
    }

    #[test]
    fn locate_saves_the_last_iteration_inside_and_agrees() {
        let c = cell();
        let prepared = PreparedCell::new(&c).unwrap();
        let (mut full, mut early) = (0, 0);
        let mut previous = None;
        // Points along a line through the cell and beyond it, each warm-started from the
        // previous one's coordinates, as the samples of a ray are.
        for k in 0..=60 {
            let p = DVec3::new(-0.1, 0.2, 0.3) + DVec3::new(1.2, 0.5, 0.4) * (k as f64 / 60.0);
            let x = map(&c, p);
            let (a, b) = (prepared.invert(x, previous), prepared.locate(x, previous));
            full += a.stats.map_evaluations;
            early += b.stats.map_evaluations;
            let (qa, qb) = (a.param().unwrap(), b.param().unwrap());
            assert_eq!(param_inside(qa), param_inside(qb), "{p}");
            assert!(
                (qa - qb).abs().max_element() <= 4.0 * LOCATE_STEP,
                "{qa} vs {qb}"
            );
            assert!(
                (qb - p).abs().max_element() <= 4.0 * LOCATE_STEP,
                "{qb} vs {p}"
            );
            previous = Some(qb);
        }
        assert!(early < full, "{early} vs {full} evaluations");
    }

    #[test]
    fn far_outside_a_thin_cell_stops_at_the_search_box() {
        // A slab 100 times thinner than wide, and targets half its width beyond its thin
        // faces: their preimages lie some 50 cell thicknesses out, far past the search box
        // [−1, 2]³. The hull settles them as soon as a Newton step meets the box, without
        // the clamped iterates creeping along it (about thirty evaluations of the map).
        let thin = CORNER_PARAMETERS.map(|p| DVec3::new(p[0], p[1], 0.01 * p[2]));
        for z in [0.5, -0.5] {
            let inv = invert(&thin, DVec3::new(0.4, 0.6, z), None);
            assert_eq!(inv.outcome, Err(InverseFailure::NotFound), "{z}");
            assert!(inv.stats.map_evaluations <= 4, "{z}: {:?}", inv.stats);
            assert_eq!(inv.stats.fallbacks, 0);
        }
        // Just beyond the thin face, and inside, Newton still converges as before.
        let near = invert(&thin, DVec3::new(0.4, 0.6, 0.0105), None);
        let q = near.param().expect("an outside root");
        assert!((q.z - 1.05).abs() < 1e-9, "{q}");
        let inside = invert(&thin, DVec3::new(0.4, 0.6, 0.005), None);
        assert!((inside.param().unwrap() - DVec3::new(0.4, 0.6, 0.5)).length() < 1e-12);
    }

    #[test]
    fn clean_failures() {
        let flat = CORNER_PARAMETERS.map(|p| DVec3::new(p[0], p[1], 0.0));
        let inv = invert(&flat, DVec3::new(0.3, 0.3, 0.0), None);
        assert_eq!(inv.outcome, Err(InverseFailure::Degenerate));
        assert_eq!(inv.stats.failures, 1);
        assert_eq!(
            invert(&cell(), DVec3::new(0.5, f64::NAN, 0.5), None).outcome,
            Err(InverseFailure::NonFinite)
        );
        let far = invert(&cell(), DVec3::splat(1e3), None);
        assert!(far.param().map_or(true, |q| q.max_element() > 1.0));
    }
}
