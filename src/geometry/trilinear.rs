//! The trilinear map of a hexahedron in VTK vertex order, `x(u, v, w)` for `(u, v, w) ∈ [0, 1]³`,
//! its Jacobian, and the interpolation of corner values with their gradients.
//!
//! Corner `i` has the parametric coordinates [`CORNER_PARAMETERS`]`[i]` and the shape function
//! `N_i(u, v, w) = û ŵ v̂` with `û = u` or `1 − u` as the corner's `u` is 1 or 0 (likewise `v`, `w`).
//! Collapsed hexahedra (wedges, pyramids, tetrahedra; see [`crate::mesh::CellKind`]) use the same
//! map; their Jacobian is singular on the collapsed edges and faces.
//!
//! Positions are evaluated relative to corner 0, `x = x₀ + Σ Nᵢ (xᵢ − x₀)`, so a cell placed far
//! from the origin keeps the precision its size allows (and a point inside never leaves the
//! cell's hull by more than rounding).

use glam::{DMat3, DVec3};

/// Parametric coordinates of the eight corners, in VTK hexahedron order.
pub const CORNER_PARAMETERS: [[f64; 3]; 8] = [
    [0.0, 0.0, 0.0],
    [1.0, 0.0, 0.0],
    [1.0, 1.0, 0.0],
    [0.0, 1.0, 0.0],
    [0.0, 0.0, 1.0],
    [1.0, 0.0, 1.0],
    [1.0, 1.0, 1.0],
    [0.0, 1.0, 1.0],
];

/// Below this value of `|det J| / (|J₀| |J₁| |J₂|)` (the sine-like quality of the Jacobian's
/// columns, scale invariant, 1 for orthogonal columns) the Jacobian counts as singular.
pub const SINGULAR_QUALITY: f64 = 1e-12;

/// The determinant of the trilinear map's Jacobian at each corner: the triple product of the
/// three edges leaving that corner in the `+u`, `+v`, `+w` sense. Positive for a well-formed
/// cell in VTK order; zero at the collapsed corners of wedges, pyramids and tetrahedra.
pub fn corner_jacobian_determinants(x: &[DVec3; 8]) -> [f64; 8] {
    [
        corner_determinant::<0>(x),
        corner_determinant::<1>(x),
        corner_determinant::<2>(x),
        corner_determinant::<3>(x),
        corner_determinant::<4>(x),
        corner_determinant::<5>(x),
        corner_determinant::<6>(x),
        corner_determinant::<7>(x),
    ]
}

/// The Jacobian determinant at corner `C`, its edges' corners constants (no index arithmetic
/// or bounds checks in the validation's and the inverse map's inner loops).
#[inline(always)]
fn corner_determinant<const C: usize>(x: &[DVec3; 8]) -> f64 {
    let edge = |[from, to]: [usize; 2]| x[to] - x[from];
    let [du, dv, dw] = const { CORNER_EDGES[C] };
    DMat3::from_cols(edge(du), edge(dv), edge(dw)).determinant()
}

/// For each corner `(u, v, w)`, the corners `[from, to]` of its edges along `u`, `v` and `w`:
/// the derivative along `u` there is `x(1, v, w) − x(0, v, w)`, and so on.
const CORNER_EDGES: [[[usize; 2]; 3]; 8] = corner_edges();

const fn corner_edges() -> [[[usize; 2]; 3]; 8] {
    let mut edges = [[[0; 2]; 3]; 8];
    let mut c = 0;
    while c < 8 {
        // Corner c's parameters in VTK order (CORNER_PARAMETERS, as integers).
        let (u, v, w) = ([0, 1, 1, 0][c % 4], [0, 0, 1, 1][c % 4], c / 4);
        edges[c] = [
            [index(0, v, w), index(1, v, w)],
            [index(u, 0, w), index(u, 1, w)],
            [index(u, v, 0), index(u, v, 1)],
        ];
        c += 1;
    }
    edges
}

/// VTK hexahedron vertex index of the corner with parametric coordinates `(u, v, w)` ∈ {0, 1}³.
pub const fn index(u: usize, v: usize, w: usize) -> usize {
    const LUT: [[usize; 2]; 2] = [[0, 3], [1, 2]];
    LUT[u][v] + 4 * w
}

/// The eight shape functions `Nᵢ(u, v, w)` at `p = (u, v, w)`, in VTK corner order. They sum
/// to 1 (up to rounding) for every `p`.
///
/// ```
/// use cylvol::geometry::trilinear::weights;
/// use glam::DVec3;
/// let n = weights(DVec3::new(1.0, 0.0, 0.0));
/// assert_eq!(n, [0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0]);
/// ```
#[inline]
pub fn weights(p: DVec3) -> [f64; 8] {
    let (u, v, w) = (p.x, p.y, p.z);
    let (iu, iv, iw) = (1.0 - u, 1.0 - v, 1.0 - w);
    let (a, b, c, d) = (iu * iv, u * iv, u * v, iu * v);
    [a * iw, b * iw, c * iw, d * iw, a * w, b * w, c * w, d * w]
}

/// The derivatives `(∂Nᵢ/∂u, ∂Nᵢ/∂v, ∂Nᵢ/∂w)` of the eight shape functions at `p`.
#[inline]
pub fn weight_derivatives(p: DVec3) -> [DVec3; 8] {
    let (u, v, w) = (p.x, p.y, p.z);
    let (iu, iv, iw) = (1.0 - u, 1.0 - v, 1.0 - w);
    [
        DVec3::new(-iv * iw, -iu * iw, -iu * iv),
        DVec3::new(iv * iw, -u * iw, -u * iv),
        DVec3::new(v * iw, u * iw, -u * v),
        DVec3::new(-v * iw, iu * iw, -iu * v),
        DVec3::new(-iv * w, -iu * w, iu * iv),
        DVec3::new(iv * w, -u * w, u * iv),
        DVec3::new(v * w, u * w, u * v),
        DVec3::new(-v * w, iu * w, iu * v),
    ]
}

/// The corners relative to corner 0 (`xᵢ − x₀`; the first is zero). The inverse map works in
/// this frame so that a cell far from the origin loses no precision.
#[inline]
pub fn relative_corners(corners: &[DVec3; 8]) -> [DVec3; 8] {
    let o = corners[0];
    corners.map(|c| c - o)
}

/// The position `x(p) − x₀` of a cell given by its corners relative to corner 0 (see
/// [`relative_corners`]), with its Jacobian (columns `∂x/∂u`, `∂x/∂v`, `∂x/∂w`).
#[inline]
pub fn relative_map_and_jacobian(rel: &[DVec3; 8], p: DVec3) -> (DVec3, DMat3) {
    let n = weights(p);
    let dn = weight_derivatives(p);
    let mut x = DVec3::ZERO;
    let (mut ju, mut jv, mut jw) = (DVec3::ZERO, DVec3::ZERO, DVec3::ZERO);
    for i in 0..8 {
        x += rel[i] * n[i];
        ju += rel[i] * dn[i].x;
        jv += rel[i] * dn[i].y;
        jw += rel[i] * dn[i].z;
    }
    (x, DMat3::from_cols(ju, jv, jw))
}

/// The trilinear map of a cell relative to corner 0 in monomial form,
/// `x(u, v, w) − x₀ = b u + c v + d w + e uv + f vw + g uw + h uvw`: the map and its Jacobian
/// then cost about a third of the shape-function sums of [`relative_map_and_jacobian`] (the
/// inverse map evaluates them a few times per call). The values agree with it to rounding.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Monomials {
    b: DVec3,
    c: DVec3,
    d: DVec3,
    e: DVec3,
    f: DVec3,
    g: DVec3,
    h: DVec3,
}

impl Monomials {
    /// From the corners relative to corner 0 ([`relative_corners`]).
    ///
    /// ```
    /// use cylvol::geometry::trilinear::{relative_corners, relative_map_and_jacobian, Monomials, CORNER_PARAMETERS};
    /// use glam::DVec3;
    /// let mut cell = CORNER_PARAMETERS.map(DVec3::from_array);
    /// cell[6] += DVec3::new(0.3, -0.2, 0.1);
    /// let rel = relative_corners(&cell);
    /// let p = DVec3::new(0.2, 0.7, 0.4);
    /// let (x, j) = Monomials::new(&rel).map_and_jacobian(p);
    /// let (x0, j0) = relative_map_and_jacobian(&rel, p);
    /// assert!((x - x0).length() < 1e-15 && (j - j0).abs_diff_eq(glam::DMat3::ZERO, 1e-15));
    /// ```
    #[inline]
    pub fn new(rel: &[DVec3; 8]) -> Monomials {
        let [x0, x1, x2, x3, x4, x5, x6, x7] = *rel;
        Monomials {
            b: x1 - x0,
            c: x3 - x0,
            d: x4 - x0,
            e: (x0 - x1) + (x2 - x3),
            f: (x0 - x3) + (x7 - x4),
            g: (x0 - x1) + (x5 - x4),
            h: ((x1 - x0) + (x3 - x2)) + ((x4 - x5) + (x6 - x7)),
        }
    }

    /// `x(p) − x₀`.
    #[inline]
    pub fn map(&self, p: DVec3) -> DVec3 {
        let (u, v, w) = (p.x, p.y, p.z);
        self.b * u
            + self.c * v
            + self.d * w
            + (self.e + self.h * w) * (u * v)
            + self.f * (v * w)
            + self.g * (u * w)
    }

    /// `x(p) − x₀` and the Jacobian (columns `∂x/∂u`, `∂x/∂v`, `∂x/∂w`).
    #[inline]
    pub fn map_and_jacobian(&self, p: DVec3) -> (DVec3, DMat3) {
        let (u, v, w) = (p.x, p.y, p.z);
        let ju = self.b + self.e * v + self.g * w + self.h * (v * w);
        let jv = self.c + self.e * u + self.f * w + self.h * (u * w);
        let jw = self.d + self.f * v + self.g * u + self.h * (u * v);
        (self.map(p), DMat3::from_cols(ju, jv, jw))
    }
}

/// The position `x(p) − x₀` of a cell given by its corners relative to corner 0.
#[inline]
pub fn relative_map(rel: &[DVec3; 8], p: DVec3) -> DVec3 {
    let n = weights(p);
    let mut x = DVec3::ZERO;
    for i in 1..8 {
        x += rel[i] * n[i];
    }
    x
}

/// The forward map `x(u, v, w)`: the point of the cell at parametric coordinates `p`
/// (also defined, by extension, outside `[0, 1]³`).
///
/// ```
/// use cylvol::geometry::trilinear::{map, CORNER_PARAMETERS};
/// use glam::DVec3;
/// let unit = CORNER_PARAMETERS.map(DVec3::from_array);
/// let cell = unit.map(|c| c * 2.0 + DVec3::X);
/// assert_eq!(map(&cell, DVec3::splat(0.5)), DVec3::new(2.0, 1.0, 1.0));
/// ```
#[inline]
pub fn map(corners: &[DVec3; 8], p: DVec3) -> DVec3 {
    corners[0] + relative_map(&relative_corners(corners), p)
}

/// The Jacobian `∂x/∂(u, v, w)` at `p`: a matrix whose columns are `∂x/∂u`, `∂x/∂v`, `∂x/∂w`.
#[inline]
pub fn jacobian(corners: &[DVec3; 8], p: DVec3) -> DMat3 {
    relative_map_and_jacobian(&relative_corners(corners), p).1
}

/// The forward map and the Jacobian at `p` together (cheaper than calling both).
#[inline]
pub fn map_and_jacobian(corners: &[DVec3; 8], p: DVec3) -> (DVec3, DMat3) {
    let (x, j) = relative_map_and_jacobian(&relative_corners(corners), p);
    (corners[0] + x, j)
}

/// Whether a Jacobian is singular: `|det J|` at most [`SINGULAR_QUALITY`] times the product of
/// its column lengths (or not finite).
#[inline]
pub fn is_singular(j: &DMat3) -> bool {
    let scale = j.x_axis.length() * j.y_axis.length() * j.z_axis.length();
    let det = j.determinant();
    !(det.is_finite() && scale.is_finite()) || det.abs() <= SINGULAR_QUALITY * scale
}

/// The trilinear interpolation of the eight corner values at `p`.
///
/// ```
/// use cylvol::geometry::trilinear::interpolate;
/// use glam::DVec3;
/// let f = [0.0, 1.0, 1.0, 0.0, 0.0, 1.0, 1.0, 0.0]; // f = u
/// assert!((interpolate(&f, DVec3::new(0.25, 0.7, 0.1)) - 0.25).abs() < 1e-15);
/// ```
#[inline]
pub fn interpolate(values: &[f64; 8], p: DVec3) -> f64 {
    let n = weights(p);
    let mut s = 0.0;
    for i in 0..8 {
        s += values[i] * n[i];
    }
    s
}

/// The gradient of the interpolated values with respect to `(u, v, w)` at `p`.
#[inline]
pub fn parametric_gradient(values: &[f64; 8], p: DVec3) -> DVec3 {
    let dn = weight_derivatives(p);
    let mut g = DVec3::ZERO;
    for i in 0..8 {
        g += dn[i] * values[i];
    }
    g
}

/// The gradient of the interpolated values in physical space at `p`, `J⁻ᵀ · ∇_{uvw} f`;
/// `None` where the Jacobian is singular (see [`is_singular`]), e.g. on the collapsed edges of
/// wedges, pyramids and tetrahedra.
pub fn physical_gradient(corners: &[DVec3; 8], values: &[f64; 8], p: DVec3) -> Option<DVec3> {
    let j = jacobian(corners, p);
    if is_singular(&j) {
        return None;
    }
    let g = j.transpose().inverse() * parametric_gradient(values, p);
    g.is_finite().then_some(g)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn unit() -> [DVec3; 8] {
        CORNER_PARAMETERS.map(DVec3::from_array)
    }

    fn skewed() -> [DVec3; 8] {
        let m = DMat3::from_cols(
            DVec3::new(2.0, 0.3, -0.1),
            DVec3::new(0.4, 1.5, 0.2),
            DVec3::new(-0.2, 0.1, 0.8),
        );
        let mut c = unit().map(|p| m * p + DVec3::new(5.0, -3.0, 1.0));
        c[6] += DVec3::new(0.2, -0.1, 0.15); // make it genuinely trilinear
        c
    }

    #[test]
    fn weights_are_a_partition_of_unity_and_interpolate_corners() {
        for (i, c) in CORNER_PARAMETERS.iter().enumerate() {
            let n = weights(DVec3::from_array(*c));
            for (k, nk) in n.iter().enumerate() {
                assert_eq!(*nk, if k == i { 1.0 } else { 0.0 });
            }
        }
        let n = weights(DVec3::new(0.3, -0.2, 1.7));
        assert!((n.iter().sum::<f64>() - 1.0).abs() < 1e-15);
    }

    #[test]
    fn map_reproduces_corners_and_affine_maps() {
        let c = skewed();
        for (i, p) in CORNER_PARAMETERS.iter().enumerate() {
            assert!((map(&c, DVec3::from_array(*p)) - c[i]).length() < 1e-14);
        }
        // An affine cell maps affinely: x(p) = x0 + M p.
        let m = DMat3::from_cols(DVec3::X * 3.0, DVec3::new(1.0, 1.0, 0.0), DVec3::Z * 0.5);
        let aff = unit().map(|p| m * p + DVec3::ONE);
        let p = DVec3::new(0.2, 0.9, 0.4);
        assert!((map(&aff, p) - (m * p + DVec3::ONE)).length() < 1e-14);
        assert!((jacobian(&aff, p) - m).abs_diff_eq(DMat3::ZERO, 1e-14));
    }

    #[test]
    fn monomials_agree_with_the_shape_functions() {
        let rel = relative_corners(&skewed());
        let poly = Monomials::new(&rel);
        for p in [
            DVec3::ZERO,
            DVec3::ONE,
            DVec3::new(0.3, 0.9, 0.1),
            DVec3::new(-0.7, 1.6, 2.0),
        ] {
            let (x, j) = poly.map_and_jacobian(p);
            let (x0, j0) = relative_map_and_jacobian(&rel, p);
            assert!((x - x0).length() < 1e-13, "{p}");
            assert!((j - j0).abs_diff_eq(DMat3::ZERO, 1e-13), "{p}");
            assert!((poly.map(p) - relative_map(&rel, p)).length() < 1e-13);
        }
    }

    #[test]
    fn jacobian_matches_finite_differences() {
        let c = skewed();
        let p = DVec3::new(0.3, 0.6, 0.8);
        let j = jacobian(&c, p);
        let h = 1e-6;
        for (axis, col) in [DVec3::X, DVec3::Y, DVec3::Z]
            .into_iter()
            .zip([j.x_axis, j.y_axis, j.z_axis])
        {
            let fd = (map(&c, p + axis * h) - map(&c, p - axis * h)) / (2.0 * h);
            assert!((fd - col).length() < 1e-8, "{fd} vs {col}");
        }
        let dets = corner_jacobian_determinants(&c);
        for (i, cp) in CORNER_PARAMETERS.iter().enumerate() {
            let d = jacobian(&c, DVec3::from_array(*cp)).determinant();
            assert!((d - dets[i]).abs() < 1e-12 * d.abs().max(1.0));
        }
    }

    #[test]
    fn physical_gradient_of_a_linear_field_is_exact() {
        let c = skewed();
        let g = DVec3::new(0.7, -1.3, 2.1);
        let values = c.map(|x| g.dot(x) + 4.0);
        for p in [DVec3::splat(0.5), DVec3::new(0.1, 0.9, 0.3), DVec3::ZERO] {
            let grad = physical_gradient(&c, &values, p).expect("regular cell");
            assert!((grad - g).length() < 1e-12, "{grad}");
            let x = map(&c, p);
            assert!((interpolate(&values, p) - (g.dot(x) + 4.0)).abs() < 1e-12);
        }
    }

    #[test]
    fn gradient_is_none_on_a_collapsed_apex() {
        // A pyramid: the top face collapsed to one apex.
        let mut c = unit();
        for ck in c.iter_mut().skip(4) {
            *ck = DVec3::new(0.5, 0.5, 1.0);
        }
        let values = c.map(|x| x.z);
        assert!(physical_gradient(&c, &values, DVec3::new(0.5, 0.5, 1.0)).is_none());
        let g = physical_gradient(&c, &values, DVec3::new(0.5, 0.5, 0.5)).expect("regular");
        assert!((g - DVec3::Z).length() < 1e-12);
    }
}
