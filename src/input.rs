//! Resolution of a command-line `INPUT`: a mesh file or a synthetic dataset `NAME[:CELLS]`.
