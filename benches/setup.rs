//! What a first frame spends before and on its rays (a plain program, not criterion: it prints
//! a table).
//!
//! `cargo bench --bench setup -- [INPUT] [STRUCTURE] [SIZE] [REPEATS]` (default
//! `pump-rotor:2100000 auto 512 3`): `INPUT` is what `cylvol render` takes (a dataset
//! `NAME[:CELLS]` or a mesh file). It times, best of `REPEATS`, each phase of the set-up that
//! the C ABI's `cylvol_volume_new` (and so the VTK mapper's first frame) and `cylvol render`
//! run, in their order: the mesh's validation (`Mesh::from_parts`, on a copy of its parts),
//! axis detection, the structure choice (for `auto`), the structure, the three phases of
//! `render::face_neighbours` (the adjacency, the boundary surface, the check of the faces
//! without a neighbour), the default step and the scalar gather; then the first frame and a
//! second one with the fast path at `SIZE × SIZE` (the bench's oblique view), the same frame
//! through VTK-style matrices for the whole image and in four bands of rows as the VTK mapper
//! renders them (each band sorts the boundary faces to its own rows), and the transfer table
//! as each band samples it from the mapper's 1,024-point functions. The phases of
//! `face_neighbours` are also timed together, through the function itself, to show that they
//! are what it does. Wall and process CPU seconds are printed for each (CPU ≈ 2 × wall on two
//! cores means the phase is parallel).

#[path = "common/timing.rs"]
mod timing;

use cylvol::accel::choose::{cylindrical_area_ratio, structure_for_ratio};
use cylvol::accel::{Accel, AccelParams, StructureKind};
use cylvol::axis::detect_with_report;
use cylvol::io::ReadOptions;
use cylvol::mesh::topology::FaceNeighbours;
use cylvol::render::{
    default_step, face_neighbours, Camera, RaySource, RenderOptions, RenderPath, Renderer,
    ScalarField, Topology, TransferFunction, Volume,
};
use cylvol::{Association, Mesh};
use timing::best;

fn main() {
    let args: Vec<String> = std::env::args()
        .skip(1)
        .filter(|a| !a.starts_with("--"))
        .collect();
    let spec = args.first().map_or("pump-rotor:2100000", |s| s.as_str());
    let structure = args.get(1).map_or("auto", |s| s.as_str());
    let size: u32 = args.get(2).and_then(|s| s.parse().ok()).unwrap_or(512);
    let repeats: usize = args.get(3).and_then(|s| s.parse().ok()).unwrap_or(3);
    let mesh = cylvol::input::load(spec, &ReadOptions::default()).expect("a loadable INPUT");
    println!(
        "{spec}: {} cells, {} threads, best of {repeats}",
        mesh.cell_count(),
        rayon::current_num_threads()
    );
    println!("  {:<36} {:>8} {:>8}", "phase", "wall s", "cpu s");
    let mut table = Table::default();
    let parts = mesh.clone().into_parts();
    let (t, _) = best(repeats, || Mesh::from_parts(parts.clone()).expect("valid"));
    let (copy, _) = best(repeats, || parts.clone());
    table.row(
        "mesh validation (less the copy)",
        (t.0 - copy.0, t.1 - copy.1),
        true,
    );
    drop(parts);

    let (t, detection) = best(repeats, || detect_with_report(&mesh));
    table.row("axis detection", t, true);
    let axis = detection.axis;
    let kind = match structure {
        "auto" => {
            let (t, ratio) = best(repeats, || cylindrical_area_ratio(&mesh, &axis));
            table.row("structure choice (auto)", t, true);
            structure_for_ratio(ratio)
        }
        name => name.parse::<StructureKind>().expect("a structure name"),
    };
    let (t, accel) = best(repeats, || {
        Accel::build(&mesh, kind, &axis, &AccelParams::default()).expect("builds")
    });
    table.row(&format!("structure ({})", kind.name()), t, true);
    structure_phases(&mesh, kind, &axis, repeats);

    let tolerance = FaceNeighbours::seam_tolerance(&mesh);
    let (t, faces) = best(repeats, || {
        FaceNeighbours::build_with_tolerance(&mesh, tolerance)
    });
    table.row("face adjacency", t, true);
    let (t, unchecked) = best(repeats, || Topology::new(&mesh, faces.clone()));
    let (copy, _) = best(repeats, || faces.clone());
    table.row(
        "boundary surface (less the copy)",
        (t.0 - copy.0, t.1 - copy.1),
        true,
    );
    let (t, _) = best(repeats, || {
        let mut checked = unchecked.clone();
        checked.check_boundary(&mesh, &accel)
    });
    let (copy, _) = best(repeats, || unchecked.clone());
    table.row(
        "boundary check (less the copy)",
        (t.0 - copy.0, t.1 - copy.1),
        true,
    );
    let (t, topology) = best(repeats, || face_neighbours(&mesh, &accel));
    table.row("  (face_neighbours as a whole)", t, false);

    let (t, step) = best(repeats, || default_step(&mesh));
    table.row("default step", t, true);
    let (t, _) = best(repeats, || ScalarField::gather(&mesh).expect("a scalar"));
    table.row("scalar gather", t, true);
    table.row("set-up in all", table.total, false);

    let volume = Volume::new(&mesh, &accel).expect("volume");
    let [lo, hi] = volume.scalar_range();
    let tf = TransferFunction::default_for_range(lo, hi, 0.3, 0.1);
    let camera = Camera::view(mesh.bounds(), size, size, 30.0, 20.0, 1.0);
    let mut options = RenderOptions::new(size, size, step);
    options.path = RenderPath::Fast;
    let frame = || {
        let renderer = Renderer::new(&volume, &tf, &options)
            .expect("renderer")
            .with_topology(&topology);
        renderer.render(&camera, None).expect("render")
    };
    let (t, _) = best(repeats, frame);
    table.row(&format!("fast frame {size}x{size}"), t, true);
    table.row("first frame in all", table.total, false);
    let through = |rays: &cylvol::render::MatrixRays| {
        let options = RenderOptions {
            height: rays.size().1,
            ..options
        };
        Renderer::new(&volume, &tf, &options)
            .expect("renderer")
            .with_topology(&topology)
            .render_rays(rays, None)
            .expect("render")
    };
    banded_frames(&camera, size, repeats, through);
    transfer_table(repeats);

    c_abi(&mesh, repeats);
}

/// The structure's build in its two phases, not counted in the totals: the cells' pieces
/// (boxes, or sectors about the axis with the seam placed) and the tree or grid over them.
fn structure_phases(mesh: &Mesh, kind: StructureKind, axis: &cylvol::axis::Axis, repeats: usize) {
    use cylvol::accel::bvh::build_bvh;
    use cylvol::accel::grid::build_grid;
    use cylvol::accel::space::{
        cartesian_pieces, cylindrical_pieces, linear_boxes, seam_frame, DEFAULT_STRADDLE_SECTORS,
    };
    use cylvol::geometry::cylindrical::CylFrame;
    let params = AccelParams::default();
    let mut table = Table::default();
    if kind.is_cylindrical() {
        let frame = CylFrame::new(axis.origin, axis.direction).expect("a usable axis");
        let (t, (seam, pieces)) = best(repeats, || {
            let pieces = cylindrical_pieces(mesh, &frame, DEFAULT_STRADDLE_SECTORS);
            seam_frame(axis, pieces).expect("a usable axis")
        });
        table.row("  cell pieces (sectors)", t, false);
        let (t, _) = if kind.is_grid() {
            let boxes = linear_boxes(&pieces);
            let coordinates = cylvol::accel::Coordinates::Cylindrical(seam);
            best(repeats, || {
                build_grid(coordinates, &boxes, &params.grid);
            })
        } else {
            best(repeats, || {
                build_bvh(&pieces, &params.bvh);
            })
        };
        table.row("  tree over them", t, false);
    } else {
        let (t, pieces) = best(repeats, || cartesian_pieces(mesh));
        table.row("  cell pieces (boxes)", t, false);
        let (t, _) = if kind.is_grid() {
            best(repeats, || {
                build_grid(cylvol::accel::Coordinates::Cartesian, &pieces, &params.grid);
            })
        } else {
            best(repeats, || {
                build_bvh(&pieces, &params.bvh);
            })
        };
        table.row("  tree over them", t, false);
    }
}

/// The fast frame through VTK-style matrices (`render` renders the rays of a matrix): the
/// whole image, and four bands of rows rendered one after the other as vtkCylVolMapper renders
/// a frame (each band's projection narrowed to its rows, each sorting the boundary faces to
/// its own rows). Not counted in the totals.
fn banded_frames<T>(
    camera: &Camera,
    size: u32,
    repeats: usize,
    render: impl Fn(&cylvol::render::MatrixRays) -> T,
) {
    use cylvol::render::{band_projection, MatrixRays, Projection};
    use glam::DMat4;
    let Projection::Perspective(angle) = camera.projection else {
        return;
    };
    let row_major = |m: DMat4| -> [f64; 16] {
        let c = m.to_cols_array();
        std::array::from_fn(|k| c[4 * (k % 4) + k / 4])
    };
    let distance = (camera.focal - camera.eye).length();
    let view = row_major(DMat4::look_at_rh(camera.eye, camera.focal, camera.up));
    let proj = row_major(DMat4::perspective_rh_gl(
        angle.to_radians(),
        1.0,
        0.01 * distance,
        100.0 * distance,
    ));
    let (t, _) = best(repeats, || {
        render(&MatrixRays::new(&view, &proj, size, size).expect("rays"))
    });
    println!("  fast frame through matrices, not counted:");
    let mut table = Table::default();
    table.row(&format!("  whole image {size}x{size}"), t, false);
    let bands = 4;
    let (t, _) = best(repeats, || {
        (0..bands)
            .map(|b| {
                let (r0, r1) = (size * b / bands, size * (b + 1) / bands);
                let band = band_projection(&proj, r0, r1, size);
                render(&MatrixRays::new(&view, &band, size, r1 - r0).expect("band rays"))
            })
            .collect::<Vec<_>>()
    });
    table.row(&format!("  four bands of {} rows", size / bands), t, false);
}

/// The transfer table as each of vtkCylVolMapper's bands samples it: functions of 1,024
/// points (the mapper's colour and opacity tables) into 4,096 entries (four an interval, as
/// `cylvol_render` sizes it when the tables span the data range).
fn transfer_table(repeats: usize) {
    const POINTS: usize = 1024;
    const ENTRIES: usize = 4096;
    let at = |k: usize| k as f64 / (POINTS - 1) as f64;
    let tf = TransferFunction {
        color: (0..POINTS)
            .map(|k| (at(k), [at(k), 0.5, 1.0 - at(k)]))
            .collect(),
        opacity: (0..POINTS).map(|k| (at(k), 0.5 * at(k) * at(k))).collect(),
        unit_distance: 0.1,
    };
    let ((wall, _), _) = best(repeats.max(20), || tf.table(0.0, 1.0, 0.01, ENTRIES));
    println!(
        "  transfer table ({POINTS}-point functions, {ENTRIES} entries), not counted: {:.2} ms",
        wall * 1e3
    );
}

/// The set-up as the VTK mapper runs it, through the C ABI from arrays laid out as VTK's
/// (`f64` points, `i64` offsets and connectivity, cell types, `f64` point scalars):
/// `cylvol_mesh_new`, `cylvol_mesh_set_scalars`, `cylvol_volume_new`. The rows above less
/// these show what the ABI adds (conversions and copies).
fn c_abi(mesh: &Mesh, repeats: usize) {
    use cylvol::ffi::*;
    use std::ptr::null_mut;
    let Some((Association::Point, values)) = mesh.active_scalars() else {
        println!("  (C ABI rows need point scalars)");
        return;
    };
    let points: Vec<f64> = mesh.points().iter().flat_map(|p| p.to_array()).collect();
    let offsets: Vec<i64> = std::iter::once(0)
        .chain(mesh.vtk_cell_ends())
        .map(|end| end as i64)
        .collect();
    let connectivity: Vec<i64> = mesh.vtk_connectivity().map(i64::from).collect();
    let types: Vec<u8> = mesh.vtk_cell_types().collect();
    println!("  C ABI, as the VTK mapper calls it:");
    let mut table = Table::default();
    let mesh_new = || {
        let mut m = null_mut();
        // SAFETY: the arrays are as long as the counts say; `m` is written.
        let status = unsafe {
            cylvol_mesh_new(
                points.as_ptr().cast(),
                CylvolValueType::F64.into(),
                mesh.point_count(),
                offsets.as_ptr().cast(),
                connectivity.as_ptr().cast(),
                CylvolIndexType::I64.into(),
                connectivity.len(),
                types.as_ptr(),
                types.len(),
                &mut m,
            )
        };
        assert_eq!(status, CylvolStatus::Ok);
        m
    };
    let set_scalars = |m: *mut CylvolMesh| {
        // SAFETY: `m` is live; the values are one a point.
        let status = unsafe {
            cylvol_mesh_set_scalars(
                m,
                c"s".as_ptr(),
                CylvolAssociation::POINT_DATA.into(),
                values.as_ptr().cast(),
                CylvolValueType::F64.into(),
                values.len(),
                1,
                0,
            )
        };
        assert_eq!(status, CylvolStatus::Ok);
    };
    let free_mesh = |m: *mut CylvolMesh| unsafe { cylvol_mesh_free(m) };
    let (t, _) = best(repeats, || free_mesh(mesh_new()));
    table.row("  cylvol_mesh_new", t, true);
    let m = mesh_new();
    let (t, _) = best(repeats, || set_scalars(m));
    table.row("  cylvol_mesh_set_scalars", t, true);
    let (t, _) = best(repeats, || {
        let mut params = CylvolBuildParams::default();
        // SAFETY: `params` is written.
        unsafe { cylvol_build_params_default(&mut params) };
        let mut v = null_mut();
        // SAFETY: `m` is live; `v` is written, then freed.
        let status = unsafe { cylvol_volume_new(m, &params, &mut v) };
        assert_eq!(status, CylvolStatus::Ok);
        unsafe { cylvol_volume_free(v) };
    });
    table.row("  cylvol_volume_new", t, true);
    free_mesh(m);
    table.row("  set-up through the C ABI in all", table.total, false);
}

/// The printed rows and the sum of those counted in the totals.
#[derive(Default)]
struct Table {
    total: (f64, f64),
}

impl Table {
    fn row(&mut self, name: &str, (wall, cpu): (f64, f64), counted: bool) {
        if counted {
            self.total.0 += wall;
            self.total.1 += cpu;
        }
        println!("  {name:<36} {wall:>8.3} {cpu:>8.2}");
    }
}
