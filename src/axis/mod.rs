//! Detection of the axis a machine turns about.

use glam::DVec3;

use crate::Mesh;

/// A line: the machine axis.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Axis {
    /// A point on the axis.
    pub origin: DVec3,
    /// Unit direction.
    pub direction: DVec3,
}

/// Detects the axis the mesh turns about.
pub fn detect(mesh: &Mesh) -> Axis {
    let b = mesh.bounds();
    Axis {
        origin: DVec3::new(b[0] + b[1], b[2] + b[3], b[4] + b[5]) * 0.5,
        direction: DVec3::Z,
    }
}
