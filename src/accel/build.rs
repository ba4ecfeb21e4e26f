//! [`Accel`]: one of the four structures built over a mesh, with point location (the cell test
//! by the inverse trilinear map) and the statistics the talk reports.

use std::sync::OnceLock;
use std::time::Instant;

use glam::DVec3;

use super::bvh::{build_bvh, BvhParams, BvhStats, NodeShapes};
use super::grid::{build_grid, GridParams, GridStats};
use super::space::{
    cartesian_pieces, cylindrical_pieces, linear_boxes, seam_frame, Coordinates,
    DEFAULT_STRADDLE_SECTORS,
};
use super::{Counters, Structure, StructureKind};
use crate::axis::Axis;
use crate::error::show_vector;
use crate::geometry::containment::locate_in_cell;
use crate::geometry::cylindrical::CylFrame;
use crate::{Error, Mesh};

/// Build parameters of all four structures.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AccelParams {
    /// Densities of the grids.
    pub grid: GridParams,
    /// Leaf size and binning of the BVHs.
    pub bvh: BvhParams,
    /// Sectors a cell straddling the axis is cut into (cylindrical structures).
    pub straddle_sectors: usize,
}

impl Default for AccelParams {
    fn default() -> Self {
        AccelParams {
            grid: GridParams::default(),
            bvh: BvhParams::default(),
            straddle_sectors: DEFAULT_STRADDLE_SECTORS,
        }
    }
}

/// The figures of a built structure (`cylvol stats`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum StructureStats {
    /// A grid's.
    Grid(GridStats),
    /// A BVH's.
    Bvh(BvhStats),
}

impl StructureStats {
    /// Heap bytes held.
    pub fn bytes(&self) -> usize {
        match self {
            StructureStats::Grid(g) => g.bytes,
            StructureStats::Bvh(b) => b.bytes,
        }
    }

    /// References held (cell ids in grid cells; pieces in BVH leaves).
    pub fn references(&self) -> usize {
        match self {
            StructureStats::Grid(g) => g.references,
            StructureStats::Bvh(b) => b.references,
        }
    }

    /// Build time in seconds, cell bounds included.
    pub fn build_s(&self) -> f64 {
        match self {
            StructureStats::Grid(g) => g.build_s,
            StructureStats::Bvh(b) => b.build_s,
        }
    }
}

/// A structure built over a mesh.
#[derive(Clone, Debug)]
pub struct Accel {
    kind: StructureKind,
    axis: Axis,
    params: AccelParams,
    coordinates: Coordinates,
    structure: Structure,
    build_s: f64,
    /// How skipping rays test a cylindrical BVH's nodes, made by the first ray traversal that needs
    /// them.
    node_shapes: OnceLock<NodeShapes>,
    /// The hexahedra a look-up tests on average ([`Accel::lookup_tests`]), measured by the
    /// first render that needs it.
    lookup_tests: OnceLock<f64>,
}

/// Points a structure's average look-up cost is measured on ([`Accel::lookup_tests`]).
pub const LOOKUP_PROBES: usize = 1024;

impl Accel {
    /// Builds `kind` over `mesh`; cylindrical structures work about `axis` (Cartesian ones
    /// ignore it). Fails only for an unusable axis.
    pub fn build(
        mesh: &Mesh,
        kind: StructureKind,
        axis: &Axis,
        params: &AccelParams,
    ) -> Result<Accel, Error> {
        let started = Instant::now();
        let (coordinates, structure) = if kind.is_cylindrical() {
            let bad_axis = || {
                Error::Invalid(format!(
                    "cannot build {kind} about the axis through {} along {}",
                    show_vector(axis.origin.to_array()),
                    show_vector(axis.direction.to_array())
                ))
            };
            let frame = CylFrame::new(axis.origin, axis.direction).ok_or_else(bad_axis)?;
            let pieces = cylindrical_pieces(mesh, &frame, params.straddle_sectors);
            let (frame, pieces) = seam_frame(axis, pieces).ok_or_else(bad_axis)?;
            let coordinates = Coordinates::Cylindrical(frame);
            let structure = if kind.is_grid() {
                Structure::Grid(build_grid(
                    coordinates,
                    &linear_boxes(&pieces),
                    &params.grid,
                ))
            } else {
                Structure::CylBvh(build_bvh(&pieces, &params.bvh))
            };
            (coordinates, structure)
        } else {
            let pieces = cartesian_pieces(mesh);
            let structure = if kind.is_grid() {
                Structure::Grid(build_grid(Coordinates::Cartesian, &pieces, &params.grid))
            } else {
                Structure::CartBvh(build_bvh(&pieces, &params.bvh))
            };
            (Coordinates::Cartesian, structure)
        };
        Ok(Accel {
            kind,
            axis: *axis,
            params: *params,
            coordinates,
            structure,
            build_s: started.elapsed().as_secs_f64(),
            node_shapes: OnceLock::new(),
            lookup_tests: OnceLock::new(),
        })
    }

    /// Which structure this is.
    pub fn kind(&self) -> StructureKind {
        self.kind
    }

    /// The coordinates it works in (for cylindrical ones, the frame with its seam placed).
    pub fn coordinates(&self) -> Coordinates {
        self.coordinates
    }

    /// The structure itself.
    pub fn structure(&self) -> &Structure {
        &self.structure
    }

    /// The hexahedra a look-up through this structure tests on average (at least 1): over
    /// [`LOOKUP_PROBES`] points seeded in `mesh`'s cells (`mesh` must be the one it was built
    /// over), measured once, on the calling thread, and kept. The fast path marches this many
    /// times [`crate::render::RenderOptions::march_reach`] cells before it locates a sample far
    /// ahead through the structure: about 1 for the cylindrical BVH of the refined mixer, 1.4
    /// for its Cartesian BVH, 7–9 for its grids, 3.5–4 for the rotor's BVHs and 16–19 for its
    /// grids (`cylvol stats INPUT`, `hex/lk`).
    pub fn lookup_tests(&self, mesh: &Mesh) -> f64 {
        *self.lookup_tests.get_or_init(|| {
            if mesh.cell_count() == 0 {
                return 1.0;
            }
            let points = super::probe::points_in_cells(mesh, LOOKUP_PROBES, 0x5eed);
            super::probe::lookup_cost_sequential(self, mesh, &points)
                .hex_tests
                .max(1.0)
        })
    }

    /// How skipping rays test a cylindrical BVH's nodes (as boxes where those are nearly as
    /// tight, else as sectors with their arcs' sines and cosines; empty for the other
    /// structures). Made on the calling thread the first time they are asked for, unless
    /// [`Accel::make_node_shapes`] made them before; then kept with the structure (40
    /// bytes a node), so every later frame has them.
    pub fn node_shapes(&self) -> &NodeShapes {
        self.node_shapes.get_or_init(|| match &self.structure {
            Structure::CylBvh(b) => NodeShapes::new_sequential(b),
            _ => NodeShapes::default(),
        })
    }

    /// Makes the tests of [`Accel::node_shapes`] in parallel, if not made yet: for a
    /// caller about to start parallel work that needs them. It never waits on another thread
    /// (one making them at the same time makes them too, and one of the equal tables is
    /// kept), so it is safe from inside the thread pool as well.
    pub fn make_node_shapes(&self) {
        if self.node_shapes.get().is_none() {
            let tests = match &self.structure {
                Structure::CylBvh(b) => NodeShapes::new(b),
                _ => NodeShapes::default(),
            };
            let _ = self.node_shapes.set(tests);
        }
    }

    /// Its figures; `build_s` counts the whole build, cell bounds included.
    pub fn stats(&self) -> StructureStats {
        match &self.structure {
            Structure::Grid(g) => StructureStats::Grid(GridStats {
                build_s: self.build_s,
                ..g.stats()
            }),
            Structure::CartBvh(b) => StructureStats::Bvh(BvhStats {
                build_s: self.build_s,
                ..b.stats()
            }),
            Structure::CylBvh(b) => StructureStats::Bvh(BvhStats {
                build_s: self.build_s,
                ..b.stats()
            }),
        }
    }

    /// The cell containing `p` and its parametric coordinates there, or `None` when no cell
    /// holds it; the work goes into `counters`.
    pub fn locate(&self, mesh: &Mesh, p: DVec3, counters: &mut Counters) -> Option<(u32, DVec3)> {
        let mut tests = 0u64;
        let mut param = DVec3::ZERO;
        let accept = |c: u32| {
            tests += 1;
            match locate_in_cell(&mesh.cell_corners(c as usize), p, None) {
                Some(found) => {
                    param = found;
                    true
                }
                None => false,
            }
        };
        let cell = self
            .structure
            .find(self.coordinates.query(p), counters, accept);
        counters.hex_tests += tests;
        cell.map(|c| (c, param))
    }

    /// The cell containing `p`, if any, with no counting (for checks such as
    /// [`crate::mesh::topology::FaceNeighbours::check_boundary`]).
    pub fn cell_at(&self, mesh: &Mesh, p: DVec3) -> Option<u32> {
        self.locate(mesh, p, &mut Counters::default())
            .map(|(c, _)| c)
    }

    /// Panics with a message unless the structure is well formed for `mesh`: every piece of
    /// every cell is referenced wherever its bounds reach, and every node holds its children.
    pub fn assert_well_formed(&self, mesh: &Mesh) {
        match (&self.structure, self.coordinates) {
            (Structure::Grid(g), Coordinates::Cartesian) => {
                g.assert_well_formed(&cartesian_pieces(mesh))
            }
            (Structure::CartBvh(b), _) => b.assert_well_formed(&cartesian_pieces(mesh)),
            (structure, _) => {
                let frame = CylFrame::new(self.axis.origin, self.axis.direction)
                    .expect("the axis was usable at build time");
                let pieces = cylindrical_pieces(mesh, &frame, self.params.straddle_sectors);
                let (_, pieces) =
                    seam_frame(&self.axis, pieces).expect("the axis was usable at build time");
                match structure {
                    Structure::Grid(g) => g.assert_well_formed(&linear_boxes(&pieces)),
                    Structure::CylBvh(b) => b.assert_well_formed(&pieces),
                    Structure::CartBvh(_) => unreachable!("handled above"),
                }
            }
        }
    }
}
