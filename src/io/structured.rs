//! Hexahedra of a structured (i, j, k) grid, shared by the legacy `STRUCTURED_GRID` and the
//! PLOT3D readers.

use glam::DVec3;

use crate::geometry::trilinear::corner_jacobian_determinants;

/// The eight point ids of the structured cell `(i, j, k)` in VTK hexahedron order, given the id
/// of a grid point `(i, j, k)`.
///
/// ```
/// use cylvol::io::structured::cell_ids;
/// let id = |i: usize, j: usize, k: usize| (i + 2 * (j + 2 * k)) as u32;
/// assert_eq!(cell_ids(0, 0, 0, id), [0, 1, 3, 2, 4, 5, 7, 6]);
/// ```
#[inline]
pub fn cell_ids(i: usize, j: usize, k: usize, id: impl Fn(usize, usize, usize) -> u32) -> [u32; 8] {
    [
        id(i, j, k),
        id(i + 1, j, k),
        id(i + 1, j + 1, k),
        id(i, j + 1, k),
        id(i, j, k + 1),
        id(i + 1, j, k + 1),
        id(i + 1, j + 1, k + 1),
        id(i, j + 1, k + 1),
    ]
}

/// The `(ni−1)(nj−1)(nk−1)` hexahedra of a structured grid whose points are stored i fastest,
/// then j, then k. Cells are oriented so that most have a positive Jacobian: a left-handed grid
/// (as PLOT3D files often are) gets its cells' vertex order mirrored in i, so the mesh it makes
/// passes [`crate::Mesh::from_parts`]. Dimensions of 1 give no cells.
///
/// ```
/// use cylvol::io::structured::hexahedra;
/// let pts: Vec<glam::DVec3> = (0..8)
///     .map(|n| glam::DVec3::new((n % 2) as f64, ((n / 2) % 2) as f64, (n / 4) as f64))
///     .collect();
/// assert_eq!(hexahedra([2, 2, 2], &pts), vec![[0, 1, 3, 2, 4, 5, 7, 6]]);
/// ```
pub fn hexahedra(dims: [usize; 3], points: &[DVec3]) -> Vec<[u32; 8]> {
    let [ni, nj, nk] = dims;
    if ni < 2 || nj < 2 || nk < 2 || points.len() < ni * nj * nk {
        return Vec::new();
    }
    let id = |i: usize, j: usize, k: usize| (i + ni * (j + nj * k)) as u32;
    let mut cells = Vec::with_capacity((ni - 1) * (nj - 1) * (nk - 1));
    for k in 0..nk - 1 {
        for j in 0..nj - 1 {
            for i in 0..ni - 1 {
                cells.push(cell_ids(i, j, k, id));
            }
        }
    }
    // Orientation: the sum of corner Jacobians over all cells says the grid's handedness.
    let signed: f64 = cells
        .iter()
        .map(|c| {
            corner_jacobian_determinants(&c.map(|i| points[i as usize]))
                .iter()
                .sum::<f64>()
        })
        .sum();
    if signed < 0.0 {
        for c in &mut cells {
            *c = [c[1], c[0], c[3], c[2], c[5], c[4], c[7], c[6]];
        }
    }
    cells
}
