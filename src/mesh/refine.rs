//! Uniform refinement of a hexahedral mesh: every hexahedron cut into `n × n × n` children
//! along its parametric coordinates ([`Mesh::refined`]).
//!
//! A child is the parent's trilinear map restricted to a sub-box of `[0, 1]³`, so it is a
//! trilinear cell itself and the children tile their parent exactly. The point arrays are
//! interpolated the same way (linearly along an edge, bilinearly across a face, trilinearly
//! inside), so a field that is trilinear in the parent is reproduced exactly: the refined
//! mesh is the same volume, with `n³` times the cells. Cell arrays are copied to the children.
//!
//! The refined mesh is conforming wherever the original is: a point on an edge or a face is
//! made once, from that edge's or face's corners taken in an order that does not depend on
//! the cell it is reached from, so neighbouring children share its index and its coordinates
//! bit for bit.

use std::collections::HashMap;

use glam::DVec3;

use super::{CellKind, DataArray, Mesh, MeshParts};
use crate::error::Error;
use crate::geometry::trilinear::{weights, CORNER_PARAMETERS};

/// The largest number of cuts per edge [`Mesh::refined`] accepts.
pub const MAX_REFINEMENT: u32 = 16;

/// About the bytes [`Mesh::refined`] holds at its peak for `children` cells: per child, its
/// corner ids and kind, and about one point (coordinates, the weights it is made from, and a
/// value per component of every point array), plus the copied cell arrays.
///
/// ```
/// use cylvol::datasets::{generate, Dataset};
/// use cylvol::mesh::refined_bytes;
/// let mesh = generate(Dataset::PumpRotor, 2_000).unwrap();
/// let children = mesh.cell_count() as u64 * 8;
/// assert!(refined_bytes(&mesh, children) > children * 160);
/// ```
pub fn refined_bytes(mesh: &Mesh, children: u64) -> u64 {
    let components = |arrays: &[DataArray]| arrays.iter().map(|a| a.components as u64).sum::<u64>();
    let value = std::mem::size_of::<f64>() as u64;
    let per_child = std::mem::size_of::<[u32; 8]>() as u64
        + std::mem::size_of::<CellKind>() as u64
        + std::mem::size_of::<DVec3>() as u64
        + std::mem::size_of::<Blend>() as u64
        + value * (components(&mesh.point_data) + components(&mesh.cell_data));
    children.saturating_mul(per_child)
}

/// The machine's physical memory in bytes (`MemTotal` of `/proc/meminfo`), where the system
/// says it (`None` elsewhere).
pub fn physical_memory() -> Option<u64> {
    let info = std::fs::read_to_string("/proc/meminfo").ok()?;
    let line = info.lines().find(|l| l.starts_with("MemTotal:"))?;
    let kib: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    kib.checked_mul(1024)
}

/// Where a new point lies: a weighted sum of original points (weights summing to one).
#[derive(Clone, Copy, Debug)]
struct Blend {
    ids: [u32; 8],
    weights: [f64; 8],
    len: usize,
}

impl Blend {
    fn of(pairs: &[(u32, f64)]) -> Blend {
        let mut b = Blend {
            ids: [0; 8],
            weights: [0.0; 8],
            len: pairs.len(),
        };
        for (k, &(id, w)) in pairs.iter().enumerate() {
            b.ids[k] = id;
            b.weights[k] = w;
        }
        b
    }

    fn point(&self, points: &[DVec3]) -> DVec3 {
        (0..self.len).fold(DVec3::ZERO, |acc, k| {
            acc + points[self.ids[k] as usize] * self.weights[k]
        })
    }

    fn value(&self, values: &[f64], components: usize, c: usize) -> f64 {
        (0..self.len)
            .map(|k| values[self.ids[k] as usize * components + c] * self.weights[k])
            .sum()
    }
}

/// A point of the refined mesh by what it lies on, in a form independent of the cell it is
/// reached from.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
enum Key {
    /// An original point.
    Corner(u32),
    /// Step `k` (of `n`) along the edge from its smaller point id to its larger.
    Edge(u32, u32, u32),
    /// Node `(s, t)` of the face's `n × n` grid, in the face's canonical frame: corners
    /// listed from the smallest id, towards its smaller-id neighbour first.
    Face([u32; 4], u32, u32),
}

/// The eight symmetries of the square `[0, n]²` (rotations and reflections).
fn square_symmetry(k: usize, n: u32, s: u32, t: u32) -> (u32, u32) {
    let (s, t) = if k >= 4 { (t, s) } else { (s, t) };
    match k % 4 {
        0 => (s, t),
        1 => (n - t, s),
        2 => (n - s, n - t),
        _ => (t, n - s),
    }
}

/// The canonical key and blend of node `(s, t)` (both in `1..n`) of the face whose corners,
/// at `(0, 0)`, `(n, 0)`, `(n, n)` and `(0, n)` of the face's grid, are `q`.
fn face_node(q: [u32; 4], n: u32, s: u32, t: u32) -> (Key, Blend) {
    let at = |s: u32, t: u32| -> usize {
        match (s == 0, t == 0) {
            (true, true) => 0,
            (false, true) => 1,
            (false, false) => 2,
            (true, false) => 3,
        }
    };
    let corners = [(0, 0), (n, 0), (n, n), (0, n)];
    let mut best: Option<([u32; 4], u32, u32)> = None;
    for k in 0..8 {
        let mut moved = [0u32; 4];
        for (c, &(cs, ct)) in corners.iter().enumerate() {
            let (ms, mt) = square_symmetry(k, n, cs, ct);
            moved[at(ms, mt)] = q[c];
        }
        let (ms, mt) = square_symmetry(k, n, s, t);
        if best.map_or(true, |(b, _, _)| moved < b) {
            best = Some((moved, ms, mt));
        }
    }
    let (c, s, t) = best.expect("eight symmetries");
    let (a, b) = (s as f64 / n as f64, t as f64 / n as f64);
    let blend = Blend::of(&[
        (c[0], (1.0 - a) * (1.0 - b)),
        (c[1], a * (1.0 - b)),
        (c[2], a * b),
        (c[3], (1.0 - a) * b),
    ]);
    (Key::Face(c, s, t), blend)
}

/// Where node `g` (each coordinate in `0..=n`) of a hexahedron's `n × n × n` grid lies, by the
/// hexahedron's slots (0–7, VTK order): the same for every cell, so worked out once.
#[derive(Clone, Copy, Debug)]
enum Node {
    /// At the corner in this slot.
    Corner(usize),
    /// Step `k` (of `n`) along the edge from slot `lo` to slot `hi`.
    Edge { lo: usize, hi: usize, k: u32 },
    /// Node `(s, t)` of the face whose corners, at `(0, 0)`, `(n, 0)`, `(n, n)` and `(0, n)` of
    /// its grid, are in slots `q`.
    Face { q: [usize; 4], s: u32, t: u32 },
    /// Inside the cell, with these trilinear weights of the eight corners.
    Interior([f64; 8]),
}

impl Node {
    fn at(n: u32, g: [u32; 3]) -> Node {
        let on = g.map(|x| x == 0 || x == n);
        // The slot of the corner at parametric corner (u, v, w), each 0 or 1.
        let slot = |c: [u32; 3]| -> usize {
            CORNER_PARAMETERS
                .iter()
                .position(|p| p.map(|x| x as u32) == c)
                .expect("a corner of the unit cube")
        };
        let unit = |x: u32| u32::from(x == n);
        match on.iter().filter(|&&b| b).count() {
            3 => Node::Corner(slot(g.map(unit))),
            2 => {
                let free = on.iter().position(|&b| !b).expect("one free axis");
                let mut lo = g.map(unit);
                let mut hi = lo;
                lo[free] = 0;
                hi[free] = 1;
                Node::Edge {
                    lo: slot(lo),
                    hi: slot(hi),
                    k: g[free],
                }
            }
            1 => {
                let fixed = on.iter().position(|&b| b).expect("one fixed axis");
                let (sa, ta) = match fixed {
                    0 => (1, 2),
                    1 => (0, 2),
                    _ => (0, 1),
                };
                let at = |s: u32, t: u32| {
                    let mut c = [0u32; 3];
                    c[fixed] = unit(g[fixed]);
                    c[sa] = s;
                    c[ta] = t;
                    slot(c)
                };
                Node::Face {
                    q: [at(0, 0), at(1, 0), at(1, 1), at(0, 1)],
                    s: g[sa],
                    t: g[ta],
                }
            }
            _ => Node::Interior(weights(
                DVec3::new(g[0] as f64, g[1] as f64, g[2] as f64) / n as f64,
            )),
        }
    }

    /// The node in the hexahedron with point ids `ids`: its key, or `None` inside the cell
    /// (which no other cell reaches), and its blend.
    fn in_cell(&self, ids: &[u32; 8], n: u32) -> (Option<Key>, Blend) {
        match *self {
            Node::Corner(slot) => {
                let id = ids[slot];
                (Some(Key::Corner(id)), Blend::of(&[(id, 1.0)]))
            }
            Node::Edge { lo, hi, k } => {
                let (a, b) = (ids[lo], ids[hi]);
                let (a, b, k) = if a <= b { (a, b, k) } else { (b, a, n - k) };
                let f = k as f64 / n as f64;
                (Some(Key::Edge(a, b, k)), Blend::of(&[(a, 1.0 - f), (b, f)]))
            }
            Node::Face { q, s, t } => {
                let (key, blend) = face_node(q.map(|k| ids[k]), n, s, t);
                (Some(key), blend)
            }
            Node::Interior(weights) => (
                None,
                Blend {
                    ids: *ids,
                    weights,
                    len: 8,
                },
            ),
        }
    }
}

impl Mesh {
    /// This mesh with every hexahedron cut into `n × n × n` children (see the module
    /// documentation of `mesh::refine`): `n³` times the cells, the same geometry, the point arrays
    /// interpolated and the cell arrays copied, the same active scalar. `n = 1` gives a copy.
    ///
    /// Errors: `n` outside `1..=`[`MAX_REFINEMENT`], a cell that is not a hexahedron
    /// (wedges, pyramids and tetrahedra would need children of their own kinds), a result
    /// with more than `u32::MAX` points or cells, or one that needs more memory than the
    /// machine has ([`refined_bytes`] against the physical memory, where the system says it;
    /// the cell and point arrays are reserved up front, so an allocator that refuses them
    /// gives an error too, never an abort).
    ///
    /// ```
    /// use cylvol::datasets::{generate, Dataset};
    /// let mesh = generate(Dataset::PumpRotor, 2_000).unwrap();
    /// let fine = mesh.refined(2).unwrap();
    /// assert_eq!(fine.cell_count(), 8 * mesh.cell_count());
    /// assert_eq!(fine.active_array().unwrap().name, mesh.active_array().unwrap().name);
    /// ```
    pub fn refined(&self, n: u32) -> Result<Mesh, Error> {
        if !(1..=MAX_REFINEMENT).contains(&n) {
            return Err(Error::Invalid(format!(
                "refinement {n} is not in 1..={MAX_REFINEMENT}"
            )));
        }
        if let Some(c) = self.kinds.iter().position(|&k| k != CellKind::Hexahedron) {
            return Err(Error::Invalid(format!(
                "cell {c} is a {}: only hexahedral meshes can be refined",
                self.kinds[c].name()
            )));
        }
        let children = self.cell_count() as u64 * u64::from(n).pow(3);
        if children > u64::from(u32::MAX) {
            return Err(Error::Invalid(format!(
                "refining {} cells by {n} makes {children} cells, more than 2^32 - 1",
                self.cell_count()
            )));
        }
        let needed = refined_bytes(self, children);
        if let Some(memory) = physical_memory() {
            if needed > memory {
                return Err(Error::Invalid(format!(
                    "refining {} cells by {n} makes {children} cells, which need about {:.1} GB; \
                     this machine has {:.1} GB of memory",
                    self.cell_count(),
                    needed as f64 / 1e9,
                    memory as f64 / 1e9
                )));
            }
        }
        let refused = |what: &str| {
            Error::Invalid(format!(
                "refining {} cells by {n} makes {children} cells: memory for their {what} \
                 was refused (about {:.1} GB in all)",
                self.cell_count(),
                needed as f64 / 1e9
            ))
        };
        let side = n as usize + 1;
        let mut index: HashMap<Key, u32> = HashMap::new();
        // About one new point per child.
        let mut blends: Vec<Blend> = Vec::new();
        blends
            .try_reserve_exact(children as usize)
            .map_err(|_| refused("points"))?;
        let mut cells: Vec<[u32; 8]> = Vec::new();
        cells
            .try_reserve_exact(children as usize)
            .map_err(|_| refused("cells"))?;
        let nodes: Vec<Node> = (0..side * side * side)
            .map(|slot| {
                let g = [
                    (slot % side) as u32,
                    ((slot / side) % side) as u32,
                    (slot / (side * side)) as u32,
                ];
                Node::at(n, g)
            })
            .collect();
        let mut grid = vec![0u32; nodes.len()];
        for ids in &self.cells {
            for (node, spot) in nodes.iter().zip(grid.iter_mut()) {
                let (key, blend) = node.in_cell(ids, n);
                let next = u32::try_from(blends.len()).map_err(|_| {
                    Error::Invalid("the refined mesh would have more than 2^32 points".into())
                })?;
                *spot = match key {
                    Some(key) => *index.entry(key).or_insert_with(|| {
                        blends.push(blend);
                        next
                    }),
                    None => {
                        blends.push(blend);
                        next
                    }
                };
            }
            let at = |g: [usize; 3]| grid[g[0] + side * (g[1] + side * g[2])];
            for k in 0..n as usize {
                for j in 0..n as usize {
                    for i in 0..n as usize {
                        cells.push(CORNER_PARAMETERS.map(|p| {
                            at([i + p[0] as usize, j + p[1] as usize, k + p[2] as usize])
                        }));
                    }
                }
            }
        }
        let points: Vec<DVec3> = blends.iter().map(|b| b.point(&self.points)).collect();
        let point_data = self
            .point_data
            .iter()
            .map(|a| DataArray {
                name: a.name.clone(),
                components: a.components,
                values: blends
                    .iter()
                    .flat_map(|b| {
                        (0..a.components).map(move |c| b.value(&a.values, a.components, c))
                    })
                    .collect(),
            })
            .collect();
        let per_parent = (n as usize).pow(3);
        let cell_data = self
            .cell_data
            .iter()
            .map(|a| DataArray {
                name: a.name.clone(),
                components: a.components,
                values: a
                    .values
                    .chunks(a.components.max(1))
                    .flat_map(|tuple| std::iter::repeat(tuple).take(per_parent).flatten().copied())
                    .collect(),
            })
            .collect();
        let mut mesh = Mesh::from_parts(MeshParts {
            points,
            kinds: vec![CellKind::Hexahedron; cells.len()],
            cells,
            point_data,
            cell_data,
        })?;
        mesh.active = self.active.clone();
        Ok(mesh)
    }
}
