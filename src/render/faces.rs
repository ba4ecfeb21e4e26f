//! The mesh's faces as the fast path walks them ([`Topology`]): the face neighbours
//! ([`FaceNeighbours`]) and the boundary surface (the faces without a neighbour, in a BVH),
//! built once per mesh and structure by [`face_neighbours`].

use std::ops::Deref;

use super::boundary::surface::BoundarySurface;
use crate::accel::Accel;
use crate::axis::periodic::Periodicity;
use crate::mesh::topology::FaceNeighbours;
use crate::Mesh;

/// Face neighbours with the boundary surface they bound (dereferences to the neighbours):
/// what [`crate::render::Renderer::with_topology`] walks.
#[derive(Clone, Debug)]
pub struct Topology {
    faces: FaceNeighbours,
    surface: BoundarySurface,
}

impl Topology {
    /// The boundary surface of `faces` over `mesh`, kept with them.
    pub fn new(mesh: &Mesh, faces: FaceNeighbours) -> Topology {
        let surface = BoundarySurface::new(mesh, &faces);
        Topology { faces, surface }
    }

    /// Checks the faces without a neighbour against `accel` (built over `mesh`), as
    /// [`face_neighbours`] does ([`FaceNeighbours::check_boundary_near`], the probes near no
    /// other such face passed by the surface), so that the boundary searches trust them only
    /// when they really bound the mesh. Returns the number of hanging faces.
    ///
    /// The neighbours and their surface need no structure: [`Topology::new`] can run while
    /// the structure is built, and this after.
    pub fn check_boundary(&mut self, mesh: &Mesh, accel: &Accel) -> usize {
        let surface = &self.surface;
        self.faces.check_boundary_near(
            mesh,
            |c, f, probes, r| surface.other_faces_near(mesh, c, f, probes, r),
            |p| accel.cell_at(mesh, p),
        )
    }

    /// The topology of the wheel that copies of this sector make about `periodicity`'s axis:
    /// the sector's start and end sides, where their faces land on each other, are joined
    /// ([`FaceNeighbours::join`]) and leave the boundary surface, so that rays cross from one
    /// copy into the next without meeting a boundary there. Returns the pairs joined too.
    pub fn with_periodic_sides(self, mesh: &Mesh, periodicity: &Periodicity) -> (Topology, usize) {
        let pairs = crate::axis::periodic::side_pairs(mesh, &self.faces, periodicity);
        let mut faces = self.faces;
        let joined = faces.join(&pairs);
        if joined == 0 {
            return (
                Topology {
                    faces,
                    surface: self.surface,
                },
                0,
            );
        }
        (Topology::new(mesh, faces), joined)
    }

    /// The face neighbours.
    pub fn faces(&self) -> &FaceNeighbours {
        &self.faces
    }

    /// The boundary surface.
    pub fn surface(&self) -> &BoundarySurface {
        &self.surface
    }
}

impl Deref for Topology {
    type Target = FaceNeighbours;
    fn deref(&self) -> &FaceNeighbours {
        &self.faces
    }
}

/// The face neighbours the fast path should walk, with their boundary surface: seams of
/// coincident points welded ([`FaceNeighbours::build_with_tolerance`] with
/// [`FaceNeighbours::seam_tolerance`]), the faces left without a neighbour checked against
/// `accel` ([`FaceNeighbours::check_boundary_near`], the probes near no other such face passed
/// by the surface) so that the boundary searches trust them only when they really bound the
/// mesh, and those faces in a boundary surface for skipping the space outside the mesh
/// (give it to the renderer with [`crate::render::Renderer::with_topology`]).
pub fn face_neighbours(mesh: &Mesh, accel: &Accel) -> Topology {
    // The surface of the faces without a neighbour is made before the check: probes with no
    // other such face near them are outside without a structure look-up.
    let mut topology = unchecked_neighbours(mesh);
    topology.check_boundary(mesh, accel);
    topology
}

/// The part of [`face_neighbours`] that needs no structure: the neighbours (seams welded)
/// and their boundary surface, the boundary not checked yet ([`Topology::check_boundary`]).
pub fn unchecked_neighbours(mesh: &Mesh) -> Topology {
    let faces = FaceNeighbours::build_with_tolerance(mesh, FaceNeighbours::seam_tolerance(mesh));
    Topology::new(mesh, faces)
}

#[cfg(test)]
mod tests {
    use std::sync::atomic::{AtomicUsize, Ordering};

    use glam::DVec3;

    use super::*;
    use crate::geometry::containment::contains;
    use crate::{CellKind, MeshParts};

    /// The cell holding `p`, by testing every cell.
    fn brute_force_cell(mesh: &Mesh, p: DVec3) -> Option<u32> {
        (0..mesh.cell_count())
            .find(|&c| contains(&mesh.cell_corners(c), p))
            .map(|c| c as u32)
    }

    /// Two unit cubes stacked in z, the upper one either conforming (sharing the lower one's
    /// top face) or split into two wedges along the diagonal of that face, or shifted by half a
    /// cell in x (a face against two half faces, as at a non-conforming interface).
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

    /// The boundary surface's filter in front of the check changes no count: on the
    /// conforming stack, the hex against two wedges and the half-shifted stack, a check
    /// filtered by the surface finds the hanging faces the unfiltered brute-force check finds;
    /// the filter passes the probes near another open face and no others.
    #[test]
    fn boundary_check_filtered_by_the_surface_finds_the_same_faces() {
        for (kind, expected) in [("hexahedron", 0), ("wedges", 3), ("shifted", 2)] {
            let mesh = stacked(kind);
            let mut plain =
                FaceNeighbours::build_with_tolerance(&mesh, FaceNeighbours::seam_tolerance(&mesh));
            assert_eq!(
                plain.check_boundary(&mesh, |p| brute_force_cell(&mesh, p)),
                expected,
                "{kind}"
            );
            let mut filtered =
                FaceNeighbours::build_with_tolerance(&mesh, FaceNeighbours::seam_tolerance(&mesh));
            let surface = BoundarySurface::new(&mesh, &filtered);
            let (asked, passed) = (AtomicUsize::new(0), AtomicUsize::new(0));
            let hanging = filtered.check_boundary_near(
                &mesh,
                |c, f, probes, r| {
                    let near = surface.other_faces_near(&mesh, c, f, probes, r);
                    asked.fetch_add(probes.len(), Ordering::Relaxed);
                    passed.fetch_add(near.iter().filter(|&&x| x).count(), Ordering::Relaxed);
                    near
                },
                |p| brute_force_cell(&mesh, p),
            );
            assert_eq!(hanging, expected, "{kind}");
            let (asked, passed) = (asked.into_inner(), passed.into_inner());
            assert!(asked > 0, "{kind}");
            if expected == 0 {
                // Two stacked cubes: every probe is away from the other open faces.
                assert_eq!(passed, 0, "{kind}: {passed} of {asked}");
            } else {
                assert!(passed > 0 && passed < asked, "{kind}: {passed} of {asked}");
            }
        }
    }
}
