//! Cell geometry of (possibly collapsed) hexahedra in VTK vertex order, all in `f64`.
//!
//! - [`trilinear`]: the forward map `x(u, v, w)` on `[0, 1]³`, its Jacobian, interpolation of
//!   corner values and their parametric and physical gradients;
//! - [`inverse`]: the inverse map (damped Newton with a subdivision fallback, verified, with
//!   cost statistics);
//! - [`containment`]: point-in-cell tests with a tolerance that leaves no crack on shared faces;
//! - [`patch`]: bilinear patches (a cell's faces) and how many times a segment crosses one;
//! - [`bounds`]: Cartesian axis-aligned boxes and the exact box of a cell;
//! - [`cylindrical`]: a cylindrical frame about the machine axis, periodic θ intervals,
//!   sector bounds with their true volume and area, and conservative cylindrical bounds of a
//!   cell (with the split of cells that straddle the axis).

pub mod bounds;
pub mod containment;
pub mod cylindrical;
pub mod inverse;
pub mod patch;
pub mod pseudo_angle;
pub mod trilinear;

pub use bounds::{cell_bounds, Aabb};
pub use containment::{contains, locate_in_cell, locate_in_cell_with_stats, CONTAINMENT_TOLERANCE};
pub use cylindrical::{cylindrical_bounds, straddle_sectors, CylBounds, CylFrame, ThetaInterval};
pub use inverse::{invert, InverseFailure, InverseStats, Inversion, Solution};
