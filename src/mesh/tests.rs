use glam::DVec3;

use super::*;

fn unit_cube() -> MeshParts {
    let points = (0..8)
        .map(|i| {
            let p = crate::geometry::trilinear::CORNER_PARAMETERS[i];
            DVec3::new(p[0], p[1], p[2])
        })
        .collect();
    MeshParts {
        points,
        cells: vec![[0, 1, 2, 3, 4, 5, 6, 7]],
        kinds: vec![CellKind::Hexahedron],
        point_data: vec![DataArray::scalar("s", (0..8).map(f64::from).collect())],
        cell_data: vec![],
    }
}

#[test]
fn valid_cube_loads_with_active_scalar() {
    let m = Mesh::from_parts(unit_cube()).unwrap();
    assert_eq!(m.cell_count(), 1);
    assert_eq!(m.scalar_range(), Some([0.0, 7.0]));
    assert_eq!(m.bounds(), [0.0, 1.0, 0.0, 1.0, 0.0, 1.0]);
}

#[test]
fn empty_mesh_is_an_error() {
    let e = Mesh::from_parts(MeshParts::default()).unwrap_err();
    assert_eq!(
        e,
        MeshError::Empty {
            points: 0,
            cells: 0
        }
    );
}

#[test]
fn non_finite_point_is_an_error() {
    let mut p = unit_cube();
    p.points[3].y = f64::NAN;
    assert!(matches!(
        Mesh::from_parts(p).unwrap_err(),
        MeshError::NonFinitePoint { index: 3, .. }
    ));
    let mut p = unit_cube();
    p.points[5].x = f64::INFINITY;
    assert!(matches!(
        Mesh::from_parts(p).unwrap_err(),
        MeshError::NonFinitePoint { index: 5, .. }
    ));
}

#[test]
fn out_of_range_index_is_an_error() {
    let mut p = unit_cube();
    p.cells[0][6] = 8;
    assert!(matches!(
        Mesh::from_parts(p).unwrap_err(),
        MeshError::IndexOutOfRange {
            cell: 0,
            index: 8,
            points: 8
        }
    ));
}

/// Among many cells, the first one with an id out of range is named, with its id.
#[test]
fn the_first_out_of_range_index_of_many_is_named() {
    let mesh = crate::datasets::generate(crate::datasets::Dataset::PumpInlet, 2000).unwrap();
    let n = mesh.point_count();
    let mut p = mesh.into_parts();
    p.cells[1500][0] = u32::MAX;
    p.cells[700][5] = n as u32 + 3;
    p.cells[701][2] = n as u32;
    assert_eq!(
        Mesh::from_parts(p).unwrap_err(),
        MeshError::IndexOutOfRange {
            cell: 700,
            index: n as i64 + 3,
            points: n
        }
    );
}

#[test]
fn wrong_array_length_is_an_error() {
    let mut p = unit_cube();
    p.point_data[0].values.pop();
    assert!(matches!(
        Mesh::from_parts(p).unwrap_err(),
        MeshError::ArrayLength {
            expected: 8,
            got: 7,
            ..
        }
    ));
}

/// NaN and infinite values are kept and listed with their counts; the default scalar is an
/// array without them; drawing one that has them is refused, naming it, the count and the
/// first, whatever component is drawn, while a component without them draws.
#[test]
fn non_finite_values_are_kept_listed_and_refused_only_when_drawn() {
    let mut p = unit_cube();
    let mut t = vec![1.0; 8];
    t[2] = f64::NAN;
    t[6] = f64::INFINITY;
    let mut u: Vec<f64> = (0..24).map(f64::from).collect();
    u[3 * 5 + 2] = f64::NEG_INFINITY;
    p.point_data = vec![
        DataArray::scalar("T", t.clone()),
        DataArray::vector("U", u),
        DataArray::scalar("p", (0..8).map(f64::from).collect()),
    ];
    p.cell_data = vec![DataArray::scalar("c", vec![f64::NAN])];
    let mut mesh = Mesh::from_parts(p).unwrap();
    assert_eq!(mesh.point_data()[0].values[2].to_bits(), f64::NAN.to_bits());
    let listed: Vec<(Association, String, usize, usize)> = mesh
        .non_finite_arrays()
        .into_iter()
        .map(|a| (a.association, a.name, a.count, a.values))
        .collect();
    let want = [
        (Association::Point, "T", 2, 8),
        (Association::Point, "U", 1, 24),
        (Association::Cell, "c", 1, 1),
    ]
    .map(|(a, n, c, v)| (a, n.to_string(), c, v));
    assert_eq!(listed, want);
    assert_eq!(mesh.active_array().unwrap().name, "p");
    assert!(mesh.drawn_scalars().is_ok());
    mesh.set_active_scalar("T").unwrap();
    assert_eq!(
        mesh.scalar_range(),
        Some([1.0, 1.0]),
        "the finite values' range"
    );
    let refusal = mesh.drawn_scalars().unwrap_err().to_string();
    assert_eq!(
        refusal,
        "point array 'T' cannot be drawn: 2 of its 8 values are NaN or infinite (the first, \
         NaN, at point 2); draw another array"
    );
    for (name, refused) in [
        ("U", true),
        ("U[2]", true),
        ("U[1]", false),
        ("cell:c", true),
    ] {
        mesh.set_active_scalar(name).unwrap();
        assert_eq!(mesh.drawn_scalars().is_err(), refused, "{name}");
    }
    mesh.set_active_scalar("U[2]").unwrap();
    let refusal = mesh.drawn_scalars().unwrap_err().to_string();
    assert!(
        refusal.starts_with("component 2 of point array 'U' cannot be drawn: 1 of its 8")
            && refusal.contains("-inf, at point 5"),
        "{refusal}"
    );
}

#[test]
fn inverted_cell_is_an_error_and_mirrored_order_too() {
    let mut p = unit_cube();
    p.cells[0] = [4, 5, 6, 7, 0, 1, 2, 3];
    assert_eq!(
        Mesh::from_parts(p).unwrap_err(),
        MeshError::InvertedCells { count: 1, first: 0 }
    );
    let mut p = unit_cube();
    p.points[6] = DVec3::new(-1.0, -1.0, -1.0); // corner pulled through the cell
    assert!(matches!(
        Mesh::from_parts(p).unwrap_err(),
        MeshError::InvertedCells { .. }
    ));
}

#[test]
fn a_slightly_folded_corner_is_accepted_and_volume_is_exact() {
    let mut p = unit_cube();
    // Corner 6 pulled in so its Jacobian is -0.1 (the largest corner's is 1): a mild fold.
    p.points[6] = DVec3::new(0.45, 0.45, 1.0);
    let corners = p.cells[0].map(|i| p.points[i as usize]);
    let dets = crate::geometry::trilinear::corner_jacobian_determinants(&corners);
    assert!((dets[6] + 0.1).abs() < 1e-12);
    assert!(Mesh::from_parts(p).is_ok());
    let cube = unit_cube();
    let corners = cube.cells[0].map(|i| cube.points[i as usize] * 2.0);
    assert!((validate::cell_volume(&corners) - 8.0).abs() < 1e-12);
}

#[test]
fn collapsed_kinds_are_not_inverted() {
    let pts = vec![
        DVec3::ZERO,
        DVec3::X,
        DVec3::Y,
        DVec3::Z,
        DVec3::X + DVec3::Z,
        DVec3::Y + DVec3::Z,
    ];
    // VTK's numbering: the wedge's base 0, 1, 2 turns (right-hand rule) away from 3, 4, 5
    // (here towards −z), the tetrahedron's 0, 1, 2 towards 3 — as `vtkCellValidator` wants.
    let wedge = CellKind::Wedge.collapse(&[0, 2, 1, 3, 5, 4]);
    let tet = CellKind::Tetrahedron.collapse(&[0, 1, 2, 3]);
    let parts = |cells: Vec<[u32; 8]>| MeshParts {
        points: pts.clone(),
        cells,
        kinds: vec![CellKind::Wedge, CellKind::Tetrahedron],
        ..Default::default()
    };
    let m = Mesh::from_parts(parts(vec![wedge, tet])).unwrap();
    assert_eq!(m.kind_counts()[1], (CellKind::Wedge, 1));
    // The other winding is the mirror image VTK calls inverted, and so do we.
    let mirrored = CellKind::Wedge.collapse(&[0, 1, 2, 3, 4, 5]);
    assert!(Mesh::from_parts(parts(vec![mirrored, tet])).is_err());
}

#[test]
fn default_active_skips_constant_arrays_and_vectors_use_magnitude() {
    let mut p = unit_cube();
    p.point_data
        .insert(0, DataArray::scalar("const", vec![1.0; 8]));
    p.point_data
        .push(DataArray::vector("U", [3.0, 4.0, 0.0].repeat(8)));
    let mut m = Mesh::from_parts(p).unwrap();
    assert_eq!(m.active_array().unwrap().name, "s");
    m.set_active_scalar("U").unwrap();
    assert_eq!(m.scalar_range(), Some([5.0, 5.0]));
    m.set_active_scalar("point:U[1]").unwrap();
    assert_eq!(m.scalar_range(), Some([4.0, 4.0]));
    assert!(m.set_active_scalar("U[3]").is_err());
    assert!(m
        .set_active_scalar("nope")
        .unwrap_err()
        .to_string()
        .contains("const, s, U"));
}
