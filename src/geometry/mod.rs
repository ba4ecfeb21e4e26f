//! Cell geometry: the trilinear map of a (possibly collapsed) hexahedron and its Jacobian.

pub mod trilinear;
