//! The trilinear map of a hexahedron in VTK vertex order, `x(u, v, w)` for `(u, v, w) ∈ [0, 1]³`,
//! and its Jacobian.

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

/// The determinant of the trilinear map's Jacobian at each corner: the triple product of the
/// three edges leaving that corner in the `+u`, `+v`, `+w` sense. Positive for a well-formed
/// cell in VTK order; zero at the collapsed corners of wedges, pyramids and tetrahedra.
pub fn corner_jacobian_determinants(x: &[DVec3; 8]) -> [f64; 8] {
    // For corner (i, j, k) the derivative along u is x(1, j, k) − x(0, j, k), etc.
    let at = |u: usize, v: usize, w: usize| x[index(u, v, w)];
    let mut dets = [0.0; 8];
    for (c, p) in CORNER_PARAMETERS.iter().enumerate() {
        let (u, v, w) = (p[0] as usize, p[1] as usize, p[2] as usize);
        let du = at(1, v, w) - at(0, v, w);
        let dv = at(u, 1, w) - at(u, 0, w);
        let dw = at(u, v, 1) - at(u, v, 0);
        dets[c] = DMat3::from_cols(du, dv, dw).determinant();
    }
    dets
}

/// VTK hexahedron vertex index of the corner with parametric coordinates `(u, v, w)` ∈ {0, 1}³.
pub fn index(u: usize, v: usize, w: usize) -> usize {
    const LUT: [[usize; 2]; 2] = [[0, 3], [1, 2]];
    LUT[u][v] + 4 * w
}
