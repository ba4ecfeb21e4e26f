//! The C ABI called as C would call it: every error path, ownership, and renders checked
//! against the Rust API, the Beer–Lambert law and each other (formats, row order, input
//! types, depth in both camera modes).

use std::ffi::CStr;
use std::ptr::{null, null_mut};

use cylvol::accel::{Accel, AccelParams, StructureKind};
use cylvol::axis::Axis;
use cylvol::ffi::*;
use cylvol::mesh::{cells_from_vtk, OffsetStyle};
use cylvol::render::{
    Camera, RenderOptions, RenderStats, Renderer, TransferFunction, Volume, DEFAULT_TABLE_SIZE,
};
use cylvol::{DataArray, Mesh, MeshParts};
use glam::DVec3;

use CylvolStatus as S;

/// Caller arrays of a mesh, as `vtkCellArray` holds them.
#[derive(Clone)]
struct Arrays {
    points: Vec<f64>,
    offsets: Vec<i64>,
    conn: Vec<i64>,
    types: Vec<u8>,
}

impl Arrays {
    fn n_points(&self) -> usize {
        self.points.len() / 3
    }
    fn n_cells(&self) -> usize {
        self.types.len()
    }
    fn push_cell(&mut self, code: u8, ids: &[i64]) {
        self.conn.extend_from_slice(ids);
        self.offsets.push(self.conn.len() as i64);
        self.types.push(code);
    }
}

/// The unit cube `[0, 1]³` cut into `n³` hexahedra.
fn cube(n: usize) -> Arrays {
    let f = |i: usize| i as f64 / n as f64;
    block([n, n, n], |i, j, k| [f(i), f(j), f(k)])
}

/// A block of `n[0] × n[1] × n[2]` hexahedra whose point `(i, j, k)` lies at `at(i, j, k)`
/// (points in VTK's order, `i` fastest).
fn block(n: [usize; 3], at: impl Fn(usize, usize, usize) -> [f64; 3]) -> Arrays {
    let mut a = Arrays {
        points: Vec::new(),
        offsets: vec![0],
        conn: Vec::new(),
        types: Vec::new(),
    };
    for k in 0..=n[2] {
        for j in 0..=n[1] {
            for i in 0..=n[0] {
                a.points.extend(at(i, j, k));
            }
        }
    }
    let id = |i: usize, j: usize, k: usize| (i + (n[0] + 1) * (j + (n[1] + 1) * k)) as i64;
    for k in 0..n[2] {
        for j in 0..n[1] {
            for i in 0..n[0] {
                a.push_cell(
                    12,
                    &[
                        id(i, j, k),
                        id(i + 1, j, k),
                        id(i + 1, j + 1, k),
                        id(i, j + 1, k),
                        id(i, j, k + 1),
                        id(i + 1, j, k + 1),
                        id(i + 1, j + 1, k + 1),
                        id(i, j + 1, k + 1),
                    ],
                );
            }
        }
    }
    a
}

/// A few hexahedra of an annulus sector about z, then a wedge and a tetrahedron on top.
fn sector_with_wedge_and_tet() -> Arrays {
    let mut a = Arrays {
        points: Vec::new(),
        offsets: vec![0],
        conn: Vec::new(),
        types: Vec::new(),
    };
    let (nr, nt) = (2usize, 3usize);
    for k in 0..2 {
        for j in 0..=nt {
            for i in 0..=nr {
                let r = 1.0 + 0.5 * i as f64;
                let t = 0.3 * j as f64;
                a.points.extend([r * t.cos(), r * t.sin(), 0.5 * k as f64]);
            }
        }
    }
    let id = |i: usize, j: usize, k: usize| (i + (nr + 1) * (j + (nt + 1) * k)) as i64;
    for j in 0..nt {
        for i in 0..nr {
            a.push_cell(
                12,
                &[
                    id(i, j, 0),
                    id(i + 1, j, 0),
                    id(i + 1, j + 1, 0),
                    id(i, j + 1, 0),
                    id(i, j, 1),
                    id(i + 1, j, 1),
                    id(i + 1, j + 1, 1),
                    id(i, j + 1, 1),
                ],
            );
        }
    }
    // A wedge on the top face of cell (0, 0): triangle (p0, p1, p2) extruded upwards, in
    // VTK's numbering (its base 0, 1, 2 turns away from the top by the right-hand rule).
    let top = a.n_points() as i64;
    let base = [id(0, 0, 1), id(1, 0, 1), id(0, 1, 1)];
    for &b in &base {
        let p = &a.points[b as usize * 3..b as usize * 3 + 3].to_vec();
        a.points.extend([p[0], p[1], p[2] + 0.5]);
    }
    a.push_cell(13, &[base[0], base[2], base[1], top, top + 2, top + 1]);
    // A tetrahedron on the top face of cell (1, 2).
    let apex = a.n_points() as i64;
    a.points
        .extend([1.75 * 0.75f64.cos(), 1.75 * 0.75f64.sin(), 0.9]);
    a.push_cell(10, &[id(1, 2, 1), id(2, 2, 1), id(1, 3, 1), apex]);
    a
}

fn last_error() -> String {
    unsafe { CStr::from_ptr(cylvol_last_error()) }
        .to_string_lossy()
        .into_owned()
}

/// `cylvol_mesh_new` on the arrays as f64 points and i64 indices, writing to `out`.
fn new_mesh_into(a: &Arrays, out: *mut *mut CylvolMesh) -> CylvolStatus {
    unsafe {
        cylvol_mesh_new(
            a.points.as_ptr().cast(),
            CylvolValueType::F64.into(),
            a.n_points(),
            a.offsets.as_ptr().cast(),
            a.conn.as_ptr().cast(),
            CylvolIndexType::I64.into(),
            a.conn.len(),
            a.types.as_ptr(),
            a.n_cells(),
            out,
        )
    }
}

/// [`new_mesh_into`] a fresh handle, which must be NULL after a failure.
fn new_mesh(a: &Arrays) -> (CylvolStatus, *mut CylvolMesh) {
    let mut out = 0x10 as *mut CylvolMesh;
    let s = new_mesh_into(a, &mut out);
    if s != S::Ok {
        assert!(out.is_null(), "*out must be NULL after a failure");
    }
    (s, out)
}

fn set_scalars(m: *mut CylvolMesh, values: &[f64], assoc: CylvolAssociation) -> CylvolStatus {
    unsafe {
        cylvol_mesh_set_scalars(
            m,
            c"s".as_ptr(),
            assoc.into(),
            values.as_ptr().cast(),
            CylvolValueType::F64.into(),
            values.len(),
            1,
            0,
        )
    }
}

/// `cylvol_volume_set_scalars` with one-component `f64` values named `name`.
fn volume_set_scalars(
    v: *mut CylvolVolume,
    name: *const std::ffi::c_char,
    values: &[f64],
    assoc: CylvolAssociation,
) -> CylvolStatus {
    unsafe {
        cylvol_volume_set_scalars(
            v,
            name,
            assoc.into(),
            values.as_ptr().cast(),
            CylvolValueType::F64.into(),
            values.len(),
            1,
            0,
        )
    }
}

/// A point scalar varying over the mesh.
fn field(a: &Arrays) -> Vec<f64> {
    a.points
        .chunks(3)
        .map(|p| p[0] + 2.0 * p[1] + 0.5 * p[2] * p[2])
        .collect()
}

/// A mesh handle with the point scalar `field`.
fn mesh_with_field(a: &Arrays) -> *mut CylvolMesh {
    let (s, m) = new_mesh(a);
    assert_eq!(s, S::Ok, "{}", last_error());
    assert_eq!(
        set_scalars(m, &field(a), CylvolAssociation::POINT_DATA),
        S::Ok
    );
    m
}

fn cart_bvh_params() -> CylvolBuildParams {
    CylvolBuildParams {
        structure: CylvolStructure::CartesianBvh.into(),
        axis_auto: 0,
        axis_origin: [0.0; 3],
        axis_direction: [0.0, 0.0, 1.0],
        preset: 0,
        ..CylvolBuildParams::default()
    }
}

fn new_volume(m: *const CylvolMesh, p: *const CylvolBuildParams) -> *mut CylvolVolume {
    let mut v = null_mut();
    let s = unsafe { cylvol_volume_new(m, p, &mut v) };
    assert_eq!(s, S::Ok, "{}", last_error());
    v
}

/// Tables for the transfer function: colours and opacities over `range`.
struct Tables {
    rgb: Vec<f32>,
    opacity: Vec<f32>,
    range: [f64; 2],
    unit: f64,
}

impl Tables {
    fn ramp(range: [f64; 2]) -> Tables {
        Tables {
            rgb: vec![
                0.1, 0.2, 0.9, 0.9, 0.9, 0.9, 0.8, 0.1, 0.1, 1.0, 0.5, 0.0, 0.3, 0.3, 0.3,
            ],
            opacity: vec![0.0, 0.2, 0.6, 0.3, 0.9],
            range,
            unit: 0.4,
        }
    }
    fn constant(opacity: f32) -> Tables {
        Tables {
            rgb: vec![1.0, 0.5, 0.25, 1.0, 0.5, 0.25],
            opacity: vec![opacity, opacity],
            range: [0.0, 1.0],
            unit: 1.0,
        }
    }
    fn c(&self) -> CylvolTransfer {
        CylvolTransfer {
            rgb: self.rgb.as_ptr(),
            n_color: self.rgb.len() / 3,
            opacity: self.opacity.as_ptr(),
            n_opacity: self.opacity.len(),
            range: self.range,
            unit_distance: self.unit,
            gradient_opacity: null(),
            n_gradient_opacity: 0,
            gradient_range: [0.0, 1.0],
        }
    }
    /// The same function for the Rust API.
    fn function(&self) -> TransferFunction {
        let [lo, hi] = self.range;
        let at = |k: usize, n: usize| lo + (hi - lo) * k as f64 / (n - 1) as f64;
        let nc = self.rgb.len() / 3;
        TransferFunction {
            color: (0..nc)
                .map(|k| {
                    let c = &self.rgb[3 * k..3 * k + 3];
                    (at(k, nc), [c[0] as f64, c[1] as f64, c[2] as f64])
                })
                .collect(),
            opacity: (0..self.opacity.len())
                .map(|k| (at(k, self.opacity.len()), self.opacity[k] as f64))
                .collect(),
            unit_distance: self.unit,
        }
    }
}

fn look_at(eye: [f64; 3], focal: [f64; 3], parallel: Option<f64>) -> CylvolCamera {
    CylvolCamera {
        eye,
        focal_point: focal,
        view_up: [0.0, 1.0, 0.0],
        parallel: i32::from(parallel.is_some()),
        parallel_scale: parallel.unwrap_or(1.0),
        view_angle: 35.0,
        ..CylvolCamera::default()
    }
}

/// The Rust API's camera of a perspective [`look_at`] camera.
fn rust_camera(c: &CylvolCamera) -> Camera {
    Camera::perspective(
        DVec3::from_array(c.eye),
        DVec3::from_array(c.focal_point),
        DVec3::from_array(c.view_up),
        c.view_angle,
    )
    .unwrap()
}

fn params(width: u32, height: u32) -> CylvolRenderParams {
    CylvolRenderParams {
        width,
        height,
        ..CylvolRenderParams::default()
    }
}

struct Out {
    status: CylvolStatus,
    f32: Vec<f32>,
    depth: Vec<f32>,
}

fn render_f32(
    v: *mut CylvolVolume,
    c: &CylvolCamera,
    t: &CylvolTransfer,
    p: &CylvolRenderParams,
    depth_in: Option<&[f32]>,
) -> Out {
    let n = p.width as usize * p.height as usize;
    let mut px = vec![-1f32; n * 4];
    let mut depth = vec![-1f32; n];
    let status = unsafe {
        cylvol_render(
            v,
            c,
            t,
            p,
            depth_in.map_or(null(), |d| d.as_ptr()),
            depth.as_mut_ptr(),
            CylvolPixelFormat::RGBA_F32.into(),
            px.as_mut_ptr().cast(),
            px.len(),
        )
    };
    Out {
        status,
        f32: px,
        depth,
    }
}

fn render_u8(
    v: *mut CylvolVolume,
    c: &CylvolCamera,
    t: &CylvolTransfer,
    p: &CylvolRenderParams,
) -> Vec<u8> {
    let mut px = vec![7u8; p.width as usize * p.height as usize * 4];
    let s = unsafe {
        cylvol_render(
            v,
            c,
            t,
            p,
            null(),
            null_mut(),
            CylvolPixelFormat::RGBA8.into(),
            px.as_mut_ptr().cast(),
            px.len(),
        )
    };
    assert_eq!(s, S::Ok, "{}", last_error());
    px
}

#[test]
fn version_and_status_messages() {
    let v = unsafe { CStr::from_ptr(cylvol_version()) };
    assert_eq!(v.to_str().unwrap(), env!("CARGO_PKG_VERSION"));
    let ok = unsafe { CStr::from_ptr(cylvol_status_message(S::Ok.into())) };
    assert_eq!(ok.to_str().unwrap(), "ok");
    let unknown = unsafe { CStr::from_ptr(cylvol_status_message(StatusCode(77))) };
    assert_eq!(unknown.to_str().unwrap(), "unknown status");
}

#[test]
fn free_accepts_null() {
    unsafe {
        cylvol_mesh_free(null_mut());
        cylvol_volume_free(null_mut());
        cylvol_camera_default(null_mut());
        cylvol_build_params_default(null_mut());
        cylvol_render_params_default(null_mut());
    }
}

#[test]
fn defaults_are_filled_in() {
    let mut b = cart_bvh_params();
    let mut p = params(1, 1);
    let mut c = look_at([9.0; 3], [1.0; 3], Some(3.0));
    unsafe {
        cylvol_build_params_default(&mut b);
        cylvol_render_params_default(&mut p);
        cylvol_camera_default(&mut c);
    }
    assert_eq!(b, CylvolBuildParams::default());
    assert_eq!(b.structure, CylvolStructure::Auto.into());
    assert_eq!(b.axis_auto, 1);
    assert_eq!((p.width, p.height, p.step), (512, 512, 0.0));
    assert_eq!(p.early_termination, 0.99);
    assert_eq!(c.mode, CylvolCameraMode::LOOK_AT.into());
    assert_eq!(c.view_angle, 30.0);
}

#[test]
fn mesh_new_reports_every_bad_input() {
    let good = cube(2);
    let call = |a: &Arrays, f: &dyn Fn(&mut [*const u8; 4], &mut i32, &mut i32)| {
        let mut ptrs = [
            a.points.as_ptr().cast::<u8>(),
            a.offsets.as_ptr().cast(),
            a.conn.as_ptr().cast(),
            a.types.as_ptr(),
        ];
        let (mut pt, mut it) = (1, 1);
        f(&mut ptrs, &mut pt, &mut it);
        let mut out = null_mut();
        let s = unsafe {
            cylvol_mesh_new(
                ptrs[0].cast(),
                ValueTypeCode(pt),
                a.n_points(),
                ptrs[1].cast(),
                ptrs[2].cast(),
                IndexTypeCode(it),
                a.conn.len(),
                ptrs[3],
                a.n_cells(),
                &mut out,
            )
        };
        assert!(out.is_null() || s == S::Ok);
        unsafe { cylvol_mesh_free(out) };
        s
    };
    assert_eq!(call(&good, &|_, _, _| {}), S::Ok);
    for k in 0..4 {
        assert_eq!(call(&good, &|p, _, _| p[k] = null()), S::NullPointer);
        assert!(
            last_error().starts_with("cylvol_mesh_new: "),
            "{}",
            last_error()
        );
        assert!(last_error().contains("is NULL"));
    }
    assert_eq!(call(&good, &|_, t, _| *t = 2), S::InvalidArgument);
    assert!(last_error().contains("points_type = 2"), "{}", last_error());
    assert_eq!(call(&good, &|_, _, t| *t = -1), S::InvalidArgument);
    assert_eq!(new_mesh_into(&good, null_mut()), S::NullPointer);

    let mut nan = good.clone();
    nan.points[7] = f64::NAN;
    assert_eq!(new_mesh(&nan).0, S::InvalidArgument);
    assert!(last_error().contains("points[7] = NaN"), "{}", last_error());
    let mut inf = good.clone();
    inf.points[0] = f64::INFINITY;
    assert_eq!(new_mesh(&inf).0, S::InvalidArgument);

    let mut far = good.clone();
    far.conn[3] = 1000;
    assert_eq!(new_mesh(&far).0, S::OutOfRange);
    assert!(last_error().contains("1000"), "{}", last_error());
    let mut negative = good.clone();
    negative.conn[0] = -1;
    assert_eq!(new_mesh(&negative).0, S::OutOfRange);
    let mut decreasing = good.clone();
    decreasing.offsets[2] = 4;
    assert_eq!(new_mesh(&decreasing).0, S::OutOfRange);
    let mut first = good.clone();
    first.offsets[0] = 1;
    assert_eq!(new_mesh(&first).0, S::InvalidArgument);
    let mut last = good.clone();
    last.conn.push(0);
    assert_eq!(new_mesh(&last).0, S::LengthMismatch);
    let mut tet8 = good.clone();
    tet8.types[0] = 10;
    assert_eq!(new_mesh(&tet8).0, S::LengthMismatch);
    let mut triangle = good.clone();
    triangle.types[1] = 5;
    assert_eq!(new_mesh(&triangle).0, S::UnsupportedCell);
    assert!(last_error().contains("triangle"), "{}", last_error());
    let empty = Arrays {
        points: vec![],
        offsets: vec![0],
        conn: vec![],
        types: vec![],
    };
    assert_eq!(new_mesh(&empty).0, S::InvalidMesh);
    let mut inverted = cube(1);
    inverted.conn.swap(0, 4);
    inverted.conn.swap(1, 5);
    inverted.conn.swap(2, 6);
    inverted.conn.swap(3, 7);
    assert_eq!(new_mesh(&inverted).0, S::InvalidMesh);
    assert!(last_error().contains("inverted"), "{}", last_error());
}

#[test]
fn thirty_two_bit_indices_and_float_points_give_the_same_mesh() {
    let a = sector_with_wedge_and_tet();
    let (s, m64) = new_mesh(&a);
    assert_eq!(s, S::Ok, "{}", last_error());
    let p32: Vec<f32> = a.points.iter().map(|&v| v as f32).collect();
    let o32: Vec<i32> = a.offsets.iter().map(|&v| v as i32).collect();
    let c32: Vec<i32> = a.conn.iter().map(|&v| v as i32).collect();
    let mut m32 = null_mut();
    let s = unsafe {
        cylvol_mesh_new(
            p32.as_ptr().cast(),
            CylvolValueType::F32.into(),
            a.n_points(),
            o32.as_ptr().cast(),
            c32.as_ptr().cast(),
            CylvolIndexType::I32.into(),
            c32.len(),
            a.types.as_ptr(),
            a.n_cells(),
            &mut m32,
        )
    };
    assert_eq!(s, S::Ok, "{}", last_error());
    let (mut np, mut nc) = (0, 0);
    assert_eq!(unsafe { cylvol_mesh_counts(m32, &mut np, &mut nc) }, S::Ok);
    assert_eq!((np, nc), (a.n_points(), 8));
    let (mut b64, mut b32) = ([0.0; 6], [0.0; 6]);
    unsafe {
        assert_eq!(cylvol_mesh_bounds(m64, b64.as_mut_ptr()), S::Ok);
        assert_eq!(cylvol_mesh_bounds(m32, b32.as_mut_ptr()), S::Ok);
    }
    for k in 0..6 {
        assert!((b64[k] - b32[k]).abs() < 1e-6, "{b64:?} {b32:?}");
    }
    assert_eq!(b64[5], 1.0, "the wedge's top");
    assert_eq!(
        unsafe { cylvol_mesh_counts(m32, null_mut(), &mut nc) },
        S::NullPointer
    );
    assert_eq!(
        unsafe { cylvol_mesh_bounds(null(), b32.as_mut_ptr()) },
        S::NullPointer
    );
    assert_eq!(
        unsafe { cylvol_mesh_bounds(m32, null_mut()) },
        S::NullPointer
    );
    unsafe {
        cylvol_mesh_free(m32);
        cylvol_mesh_free(m64);
    }
}

#[test]
fn set_scalars_reports_every_bad_input_and_picks_components() {
    let a = cube(2);
    let (_, m) = new_mesh(&a);
    let mut range = [0.0; 2];
    assert_eq!(
        unsafe { cylvol_mesh_scalar_range(m, range.as_mut_ptr()) },
        S::NoScalars
    );
    let n = a.n_points();
    let vectors: Vec<f64> = (0..n).flat_map(|i| [i as f64, 3.0, -4.0]).collect();
    let call = |values: &[f64], assoc: i32, vt: i32, tuples: usize, comps: usize, comp: i32| unsafe {
        cylvol_mesh_set_scalars(
            m,
            null(),
            AssociationCode(assoc),
            if values.is_empty() {
                null()
            } else {
                values.as_ptr().cast()
            },
            ValueTypeCode(vt),
            tuples,
            comps,
            comp,
        )
    };
    assert_eq!(call(&[], 0, 1, n, 3, 0), S::NullPointer);
    assert_eq!(call(&vectors, 2, 1, n, 3, 0), S::InvalidArgument);
    assert_eq!(call(&vectors, 0, 5, n, 3, 0), S::InvalidArgument);
    assert_eq!(call(&vectors, 0, 1, n, 0, 0), S::InvalidArgument);
    assert_eq!(call(&vectors, 0, 1, n - 1, 3, 0), S::LengthMismatch);
    assert_eq!(
        call(&vectors, 1, 1, n, 3, 0),
        S::LengthMismatch,
        "cell data"
    );
    assert_eq!(call(&vectors, 0, 1, n, 3, 3), S::OutOfRange);
    assert_eq!(call(&vectors, 0, 1, n, 3, -2), S::OutOfRange);
    assert!(last_error().contains("component -2"), "{}", last_error());
    // A NaN in tuple 1's component 2: refused where component 2 or the magnitude is drawn,
    // naming what and how many, as a mesh read from a file is; component 0 draws (below).
    let mut nan = vectors.clone();
    nan[5] = f64::NAN;
    assert_eq!(call(&nan, 0, 1, n, 3, 2), S::InvalidArgument);
    assert!(
        last_error().contains("component 2 of point array 'scalars' cannot be drawn: 1 of its")
            && last_error().contains("(the first, NaN, at point 1)"),
        "{}",
        last_error()
    );
    assert_eq!(call(&nan, 0, 1, n, 3, -1), S::InvalidArgument);
    assert!(
        last_error().contains(": the magnitude of point array"),
        "{}",
        last_error()
    );
    assert_eq!(
        unsafe {
            cylvol_mesh_set_scalars(
                null_mut(),
                null(),
                AssociationCode(0),
                vectors.as_ptr().cast(),
                ValueTypeCode(1),
                n,
                3,
                0,
            )
        },
        S::NullPointer
    );
    // Still no scalars after the failures.
    assert_eq!(
        unsafe { cylvol_mesh_scalar_range(m, range.as_mut_ptr()) },
        S::NoScalars
    );
    // Component 0 of the array with a NaN in component 2: finite, so drawn.
    assert_eq!(call(&nan, 0, 1, n, 3, 0), S::Ok, "{}", last_error());
    // Component 0: the index; 1: constant 3; −1: the magnitude √(i² + 25).
    assert_eq!(call(&vectors, 0, 1, n, 3, 0), S::Ok);
    unsafe { cylvol_mesh_scalar_range(m, range.as_mut_ptr()) };
    assert_eq!(range, [0.0, (n - 1) as f64]);
    assert_eq!(call(&vectors, 0, 1, n, 3, 1), S::Ok);
    unsafe { cylvol_mesh_scalar_range(m, range.as_mut_ptr()) };
    assert_eq!(range, [3.0, 3.0]);
    assert_eq!(call(&vectors, 0, 1, n, 3, -1), S::Ok);
    unsafe { cylvol_mesh_scalar_range(m, range.as_mut_ptr()) };
    assert_eq!(range, [5.0, (((n - 1) * (n - 1)) as f64 + 25.0).sqrt()]);
    // A one-component array: 0 and −1 both mean the value (not its absolute value).
    let cell: Vec<f64> = (0..a.n_cells()).map(|c| -(c as f64)).collect();
    assert_eq!(call(&cell, 1, 1, a.n_cells(), 1, -1), S::Ok);
    unsafe { cylvol_mesh_scalar_range(m, range.as_mut_ptr()) };
    assert_eq!(range, [-7.0, 0.0]);
    assert_eq!(call(&cell, 1, 1, a.n_cells(), 1, 1), S::OutOfRange);
    let floats: Vec<f32> = cell.iter().map(|&v| v as f32 * 0.5).collect();
    assert_eq!(
        unsafe {
            cylvol_mesh_set_scalars(
                m,
                c"half".as_ptr(),
                CylvolAssociation::CELL_DATA.into(),
                floats.as_ptr().cast(),
                CylvolValueType::F32.into(),
                floats.len(),
                1,
                0,
            )
        },
        S::Ok
    );
    unsafe { cylvol_mesh_scalar_range(m, range.as_mut_ptr()) };
    assert_eq!(range, [-3.5, 0.0]);
    assert_eq!(
        unsafe { cylvol_mesh_scalar_range(m, null_mut()) },
        S::NullPointer
    );
    unsafe { cylvol_mesh_free(m) };
}

#[test]
fn volume_new_reports_bad_parameters_and_builds_every_structure() {
    let a = sector_with_wedge_and_tet();
    let m = mesh_with_field(&a);
    let mut out = null_mut();
    let p = CylvolBuildParams::default();
    assert_eq!(
        unsafe { cylvol_volume_new(null(), &p, &mut out) },
        S::NullPointer
    );
    assert_eq!(
        unsafe { cylvol_volume_new(m, &p, null_mut()) },
        S::NullPointer
    );
    for bad in [
        CylvolBuildParams {
            structure: StructureCode(5),
            ..p
        },
        CylvolBuildParams { preset: 9, ..p },
        CylvolBuildParams {
            axis_auto: 0,
            axis_direction: [0.0; 3],
            ..p
        },
        CylvolBuildParams {
            axis_auto: 0,
            axis_origin: [f64::NAN, 0.0, 0.0],
            ..p
        },
    ] {
        assert_eq!(
            unsafe { cylvol_volume_new(m, &bad, &mut out) },
            S::InvalidArgument
        );
        assert!(out.is_null());
        assert!(last_error().starts_with("cylvol_volume_new: "));
    }
    let mut stats = CylvolBuildStats {
        structure: CylvolStructure::Auto,
        build_seconds: -1.0,
        bytes: 0,
        cells: 0,
        axis_origin: [0.0; 3],
        axis_direction: [0.0; 3],
        axis_clear: -1,
        area_ratio: -1.0,
        ..CylvolBuildStats::default()
    };
    // AUTO (NULL params = defaults) on a sector about z: the cylindrical BVH, about z.
    let v = new_volume(m, null());
    assert_eq!(unsafe { cylvol_volume_build_stats(v, &mut stats) }, S::Ok);
    assert_ne!(stats.structure, CylvolStructure::Auto);
    assert_eq!(stats.cells, 8);
    assert!(stats.bytes > 0 && stats.build_seconds >= 0.0);
    assert!(stats.area_ratio > 0.0, "AUTO measures the ratio");
    let mut step = 0.0;
    assert_eq!(unsafe { cylvol_volume_default_step(v, &mut step) }, S::Ok);
    assert!(step > 0.0 && step < 1.0);
    assert_eq!(
        unsafe { cylvol_volume_default_step(v, null_mut()) },
        S::NullPointer
    );
    assert_eq!(
        unsafe { cylvol_volume_build_stats(null(), &mut stats) },
        S::NullPointer
    );
    unsafe { cylvol_volume_free(v) };
    for (code, kind) in [
        (1, CylvolStructure::CartesianGrid),
        (2, CylvolStructure::CylindricalGrid),
        (3, CylvolStructure::CartesianBvh),
        (4, CylvolStructure::CylindricalBvh),
    ] {
        for preset in 0..=4 {
            let p = CylvolBuildParams {
                structure: StructureCode(code),
                axis_auto: 0,
                axis_origin: [0.0; 3],
                axis_direction: [0.0, 0.0, -2.0],
                preset,
                ..CylvolBuildParams::default()
            };
            let v = new_volume(m, &p);
            unsafe { cylvol_volume_build_stats(v, &mut stats) };
            assert_eq!(stats.structure, kind);
            assert_eq!(stats.axis_direction, [0.0, 0.0, 1.0]);
            assert_eq!(stats.area_ratio, 0.0);
            unsafe { cylvol_volume_free(v) };
        }
    }
    unsafe { cylvol_mesh_free(m) };
}

#[test]
fn render_reports_every_bad_input() {
    let a = cube(2);
    let m = mesh_with_field(&a);
    let v = new_volume(m, &cart_bvh_params());
    let (_, none) = new_mesh(&a);
    let bare = new_volume(none, &cart_bvh_params());
    unsafe {
        cylvol_mesh_free(m);
        cylvol_mesh_free(none);
    }
    let tables = Tables::ramp([0.0, 3.5]);
    let t = tables.c();
    let c = look_at([0.5, 0.5, 4.0], [0.5, 0.5, 0.5], None);
    let p = params(6, 5);
    assert_eq!(render_f32(v, &c, &t, &p, None).status, S::Ok);
    let check = |status: CylvolStatus, out: Out, needle: &str| {
        assert_eq!(out.status, status, "{}", last_error());
        assert!(
            last_error().starts_with("cylvol_render: "),
            "{}",
            last_error()
        );
        assert!(last_error().contains(needle), "{needle}: {}", last_error());
    };
    check(
        S::NoScalars,
        render_f32(bare, &c, &t, &p, None),
        "no scalar",
    );
    let detail = unsafe { CStr::from_ptr(cylvol_volume_last_error(bare)) };
    assert!(detail.to_str().unwrap().contains("no scalar"));
    check(
        S::NullPointer,
        render_f32(null_mut(), &c, &t, &p, None),
        "volume",
    );
    let mut px = vec![0f32; 120];
    let raw = |cam: *const CylvolCamera,
               tr: *const CylvolTransfer,
               pa: *const CylvolRenderParams,
               format: i32,
               pixels: *mut f32,
               len: usize| unsafe {
        cylvol_render(
            v,
            cam,
            tr,
            pa,
            null(),
            null_mut(),
            PixelFormatCode(format),
            pixels.cast(),
            len,
        )
    };
    assert_eq!(raw(null(), &t, &p, 1, px.as_mut_ptr(), 120), S::NullPointer);
    assert_eq!(raw(&c, null(), &p, 1, px.as_mut_ptr(), 120), S::NullPointer);
    assert_eq!(raw(&c, &t, null(), 1, px.as_mut_ptr(), 120), S::NullPointer);
    assert_eq!(raw(&c, &t, &p, 1, null_mut(), 120), S::NullPointer);
    assert_eq!(raw(&c, &t, &p, 2, px.as_mut_ptr(), 120), S::InvalidArgument);
    assert_eq!(raw(&c, &t, &p, 1, px.as_mut_ptr(), 119), S::LengthMismatch);
    assert!(last_error().contains("pixels_len = 119"));
    assert_eq!(raw(&c, &t, &p, 1, px.as_mut_ptr(), 120), S::Ok);

    let bad_params: Vec<(CylvolRenderParams, &str)> = vec![
        (params(0, 5), "image size"),
        (params(6, 0), "image size"),
        (
            CylvolRenderParams {
                path: PathCode(7),
                ..p
            },
            "params->path",
        ),
        (
            CylvolRenderParams {
                interpolation: InterpolationCode(3),
                ..p
            },
            "params->interpolation",
        ),
        (
            CylvolRenderParams {
                blend: BlendCode(3),
                ..p
            },
            "params->blend",
        ),
        (
            CylvolRenderParams {
                clip_plane_count: 7,
                ..p
            },
            "params->clip_plane_count = 7 (at most 6)",
        ),
        (
            CylvolRenderParams {
                clip_plane_count: 2,
                clip_planes: [
                    [1.0, 0.0, 0.0, 0.0],
                    [0.0, 0.0, 0.0, 1.0],
                    [0.0; 4],
                    [0.0; 4],
                    [0.0; 4],
                    [0.0; 4],
                ],
                ..p
            },
            "params->clip_planes: clipping plane 1: [0, 0, 0, 1] has no normal",
        ),
        (
            CylvolRenderParams {
                clip_plane_count: 1,
                clip_planes: [[1.0, f64::NAN, 0.0, 0.0]; 6],
                ..p
            },
            "not finite",
        ),
        (
            CylvolRenderParams {
                step: f64::NAN,
                ..p
            },
            "step",
        ),
        (
            CylvolRenderParams {
                early_termination: f64::NAN,
                ..p
            },
            "early_termination",
        ),
        (
            CylvolRenderParams {
                march_reach: f64::NAN,
                ..p
            },
            "params->march_reach = NaN",
        ),
        (
            CylvolRenderParams {
                march_reach: -1.0,
                ..p
            },
            "params->march_reach = -1",
        ),
        (
            CylvolRenderParams {
                march_reach: -1e-300,
                ..p
            },
            "params->march_reach = -1e-300 (a number",
        ),
        (
            CylvolRenderParams {
                max_error: f64::NAN,
                ..p
            },
            "params->max_error = NaN (must be a finite number of 1/255",
        ),
        (
            CylvolRenderParams {
                max_error: -1.0,
                ..p
            },
            "params->max_error = -1 (must",
        ),
        (
            CylvolRenderParams {
                max_error: f64::INFINITY,
                ..p
            },
            "params->max_error = inf (must",
        ),
        (
            CylvolRenderParams {
                shading: 1,
                ambient: -1e-300,
                ..p
            },
            "params->ambient = -1e-300 (must",
        ),
        (
            CylvolRenderParams {
                shading: 1,
                specular_power: f64::INFINITY,
                ..p
            },
            "specular_power",
        ),
        (
            CylvolRenderParams {
                shading: 1,
                diffuse: -1.0,
                ..p
            },
            "diffuse",
        ),
    ];
    for (bad, needle) in bad_params {
        let n = (bad.width as usize * bad.height as usize * 4).max(4);
        let mut px = vec![0f32; n];
        let s = raw(&c, &t, &bad, 1, px.as_mut_ptr(), n);
        assert_eq!(s, S::InvalidArgument, "{needle}");
        assert!(last_error().contains(needle), "{needle}: {}", last_error());
    }

    let mut cams: Vec<(CylvolCamera, &str)> = Vec::new();
    let mut nan_eye = c;
    nan_eye.eye[1] = f64::NAN;
    cams.push((nan_eye, "camera->eye[1]"));
    cams.push((look_at([0.5; 3], [0.5; 3], None), "degenerate"));
    let mut angle = c;
    angle.view_angle = 180.0;
    cams.push((angle, "view_angle"));
    cams.push((
        look_at([0.5, 0.5, 4.0], [0.5; 3], Some(0.0)),
        "parallel_scale",
    ));
    let mut mode = c;
    mode.mode = CameraModeCode(2);
    cams.push((mode, "camera->mode"));
    let mut singular = c;
    singular.mode = CylvolCameraMode::MATRICES.into();
    singular.projection = [0.0; 16];
    cams.push((singular, "singular"));
    let mut nan_matrix = singular;
    nan_matrix.view[3] = f64::NAN;
    cams.push((nan_matrix, "camera->view[3]"));
    for (cam, needle) in cams {
        check(
            S::InvalidArgument,
            render_f32(v, &cam, &t, &p, None),
            needle,
        );
    }

    let mut trs: Vec<(Tables, &str)> = Vec::new();
    let mut nan = Tables::ramp([0.0, 3.5]);
    nan.rgb[4] = f32::NAN;
    trs.push((nan, "transfer->rgb[4]"));
    let mut above = Tables::ramp([0.0, 3.5]);
    above.opacity[2] = 1.5;
    trs.push((above, "transfer->opacity[2] = 1.5"));
    let mut short = Tables::ramp([0.0, 3.5]);
    short.opacity.truncate(1);
    trs.push((short, "at least 2"));
    trs.push((Tables::ramp([f64::NAN, 1.0]), "transfer->range"));
    trs.push((Tables::ramp([2.0, 1.0]), "reversed"));
    let mut unit = Tables::ramp([0.0, 1.0]);
    unit.unit = 0.0;
    trs.push((unit, "unit_distance"));
    for (tables, needle) in &trs {
        check(
            S::InvalidArgument,
            render_f32(v, &c, &tables.c(), &p, None),
            needle,
        );
    }
    let mut no_rgb = t;
    no_rgb.rgb = null();
    check(S::NullPointer, render_f32(v, &c, &no_rgb, &p, None), "rgb");
    let bad_gradient = [0.0f32, 1.5];
    let mut with_gradient = t;
    with_gradient.gradient_opacity = bad_gradient.as_ptr();
    with_gradient.n_gradient_opacity = 2;
    check(
        S::InvalidArgument,
        render_f32(v, &c, &with_gradient, &p, None),
        "transfer->gradient_opacity[1] = 1.5",
    );
    with_gradient.gradient_opacity = [0.5f32, 1.0].as_ptr();
    with_gradient.n_gradient_opacity = 1;
    check(
        S::InvalidArgument,
        render_f32(v, &c, &with_gradient, &p, None),
        "at least 2",
    );
    with_gradient.n_gradient_opacity = 2;
    with_gradient.gradient_range = [1.0, f64::INFINITY];
    check(
        S::InvalidArgument,
        render_f32(v, &c, &with_gradient, &p, None),
        "transfer->gradient_range[1]",
    );
    let nan_depth = vec![f32::NAN; 30];
    check(
        S::InvalidArgument,
        render_f32(v, &c, &t, &p, Some(&nan_depth)),
        "depth_in[0]",
    );
    let mut matrices = singular_free_matrices(&c, 6, 5);
    let outside = vec![1.5f32; 30];
    matrices.mode = CylvolCameraMode::MATRICES.into();
    check(
        S::InvalidArgument,
        render_f32(v, &matrices, &t, &p, Some(&outside)),
        "window depth",
    );
    // The volume keeps its own last error; a NULL volume gets a static sentence.
    let detail = unsafe { CStr::from_ptr(cylvol_volume_last_error(v)) };
    assert!(detail.to_str().unwrap().contains("window depth"));
    let detail = unsafe { CStr::from_ptr(cylvol_volume_last_error(null())) };
    assert!(!detail.to_bytes().is_empty());
    unsafe {
        cylvol_volume_free(v);
        cylvol_volume_free(bare);
    }
}

/// `vtkCamera`-style matrices (row-major) equal to a look-at camera for a `w × h` image, with
/// near and far planes at 0.1 and 100.
fn singular_free_matrices(c: &CylvolCamera, w: u32, h: u32) -> CylvolCamera {
    let eye = DVec3::from_array(c.eye);
    let f = (DVec3::from_array(c.focal_point) - eye).normalize();
    let r = f.cross(DVec3::from_array(c.view_up)).normalize();
    let u = r.cross(f);
    let view = [
        r.x,
        r.y,
        r.z,
        -r.dot(eye),
        u.x,
        u.y,
        u.z,
        -u.dot(eye),
        -f.x,
        -f.y,
        -f.z,
        f.dot(eye),
        0.0,
        0.0,
        0.0,
        1.0,
    ];
    let aspect = w as f64 / h as f64;
    let (n, fa) = (0.1, 100.0);
    let projection = if c.parallel != 0 {
        let s = c.parallel_scale;
        [
            1.0 / (s * aspect),
            0.0,
            0.0,
            0.0,
            0.0,
            1.0 / s,
            0.0,
            0.0,
            0.0,
            0.0,
            -2.0 / (fa - n),
            -(fa + n) / (fa - n),
            0.0,
            0.0,
            0.0,
            1.0,
        ]
    } else {
        let k = 1.0 / (c.view_angle.to_radians() * 0.5).tan();
        [
            k / aspect,
            0.0,
            0.0,
            0.0,
            0.0,
            k,
            0.0,
            0.0,
            0.0,
            0.0,
            -(fa + n) / (fa - n),
            -2.0 * fa * n / (fa - n),
            0.0,
            0.0,
            -1.0,
            0.0,
        ]
    };
    CylvolCamera {
        mode: CylvolCameraMode::MATRICES.into(),
        view,
        projection,
        ..*c
    }
}

/// The mesh of the caller arrays `a` with the point scalar `values` named `s`, for the Rust API.
fn rust_mesh(a: &Arrays, values: Vec<f64>) -> Mesh {
    let cells = cells_from_vtk(
        &a.conn,
        &a.offsets,
        OffsetStyle::Starts,
        &a.types,
        a.n_points(),
    )
    .unwrap();
    Mesh::from_parts(MeshParts {
        points: a
            .points
            .chunks(3)
            .map(|p| DVec3::new(p[0], p[1], p[2]))
            .collect(),
        cells: cells.cells,
        kinds: cells.kinds,
        point_data: vec![DataArray::scalar("s", values)],
        cell_data: vec![],
    })
    .unwrap()
}

/// The same scene through the Rust API: mesh, Cartesian BVH, face neighbours, fast path.
fn rust_image(
    a: &Arrays,
    values: Vec<f64>,
    tables: &Tables,
    camera: &Camera,
    w: u32,
    h: u32,
    tweak: impl Fn(&mut RenderOptions),
) -> (Vec<f32>, RenderStats) {
    let mesh = rust_mesh(a, values);
    let accel = Accel::build(
        &mesh,
        StructureKind::CartBvh,
        &Axis::Z,
        &AccelParams::default(),
    )
    .unwrap();
    let neighbours = cylvol::render::face_neighbours(&mesh, &accel);
    let volume = Volume::new(&mesh, &accel).unwrap();
    let mut options = RenderOptions::new(w, h, cylvol::render::default_step(&mesh));
    tweak(&mut options);
    assert_eq!(options.table_size, DEFAULT_TABLE_SIZE);
    let renderer = Renderer::new(&volume, &tables.function(), &options)
        .unwrap()
        .with_topology(&neighbours);
    let (image, stats) = renderer.render(camera, None).unwrap();
    (image.rgba.iter().flatten().copied().collect(), stats)
}

#[test]
fn renders_equal_the_rust_api_and_agree_across_formats_types_and_row_orders() {
    let a = sector_with_wedge_and_tet();
    let m = mesh_with_field(&a);
    let v = new_volume(m, &cart_bvh_params());
    let mut range = [0.0; 2];
    unsafe { cylvol_mesh_scalar_range(m, range.as_mut_ptr()) };
    let tables = Tables::ramp(range);
    let t = tables.c();
    let c = look_at([0.4, 1.8, 4.0], [1.2, 0.6, 0.5], None);
    let (w, h) = (24, 17);
    let p = params(w, h);
    let mut stats = CylvolRenderStats::default();
    unsafe { cylvol_volume_render_stats(v, &mut stats) };
    assert_eq!(stats, CylvolRenderStats::default(), "no render yet");
    let out = render_f32(v, &c, &t, &p, None);
    assert_eq!(out.status, S::Ok, "{}", last_error());
    unsafe { cylvol_volume_render_stats(v, &mut stats) };
    assert_eq!(stats.rays, (w * h) as u64);
    assert!(stats.samples > 0 && stats.samples_located > 0 && stats.hex_tests > 0);
    assert!(stats.internal_visits + stats.leaf_visits > 0 && stats.seconds > 0.0);
    assert_eq!(stats.gradient_evaluations, 0, "no shading, no gradients");
    let first_stats = stats;
    assert_eq!(
        unsafe { cylvol_volume_render_stats(v, null_mut()) },
        S::NullPointer
    );
    // The Rust API's image, bit for bit.
    let camera = rust_camera(&c);
    let (reference, reference_stats) = rust_image(&a, field(&a), &tables, &camera, w, h, |_| {});
    assert_eq!(out.f32, reference);
    // And its counters, every one of them.
    assert_eq!(
        first_stats,
        CylvolRenderStats {
            seconds: first_stats.seconds,
            ..CylvolRenderStats::from((0.0, reference_stats))
        }
    );
    assert!(reference_stats.walk_steps > 0 && reference_stats.surface_visits > 0);
    assert!(out.f32.chunks(4).any(|p| p[3] > 0.05), "something is seen");
    assert!(
        out.f32.chunks(4).any(|p| p[3] == 0.0),
        "something is missed"
    );
    // RGBA8 is the rounded F32 image.
    let bytes = render_u8(v, &c, &t, &p);
    for (b, f) in bytes.iter().zip(&out.f32) {
        assert_eq!(*b, (f.clamp(0.0, 1.0) * 255.0).round() as u8);
    }
    // Bottom-up rows are the same rows in reverse order.
    let flipped = render_f32(
        v,
        &c,
        &t,
        &CylvolRenderParams {
            rows_bottom_up: 1,
            ..p
        },
        None,
    );
    let row = w as usize * 4;
    for j in 0..h as usize {
        let k = h as usize - 1 - j;
        assert_eq!(
            flipped.f32[j * row..(j + 1) * row],
            out.f32[k * row..(k + 1) * row]
        );
        let dr = w as usize;
        assert_eq!(
            flipped.depth[j * dr..(j + 1) * dr],
            out.depth[k * dr..(k + 1) * dr]
        );
    }
    // Shading evaluates gradients.
    let shaded = render_f32(v, &c, &t, &CylvolRenderParams { shading: 1, ..p }, None);
    assert_eq!(shaded.status, S::Ok);
    unsafe { cylvol_volume_render_stats(v, &mut stats) };
    assert!(stats.gradient_evaluations > 0);
    assert_ne!(shaded.f32, out.f32);
    // The paper path renders the same picture up to the choice of cell on shared faces.
    let paper = render_f32(
        v,
        &c,
        &t,
        &CylvolRenderParams {
            path: CylvolPath::Paper.into(),
            ..p
        },
        None,
    );
    let diff = paper
        .f32
        .iter()
        .zip(&out.f32)
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f32::max);
    assert!(diff < 1e-5, "{diff}");
    // f32 points and values give the same picture as f64 ones when they are the same numbers.
    let mut a32 = a.clone();
    for x in &mut a32.points {
        *x = *x as f32 as f64;
    }
    let p32: Vec<f32> = a32.points.iter().map(|&x| x as f32).collect();
    let values: Vec<f32> = field(&a32).iter().map(|&x| x as f32).collect();
    let mut m32 = null_mut();
    let m64 = unsafe {
        cylvol_mesh_new(
            p32.as_ptr().cast(),
            CylvolValueType::F32.into(),
            a.n_points(),
            a.offsets.as_ptr().cast(),
            a.conn.as_ptr().cast(),
            CylvolIndexType::I64.into(),
            a.conn.len(),
            a.types.as_ptr(),
            a.n_cells(),
            &mut m32,
        );
        cylvol_mesh_set_scalars(
            m32,
            null(),
            CylvolAssociation::POINT_DATA.into(),
            values.as_ptr().cast(),
            CylvolValueType::F32.into(),
            values.len(),
            1,
            0,
        );
        let (_, m64) = new_mesh(&a32);
        let v64s: Vec<f64> = values.iter().map(|&x| x as f64).collect();
        set_scalars(m64, &v64s, CylvolAssociation::POINT_DATA);
        m64
    };
    let v32 = new_volume(m32, &cart_bvh_params());
    let v64 = new_volume(m64, &cart_bvh_params());
    let i32_ = render_f32(v32, &c, &t, &p, None);
    let i64_ = render_f32(v64, &c, &t, &p, None);
    assert_eq!(i32_.status, S::Ok);
    assert_eq!(i32_.f32, i64_.f32);
    unsafe {
        cylvol_volume_free(v32);
        cylvol_volume_free(v64);
        cylvol_mesh_free(m32);
        cylvol_mesh_free(m64);
        cylvol_mesh_free(m);
        cylvol_volume_free(v);
    }
}

#[test]
fn volume_set_scalars_changes_the_picture_without_a_rebuild() {
    let a = cube(3);
    let m = mesh_with_field(&a);
    let v = new_volume(m, &cart_bvh_params());
    let mut before = CylvolBuildStats {
        ..CylvolBuildStats::default()
    };
    let mut after = before;
    unsafe { cylvol_volume_build_stats(v, &mut before) };
    let tables = Tables::ramp([0.0, 3.5]);
    let c = look_at([2.0, 1.5, 3.0], [0.5; 3], None);
    let p = params(16, 16);
    let first = render_f32(v, &c, &tables.c(), &p, None);
    let other: Vec<f64> = a.points.chunks(3).map(|q| 3.5 * q[2]).collect();
    let s = volume_set_scalars(v, c"z".as_ptr(), &other, CylvolAssociation::POINT_DATA);
    assert_eq!(s, S::Ok);
    unsafe { cylvol_volume_build_stats(v, &mut after) };
    assert_eq!(before, after, "no rebuild");
    let second = render_f32(v, &c, &tables.c(), &p, None);
    assert_ne!(first.f32, second.f32);
    // The same as a volume built over a mesh with those scalars.
    assert_eq!(set_scalars(m, &other, CylvolAssociation::POINT_DATA), S::Ok);
    let fresh = new_volume(m, &cart_bvh_params());
    assert_eq!(render_f32(fresh, &c, &tables.c(), &p, None).f32, second.f32);
    // Errors on the volume are kept in it.
    let s = volume_set_scalars(v, null(), &other, CylvolAssociation::CELL_DATA);
    assert_eq!(s, S::LengthMismatch);
    let detail = unsafe { CStr::from_ptr(cylvol_volume_last_error(v)) };
    assert!(detail
        .to_str()
        .unwrap()
        .starts_with("cylvol_volume_set_scalars: n_tuples"));
    // …and the volume still renders its last good scalars.
    assert_eq!(render_f32(v, &c, &tables.c(), &p, None).f32, second.f32);
    // Freeing the mesh does not affect the volumes.
    unsafe { cylvol_mesh_free(m) };
    assert_eq!(render_f32(fresh, &c, &tables.c(), &p, None).f32, second.f32);
    unsafe {
        cylvol_volume_free(v);
        cylvol_volume_free(fresh);
    }
}

/// A volume keeps what a frame derived from its transfer table (transparent cells, visible
/// nodes) for the next frame of the same table, and drops it for another table or new
/// scalars: every frame equals the frame of a volume rendering it first.
#[test]
fn frames_after_a_change_of_table_equal_first_frames() {
    let a = cube(4);
    let m = mesh_with_field(&a);
    let v = new_volume(m, &cart_bvh_params());
    let c = look_at([2.5, 1.5, 3.0], [0.5; 3], None);
    let p = params(16, 16);
    let transparent_low = Tables {
        opacity: vec![0.0, 0.0, 0.0, 0.3, 0.9],
        ..Tables::ramp([0.0, 3.5])
    };
    let transparent_high = Tables {
        opacity: vec![0.9, 0.3, 0.0, 0.0, 0.0],
        ..Tables::ramp([0.0, 3.5])
    };
    let first_of = |t: &Tables| {
        let fresh = new_volume(m, &cart_bvh_params());
        let image = render_f32(fresh, &c, &t.c(), &p, None).f32;
        unsafe { cylvol_volume_free(fresh) };
        image
    };
    for t in [
        &transparent_low,
        &transparent_low,
        &transparent_high,
        &transparent_low,
    ] {
        assert_eq!(render_f32(v, &c, &t.c(), &p, None).f32, first_of(t));
    }
    assert_ne!(first_of(&transparent_low), first_of(&transparent_high));
    unsafe {
        cylvol_volume_free(v);
        cylvol_mesh_free(m);
    }
}

#[test]
fn a_constant_medium_gives_the_beer_lambert_alpha_and_misses_give_zero() {
    let a = cube(4);
    let m = mesh_with_field(&a);
    let v = new_volume(m, &cart_bvh_params());
    unsafe { cylvol_mesh_free(m) };
    // Parallel rays along −z through the unit cube: path length 1.
    let c = look_at([0.5, 0.5, 3.0], [0.5, 0.5, 0.5], Some(0.75));
    let (w, h) = (8u32, 8u32);
    let tables = Tables::constant(0.3);
    let out = render_f32(v, &c, &tables.c(), &params(w, h), None);
    assert_eq!(out.status, S::Ok);
    let expected = 1.0 - (1.0f64 - 0.3).powf(1.0 / 1.0);
    for j in 0..h {
        for i in 0..w {
            let x = ((i as f64 + 0.5) / w as f64 * 2.0 - 1.0) * 0.75;
            let y = (1.0 - (j as f64 + 0.5) / h as f64 * 2.0) * 0.75;
            let at = (j * w + i) as usize;
            let alpha = out.f32[at * 4 + 3] as f64;
            if x.abs() < 0.5 && y.abs() < 0.5 {
                assert!((alpha - expected).abs() < 1e-5, "{i},{j}: {alpha}");
                // Colour is the constant colour times alpha (premultiplied).
                assert!((out.f32[at * 4] as f64 - alpha).abs() < 1e-6);
                assert!((out.f32[at * 4 + 1] as f64 - 0.5 * alpha).abs() < 1e-6);
                assert_eq!(out.depth[at], f32::INFINITY, "alpha never reaches 0.5");
            } else {
                assert_eq!(&out.f32[at * 4..at * 4 + 4], &[0.0; 4], "{i},{j}");
            }
        }
    }
    unsafe { cylvol_volume_free(v) };
}

/// A constant field (every value 0.5) under a caller's transfer function over its own range
/// `[0, 1]` is drawn as that function gives 0.5, as VTK's mappers draw it: the empty data
/// range does not empty the picture. Parallel rays through the unit cube: path length 1.
#[test]
fn a_constant_field_draws_the_transfer_function_at_its_value() {
    let a = cube(4);
    let (s, m) = new_mesh(&a);
    assert_eq!(s, S::Ok, "{}", last_error());
    let constant = vec![0.5; a.n_points()];
    assert_eq!(
        set_scalars(m, &constant, CylvolAssociation::POINT_DATA),
        S::Ok
    );
    let v = new_volume(m, &cart_bvh_params());
    unsafe { cylvol_mesh_free(m) };
    let c = look_at([0.5, 0.5, 3.0], [0.5, 0.5, 0.5], Some(0.75));
    let tables = Tables::ramp([0.0, 1.0]);
    // The ramp's third of five entries sits at 0.5: opacity 0.6, colour (0.8, 0.1, 0.1).
    let (opacity, color) = (0.6f64, [0.8f64, 0.1, 0.1]);
    let expected = 1.0 - (1.0 - opacity).powf(1.0 / tables.unit);
    let out = render_f32(v, &c, &tables.c(), &params(8, 8), None);
    assert_eq!(out.status, S::Ok, "{}", last_error());
    // The four central pixels look through the cube's middle.
    for (i, j) in [(3usize, 3usize), (4, 3), (3, 4), (4, 4)] {
        let at = (j * 8 + i) * 4;
        let alpha = out.f32[at + 3] as f64;
        assert!(
            (alpha - expected).abs() < 1e-4,
            "{i},{j}: {alpha} vs {expected}"
        );
        for (k, want) in color.iter().enumerate() {
            let c = out.f32[at + k] as f64;
            assert!((c - want * alpha).abs() < 1e-4, "{i},{j} channel {k}: {c}");
        }
    }
    unsafe { cylvol_volume_free(v) };
}

#[test]
fn depth_in_and_out_in_both_camera_modes() {
    let a = cube(4);
    let m = mesh_with_field(&a);
    let v = new_volume(m, &cart_bvh_params());
    unsafe { cylvol_mesh_free(m) };
    let tables = Tables::constant(0.9);
    let t = tables.c();
    let (w, h) = (9u32, 7u32);
    let p = params(w, h);
    let n = (w * h) as usize;
    for parallel in [None, Some(0.8)] {
        let c = look_at([0.6, 0.4, 3.0], [0.5, 0.5, 0.5], parallel);
        let mc = singular_free_matrices(&c, w, h);
        let look = render_f32(v, &c, &t, &p, None);
        let mat = render_f32(v, &mc, &t, &p, None);
        assert_eq!(
            (look.status, mat.status),
            (S::Ok, S::Ok),
            "{}",
            last_error()
        );
        let diff = look
            .f32
            .iter()
            .zip(&mat.f32)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f32::max);
        assert!(
            diff < 1e-5,
            "the two camera modes see the same picture: {diff}"
        );
        // Look-at depths are distances along the ray; matrix depths the window depth of the
        // same point: z_ndc of its eye-space depth e through the projection.
        let eye = DVec3::from_array(c.eye);
        let focal = DVec3::from_array(c.focal_point);
        let forward = (focal - eye).normalize();
        let (near, far) = (0.1, 100.0);
        let gen = cylvol::render::RayGenerator::new(
            &Camera::perspective(eye, focal, DVec3::Y, 35.0).unwrap(),
            w,
            h,
        )
        .unwrap();
        let window = |i: u32, j: u32, d: f64| {
            let z_ndc = match parallel {
                // Parallel: the ray leaves the eye's plane along `forward`, e = d.
                Some(_) => (2.0 * d - (far + near)) / (far - near),
                None => {
                    let e = gen.ray(i, j).1.dot(forward) * d;
                    (far + near) / (far - near) - 2.0 * far * near / ((far - near) * e)
                }
            };
            (z_ndc + 1.0) * 0.5
        };
        let mut hits = 0;
        for j in 0..h {
            for i in 0..w {
                let at = (j * w + i) as usize;
                let (d, z) = (look.depth[at] as f64, mat.depth[at] as f64);
                if d.is_infinite() {
                    assert_eq!(z, 1.0);
                    continue;
                }
                hits += 1;
                let expected = window(i, j, d);
                assert!((z - expected).abs() < 1e-6, "{i},{j}: {z} vs {expected}");
            }
        }
        assert!(hits > 10);
        // depth_in at the near plane (0 / distance 0) stops everything; at the far plane
        // (1 / +∞) nothing.
        let zeros = vec![0.0; n];
        assert!(render_f32(v, &c, &t, &p, Some(&zeros))
            .f32
            .iter()
            .all(|&x| x == 0.0));
        assert!(render_f32(v, &mc, &t, &p, Some(&zeros))
            .f32
            .iter()
            .all(|&x| x == 0.0));
        let inf = vec![f32::INFINITY; n];
        assert_eq!(render_f32(v, &c, &t, &p, Some(&inf)).f32, look.f32);
        assert_eq!(render_f32(v, &mc, &t, &p, Some(&vec![1.0; n])).f32, mat.f32);
        // Stopping half a step before the depth output (between two samples): the same stop
        // in both modes, less opacity than without.
        let mut step = 0.0;
        unsafe { cylvol_volume_default_step(v, &mut step) };
        let stop_d: Vec<f32> = look.depth.iter().map(|&d| d - 0.5 * step as f32).collect();
        let stop_z: Vec<f32> = (0..n)
            .map(|k| match stop_d[k] {
                d if d.is_finite() => window(k as u32 % w, k as u32 / w, d as f64) as f32,
                _ => 1.0,
            })
            .collect();
        let a = render_f32(v, &c, &t, &p, Some(&stop_d));
        let b = render_f32(v, &mc, &t, &p, Some(&stop_z));
        assert_eq!((a.status, b.status), (S::Ok, S::Ok), "{}", last_error());
        for k in 0..n {
            if look.depth[k].is_finite() {
                let (x, y) = (a.f32[k * 4 + 3], b.f32[k * 4 + 3]);
                assert!(x < look.f32[k * 4 + 3] && x < 0.5 && x > 0.05, "{k}: {x}");
                assert!((x - y).abs() < 1e-5, "{k}: {x} vs {y}");
            }
        }
        // Bottom-up rows apply to depth_in too.
        let mut flipped_in = vec![0f32; n];
        for j in 0..h as usize {
            for i in 0..w as usize {
                flipped_in[(h as usize - 1 - j) * w as usize + i] = stop_d[j * w as usize + i];
            }
        }
        let f = render_f32(
            v,
            &c,
            &t,
            &CylvolRenderParams {
                rows_bottom_up: 1,
                ..p
            },
            Some(&flipped_in),
        );
        for j in 0..h as usize {
            for i in 0..w as usize {
                let k = j * w as usize + i;
                let kf = (h as usize - 1 - j) * w as usize + i;
                assert_eq!(f.f32[kf * 4..kf * 4 + 4], a.f32[k * 4..k * 4 + 4]);
            }
        }
    }
    unsafe { cylvol_volume_free(v) };
}

#[test]
fn volumes_built_from_one_mesh_in_parallel_render_alike() {
    let a = sector_with_wedge_and_tet();
    let m = mesh_with_field(&a) as usize;
    let images: Vec<Vec<f32>> = std::thread::scope(|s| {
        let handles: Vec<_> = (0..3)
            .map(|_| {
                s.spawn(move || {
                    let v = new_volume(m as *const CylvolMesh, &cart_bvh_params());
                    let tables = Tables::ramp([0.0, 4.0]);
                    let c = look_at([1.0, 0.5, 4.0], [1.0, 0.5, 0.5], None);
                    let out = render_f32(v, &c, &tables.c(), &params(12, 12), None);
                    unsafe { cylvol_volume_free(v) };
                    out.f32
                })
            })
            .collect();
        handles.into_iter().map(|h| h.join().unwrap()).collect()
    });
    assert!(images.windows(2).all(|w| w[0] == w[1]));
    unsafe { cylvol_mesh_free(m as *mut CylvolMesh) };
}

/// The sector with a wedge and a tetrahedron as a Cartesian-BVH volume (its mesh handle freed),
/// a ramp over its field, and one perspective view of it as a C camera and as the Rust one.
fn sector_scene() -> (Arrays, *mut CylvolVolume, Tables, CylvolCamera, Camera) {
    let a = sector_with_wedge_and_tet();
    let m = mesh_with_field(&a);
    let v = new_volume(m, &cart_bvh_params());
    unsafe { cylvol_mesh_free(m) };
    let tables = Tables::ramp([0.0, 4.0]);
    let c = look_at([0.4, 1.8, 4.0], [1.2, 0.6, 0.5], None);
    let camera = rust_camera(&c);
    (a, v, tables, c, camera)
}

#[test]
fn nearest_interpolation_and_gradient_opacity_match_the_rust_api() {
    let (a, v, tables, c, camera) = sector_scene();
    let (w, h) = (20, 14);
    let linear = render_f32(v, &c, &tables.c(), &params(w, h), None);
    let p = CylvolRenderParams {
        interpolation: CylvolInterpolation::Nearest.into(),
        ..params(w, h)
    };
    let nearest = render_f32(v, &c, &tables.c(), &p, None);
    assert_eq!(nearest.status, S::Ok, "{}", last_error());
    assert_ne!(nearest.f32, linear.f32);
    let (reference, _) = rust_image(&a, field(&a), &tables, &camera, w, h, |o| {
        o.interpolation = cylvol::render::Interpolation::Nearest
    });
    assert_eq!(nearest.f32, reference);

    // Gradient opacity: a ramp over |∇s| in [0, 3] (the field's gradient is about 2.2).
    let g = [0.0f32, 0.25, 1.0];
    let mut t = tables.c();
    t.gradient_opacity = g.as_ptr();
    t.n_gradient_opacity = 3;
    t.gradient_range = [0.0, 3.0];
    let out = render_f32(v, &c, &t, &params(w, h), None);
    assert_eq!(out.status, S::Ok, "{}", last_error());
    let mut stats = CylvolRenderStats::default();
    unsafe { cylvol_volume_render_stats(v, &mut stats) };
    assert!(
        stats.gradient_evaluations > 0,
        "gradient opacity needs gradients"
    );
    let (reference, _) = rust_image(&a, field(&a), &tables, &camera, w, h, |o| {
        o.gradient_opacity = Some(
            cylvol::render::GradientOpacity::new(&[(0.0, 0.0), (1.5, 0.25), (3.0, 1.0)]).unwrap(),
        )
    });
    assert_eq!(out.f32, reference);
    let alpha = |img: &[f32]| img.chunks(4).map(|p| p[3] as f64).sum::<f64>();
    assert!(alpha(&out.f32) < alpha(&linear.f32) && alpha(&out.f32) > 0.0);
    // A zero factor everywhere makes the volume invisible.
    let zero = [0.0f32, 0.0];
    t.gradient_opacity = zero.as_ptr();
    t.n_gradient_opacity = 2;
    let none = render_f32(v, &c, &t, &params(w, h), None);
    assert!(none.f32.iter().all(|&x| x == 0.0));
    unsafe { cylvol_volume_free(v) };
}

/// Maximum- and minimum-intensity projections through the C ABI: each equals the Rust API's
/// image with that blend, the two differ from each other and from compositing, and the default
/// parameters composite.
#[test]
fn intensity_projections_match_the_rust_api() {
    let (a, v, tables, c, camera) = sector_scene();
    let (w, h) = (20, 14);
    assert_eq!(params(w, h).blend, CylvolBlend::Composite.into());
    let composite = render_f32(v, &c, &tables.c(), &params(w, h), None);
    let mut images = Vec::new();
    for (code, blend) in [
        (CylvolBlend::Maximum, cylvol::render::Blend::Maximum),
        (CylvolBlend::Minimum, cylvol::render::Blend::Minimum),
    ] {
        let p = CylvolRenderParams {
            blend: code.into(),
            shading: 1,
            ..params(w, h)
        };
        let out = render_f32(v, &c, &tables.c(), &p, None);
        assert_eq!(out.status, S::Ok, "{}", last_error());
        let mut stats = CylvolRenderStats::default();
        unsafe { cylvol_volume_render_stats(v, &mut stats) };
        assert_eq!(stats.gradient_evaluations, 0, "{code:?} shades nothing");
        assert!(out.f32.iter().any(|&x| x > 0.0));
        assert_ne!(out.f32, composite.f32);
        let (reference, rust) =
            rust_image(&a, field(&a), &tables, &camera, w, h, |o| o.blend = blend);
        assert_eq!(out.f32, reference, "{code:?}");
        // The same cells passed over as unable to beat the extreme, counted through the ABI.
        assert_eq!(stats.extreme_skips, rust.extreme_skips, "{code:?}");
        assert_eq!(stats.extreme_jumps, rust.extreme_jumps, "{code:?}");
        assert_eq!(stats.samples_located, rust.samples_located, "{code:?}");
        images.push(out.f32);
    }
    assert_ne!(images[0], images[1]);
    unsafe { cylvol_volume_free(v) };
}

/// Clipping planes through the C ABI: the image equals the Rust API's with the same planes
/// (equations as VTK's `GetClippingPlaneInDataCoords` gives them), differs from the unclipped
/// one, samples less, and unused rows of `clip_planes` are ignored (even when not finite).
#[test]
fn clipping_planes_match_the_rust_api() {
    let (a, v, tables, c, camera) = sector_scene();
    let (w, h) = (20, 14);
    assert_eq!(params(w, h).clip_plane_count, 0);
    let whole = render_f32(v, &c, &tables.c(), &params(w, h), None);
    let mut all = CylvolRenderStats::default();
    unsafe { cylvol_volume_render_stats(v, &mut all) };
    let planes = [[1.0, 0.2, -0.1, -1.1], [-0.1, 0.0, -1.0, 0.8]];
    let mut p = params(w, h);
    p.clip_plane_count = 2;
    p.clip_planes[..2].copy_from_slice(&planes);
    p.clip_planes[2] = [f64::NAN; 4];
    let out = render_f32(v, &c, &tables.c(), &p, None);
    assert_eq!(out.status, S::Ok, "{}", last_error());
    let mut stats = CylvolRenderStats::default();
    unsafe { cylvol_volume_render_stats(v, &mut stats) };
    assert!(stats.samples_located < all.samples_located);
    assert_ne!(out.f32, whole.f32);
    assert!(out.f32.iter().any(|&x| x > 0.0));
    let (reference, rust) = rust_image(&a, field(&a), &tables, &camera, w, h, |o| {
        o.clip_planes = cylvol::render::ClipPlanes::new(&planes).unwrap()
    });
    assert_eq!(out.f32, reference);
    assert_eq!(stats.samples_located, rust.samples_located);
    unsafe { cylvol_volume_free(v) };
}

/// The march reach through the C ABI: 6 cells by default; at 0 every sample past its
/// predecessor's cell is located through the structure (counted in `far_locates`), at
/// `INFINITY` none is — with the same image, equal to the Rust API's with that reach.
#[test]
fn march_reach_changes_the_work_not_the_image() {
    let (a, v, tables, c, camera) = sector_scene();
    let (w, h) = (20, 14);
    assert_eq!(
        params(w, h).march_reach,
        cylvol::render::DEFAULT_MARCH_REACH
    );
    let mut images = Vec::new();
    let mut far = Vec::new();
    for reach in [f64::INFINITY, 0.0] {
        let p = CylvolRenderParams {
            march_reach: reach,
            ..params(w, h)
        };
        let out = render_f32(v, &c, &tables.c(), &p, None);
        assert_eq!(out.status, S::Ok, "{}", last_error());
        let mut stats = CylvolRenderStats::default();
        unsafe { cylvol_volume_render_stats(v, &mut stats) };
        let (reference, rust) = rust_image(&a, field(&a), &tables, &camera, w, h, |o| {
            o.march_reach = reach
        });
        assert_eq!(out.f32, reference, "reach {reach}");
        assert_eq!(stats.far_locates, rust.far_locates, "reach {reach}");
        assert!(out.f32.iter().any(|&x| x > 0.0));
        far.push(stats.far_locates);
        images.push(out.f32);
    }
    assert_eq!(far[0], 0);
    assert!(far[1] > 0, "{far:?}");
    let diff = images[0]
        .iter()
        .zip(&images[1])
        .map(|(x, y)| (x - y).abs())
        .fold(0.0f32, f32::max);
    assert!(diff <= 1e-6, "the reach changed the image by {diff}");
    unsafe { cylvol_volume_free(v) };
}

/// The error bound through the C ABI: off (0) by default; at 2/255 the image equals the Rust
/// API's at `max_error` 2, bit for bit, with the same counters, and refines where the fixed
/// step (`max_error` 0) refines nothing and integrates nothing; a tighter bound takes more
/// samples; an intensity projection ignores the bound, as the Rust API does.
#[test]
fn an_error_bound_matches_the_rust_api_and_refines_only_when_asked() {
    let (a, v, tables, c, camera) = sector_scene();
    let (w, h) = (20, 14);
    assert_eq!(params(w, h).max_error, 0.0);
    let render = |p: &CylvolRenderParams| {
        let out = render_f32(v, &c, &tables.c(), p, None);
        assert_eq!(out.status, S::Ok, "{}", last_error());
        let mut stats = CylvolRenderStats::default();
        assert_eq!(unsafe { cylvol_volume_render_stats(v, &mut stats) }, S::Ok);
        (out.f32, stats)
    };
    let with_error = |e: f64| CylvolRenderParams {
        max_error: e,
        ..params(w, h)
    };
    let (fixed, fixed_stats) = render(&params(w, h));
    assert_eq!(
        (
            fixed_stats.refined_samples,
            fixed_stats.slopes,
            fixed_stats.integrated_stretches
        ),
        (0, 0, 0),
        "the fixed step does no error-bounded work"
    );
    let (bounded, stats) = render(&with_error(2.0));
    let (reference, rust) = rust_image(&a, field(&a), &tables, &camera, w, h, |o| {
        o.max_error = Some(2.0)
    });
    assert_eq!(bounded, reference);
    assert_eq!(
        stats,
        CylvolRenderStats {
            seconds: stats.seconds,
            ..CylvolRenderStats::from((0.0, rust))
        }
    );
    assert!(stats.refined_samples > 0, "{stats:?}");
    assert!(
        stats.slopes > 0 && stats.integrated_stretches > 0,
        "{stats:?}"
    );
    assert_ne!(bounded, fixed);
    let (_, tight) = render(&with_error(0.25));
    assert!(tight.samples > stats.samples, "{tight:?} vs {stats:?}");
    assert!(tight.refined_samples > stats.refined_samples);
    // An intensity projection keeps the fixed step: the same image and work either way.
    let maximum = |e: f64| CylvolRenderParams {
        blend: CylvolBlend::Maximum.into(),
        ..with_error(e)
    };
    let (mip, mip_stats) = render(&maximum(0.0));
    let (mip_bounded, mip_bounded_stats) = render(&maximum(2.0));
    assert_eq!(mip, mip_bounded);
    assert_eq!(mip_bounded_stats.refined_samples, 0);
    assert_eq!(mip_bounded_stats.samples, mip_stats.samples);
    unsafe { cylvol_volume_free(v) };
}

/// A volume shares its mesh handle's memory, but neither sees the other's later scalars: the
/// mesh's new scalars leave the volume's picture as it was, and the volume's new scalars leave
/// the mesh's range as it was.
#[test]
fn a_volume_and_its_mesh_keep_their_own_scalars_after_the_build() {
    let a = cube(3);
    let m = mesh_with_field(&a);
    let range = |m: *const CylvolMesh| {
        let mut r = [0.0; 2];
        assert_eq!(
            unsafe { cylvol_mesh_scalar_range(m, r.as_mut_ptr()) },
            S::Ok
        );
        r
    };
    let built_range = range(m);
    let v = new_volume(m, &cart_bvh_params());
    let tables = Tables::ramp(built_range);
    let c = look_at([2.0, 1.5, 3.0], [0.5; 3], None);
    let p = params(16, 16);
    let first = render_f32(v, &c, &tables.c(), &p, None);
    // New scalars on the mesh: its range changes, the volume's picture does not.
    let doubled: Vec<f64> = field(&a).iter().map(|s| 2.0 * s + 1.0).collect();
    assert_eq!(
        set_scalars(m, &doubled, CylvolAssociation::POINT_DATA),
        S::Ok
    );
    assert_ne!(range(m), built_range);
    assert_eq!(render_f32(v, &c, &tables.c(), &p, None).f32, first.f32);
    // A second volume shares the mesh with the new scalars; new scalars on it leave the mesh.
    let w = new_volume(m, &cart_bvh_params());
    let mesh_range = range(m);
    let zeros = vec![0.0; doubled.len()];
    let s = volume_set_scalars(w, c"zero".as_ptr(), &zeros, CylvolAssociation::POINT_DATA);
    assert_eq!(s, S::Ok);
    assert_eq!(range(m), mesh_range);
    assert_ne!(render_f32(w, &c, &tables.c(), &p, None).f32, first.f32);
    assert_eq!(render_f32(v, &c, &tables.c(), &p, None).f32, first.f32);
    unsafe {
        cylvol_mesh_free(m);
        cylvol_volume_free(v);
        cylvol_volume_free(w);
    }
}

/// A quarter annulus about z (r 1–2, θ 0–90°, z 0–1) of `nr × nt × nz` hexahedra.
fn quarter_annulus(nr: usize, nt: usize, nz: usize) -> Arrays {
    block([nr, nt, nz], |i, j, k| {
        let r = 1.0 + i as f64 / nr as f64;
        let t = std::f64::consts::FRAC_PI_2 * j as f64 / nt as f64;
        [r * t.cos(), r * t.sin(), k as f64 / nz as f64]
    })
}

/// Periodic copies through the build parameters: found (`-1`) or given, said in the build's
/// figures (copies, span, matched faces, the wheel's box), drawn as the Rust API draws them,
/// a range of copies; bad requests refused with the reason.
#[test]
fn periodic_copies_are_built_said_and_drawn_as_the_rust_api_draws_them() {
    let a = quarter_annulus(3, 6, 2);
    let m = mesh_with_field(&a);
    let build = |periodic: i32, first: i32, end: i32| {
        let p = CylvolBuildParams {
            periodic,
            copies_first: first,
            copies_end: end,
            ..cart_bvh_params()
        };
        let mut v = null_mut();
        let status = unsafe { cylvol_volume_new(m, &p, &mut v) };
        (status, v)
    };
    let stats = |v: *mut CylvolVolume| {
        let mut b = CylvolBuildStats::default();
        assert_eq!(unsafe { cylvol_volume_build_stats(v, &mut b) }, S::Ok);
        b
    };
    let (s0, sector) = build(0, 0, 0);
    let (s1, wheel) = build(-1, 0, 0);
    let (s2, three) = build(4, 1, 4);
    assert_eq!((s0, s1, s2), (S::Ok, S::Ok, S::Ok), "{}", last_error());
    let (b0, b1, b2) = (stats(sector), stats(wheel), stats(three));
    assert_eq!((b0.periodic_copies, b0.copies_end), (0, 0));
    assert!(b0.bounds[0].abs() < 1e-12 && (b0.bounds[1] - 2.0).abs() < 1e-12);
    assert_eq!(
        (b1.periodic_copies, b1.copies_first, b1.copies_end),
        (4, 0, 4)
    );
    assert!((b1.periodic_span_degrees - 90.0).abs() < 1e-9);
    // One side's faces: 3 radial by 2 high.
    assert_eq!(b1.periodic_matched_faces, 3 * 2);
    assert!(b1.periodic_worst_mismatch < 1e-9);
    assert!((b1.bounds[0] + 2.0).abs() < 1e-9 && (b1.bounds[2] + 2.0).abs() < 1e-9);
    assert_eq!((b2.copies_first, b2.copies_end), (1, 4));

    // Drawn as the Rust API draws the copies, bit for bit.
    let tables = Tables::ramp([-4.0, 4.0]);
    let c = look_at([0.5, -1.0, 6.0], [0.0, 0.0, 0.5], None);
    let camera = rust_camera(&c);
    let (w, h) = (24, 20);
    let lit = |img: &[f32]| img.chunks(4).filter(|p| p[3] > 0.01).count();
    let drawn = render_f32(wheel, &c, &tables.c(), &params(w, h), None);
    assert_eq!(drawn.status, S::Ok, "{}", last_error());
    let alone = render_f32(sector, &c, &tables.c(), &params(w, h), None);
    let part = render_f32(three, &c, &tables.c(), &params(w, h), None);
    assert!(lit(&drawn.f32) > lit(&part.f32) && lit(&part.f32) > lit(&alone.f32));
    let mesh = rust_mesh(&a, field(&a));
    let accel = Accel::build(
        &mesh,
        StructureKind::CartBvh,
        &Axis::Z,
        &AccelParams::default(),
    )
    .unwrap();
    let found = cylvol::axis::periodic::detect(&mesh, &Axis::Z).unwrap();
    let topology = cylvol::render::face_neighbours(&mesh, &accel)
        .with_periodic_sides(&mesh, &found)
        .0;
    let volume = Volume::new(&mesh, &accel).unwrap();
    let options = RenderOptions::new(w, h, cylvol::render::default_step(&mesh));
    let copies = cylvol::render::Copies::new(&mesh, found, None).unwrap();
    let renderer = Renderer::new(&volume, &tables.function(), &options)
        .unwrap()
        .with_topology(&topology)
        .with_copies(copies)
        .unwrap();
    let (image, _) = renderer.render(&camera, None).unwrap();
    let reference: Vec<f32> = image.rgba.iter().flatten().copied().collect();
    assert_eq!(drawn.f32, reference);

    // The range the tables span: the scalar's own, whatever the copies.
    let (mut r0, mut r1) = ([0.0; 2], [0.0; 2]);
    unsafe {
        assert_eq!(cylvol_volume_scalar_range(sector, r0.as_mut_ptr()), S::Ok);
        assert_eq!(cylvol_volume_scalar_range(wheel, r1.as_mut_ptr()), S::Ok);
        assert_eq!(
            cylvol_volume_scalar_range(wheel, null_mut()),
            S::NullPointer
        );
    }
    assert_eq!(r0, r1);
    assert_eq!(r0, volume.scalar_range());

    // Refused, with the reason.
    for (periodic, first, end, said) in [
        (-2, 0, 0, "params->periodic"),
        (0, 0, 2, "need params->periodic"),
        (4, 2, 6, "not a range"),
        (4, -1, 2, "numbered from 0"),
        (3, 0, 0, "periodic copies:"),
    ] {
        let (status, v) = build(periodic, first, end);
        assert_eq!(status, S::InvalidArgument, "{periodic} {first}:{end}");
        assert!(v.is_null());
        assert!(last_error().contains(said), "{}", last_error());
    }
    unsafe {
        cylvol_volume_free(sector);
        cylvol_volume_free(wheel);
        cylvol_volume_free(three);
        cylvol_mesh_free(m);
    }
}

/// A vector's component given whole through the C ABI turns with the copies: the range the
/// tables span is the turned components' over every copy, and the sector's where only copy 0
/// is drawn.
#[test]
fn a_vector_component_turns_with_the_copies_through_the_c_abi() {
    let a = quarter_annulus(3, 6, 2);
    // A swirl: the vector turns with the angle, so its x component differs copy by copy.
    let vectors: Vec<f64> = a
        .points
        .chunks(3)
        .flat_map(|p| [-p[1] + 0.3, p[0], p[2]])
        .collect();
    let (s, m) = new_mesh(&a);
    assert_eq!(s, S::Ok);
    let status = unsafe {
        cylvol_mesh_set_scalars(
            m,
            c"v".as_ptr(),
            CylvolAssociation::POINT_DATA.into(),
            vectors.as_ptr().cast(),
            CylvolValueType::F64.into(),
            a.n_points(),
            3,
            0,
        )
    };
    assert_eq!(status, S::Ok, "{}", last_error());
    let build = |first: i32, end: i32| {
        let p = CylvolBuildParams {
            periodic: 4,
            copies_first: first,
            copies_end: end,
            ..cart_bvh_params()
        };
        new_volume(m, &p)
    };
    let (wheel, first) = (build(0, 0), build(0, 1));
    let (mut all, mut one) = ([0.0; 2], [0.0; 2]);
    unsafe {
        assert_eq!(cylvol_volume_scalar_range(wheel, all.as_mut_ptr()), S::Ok);
        assert_eq!(cylvol_volume_scalar_range(first, one.as_mut_ptr()), S::Ok);
    }
    // x of the swirl over the sector (x, y in [0, 2]) is -y + 0.3 in [-1.7, 0.3]; over the
    // wheel, turned, it reaches +-(the largest radius) + 0.3 turned.
    assert!(
        (one[0] + 1.7).abs() < 1e-9 && (one[1] - 0.3).abs() < 1e-9,
        "{one:?}"
    );
    assert!(all[0] < one[0] - 0.1 && all[1] > one[1] + 1.0, "{all:?}");
    unsafe {
        cylvol_volume_free(wheel);
        cylvol_volume_free(first);
        cylvol_mesh_free(m);
    }
}
