//! What the fast path walks: the mesh's face neighbours ([`FaceNeighbors`]) and its boundary
//! surface ([`BoundarySurface`]), built once per mesh and structure by [`face_neighbours`].

use std::ops::Deref;

use super::raycast::Neighbours;
use super::surface::BoundarySurface;
use crate::accel::Accel;
use crate::mesh::topology::FaceNeighbors;
use crate::Mesh;

/// Face neighbours with the boundary surface they bound (dereferences to the neighbours).
#[derive(Clone, Debug)]
pub struct Topology {
    faces: FaceNeighbors,
    surface: BoundarySurface,
}

impl Topology {
    /// The boundary surface of `faces` over `mesh`, kept with them.
    pub fn new(mesh: &Mesh, faces: FaceNeighbors) -> Topology {
        let surface = BoundarySurface::new(mesh, &faces);
        Topology { faces, surface }
    }

    /// Checks the faces without a neighbour against `accel` (built over `mesh`), as
    /// [`face_neighbours`] does ([`FaceNeighbors::check_boundary_near`], the probes near no
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

    /// The face neighbours.
    pub fn faces(&self) -> &FaceNeighbors {
        &self.faces
    }

    /// The boundary surface.
    pub fn surface(&self) -> &BoundarySurface {
        &self.surface
    }
}

impl Deref for Topology {
    type Target = FaceNeighbors;
    fn deref(&self) -> &FaceNeighbors {
        &self.faces
    }
}

impl Neighbours for Topology {
    fn neighbours(&self, cell: u32) -> [u32; 6] {
        self.faces.neighbors(cell)
    }

    fn complete(&self) -> bool {
        self.faces.is_closed()
    }

    fn surface(&self) -> Option<&BoundarySurface> {
        Some(&self.surface)
    }

    #[inline]
    fn prefetch(&self, cell: u32) {
        if let Some(row) = self.faces.raw().get(cell as usize * 6) {
            crate::accel::prefetch(row);
        }
    }
}

/// The face neighbours the fast path should walk, with their boundary surface: seams of
/// coincident points welded ([`FaceNeighbors::build_with_tolerance`] with
/// [`FaceNeighbors::seam_tolerance`]), the faces left without a neighbour checked against
/// `accel` ([`FaceNeighbors::check_boundary_near`], the probes near no other such face passed
/// by the surface) so that the boundary searches trust them only when they really bound the
/// mesh, and those faces in a [`BoundarySurface`] for skipping the space outside the mesh.
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
    let faces = FaceNeighbors::build_with_tolerance(mesh, FaceNeighbors::seam_tolerance(mesh));
    Topology::new(mesh, faces)
}
