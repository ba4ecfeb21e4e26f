//! Renders a mesh file (or a synthetic dataset) to a PNG with the cylvol library: load it, find
//! the machine's axis, build the structure `auto` chooses about it, and ray-cast one frame.
//!
//! cargo run --release --example render_mesh -- tests/data/mixer.vtk mixer.png

use cylvol::accel::{choose::auto_structure, Accel, AccelParams};
use cylvol::io::ReadOptions;
use cylvol::render::{
    default_step, face_neighbours, Camera, RenderOptions, Renderer, TransferFunction, Volume,
};

fn main() -> Result<(), cylvol::Error> {
    let args: Vec<String> = std::env::args().collect();
    let input = args.get(1).map_or("tests/data/mixer.vtk", String::as_str);
    let output = args.get(2).map_or("mesh.png", String::as_str);

    // A file (.vtk, .vtu, .pvtu, PLOT3D) or a dataset such as `pump-rotor:200000`.
    let mesh = cylvol::input::load(input, &ReadOptions::default())?;
    let axis = cylvol::axis::detect(&mesh);
    let kind = auto_structure(&mesh, &axis);
    let accel = Accel::build(&mesh, kind, &axis, &AccelParams::default())?;

    let volume = Volume::new(&mesh, &accel)?;
    let [lo, hi] = volume.scalar_range();
    // Cool to warm, transparent over the lowest quarter of the range, opacity 0.3 per 1 % of
    // the diagonal at the top: `cylvol render`'s default.
    let [x0, x1, y0, y1, z0, z1] = mesh.bounds();
    let diagonal = ((x1 - x0).powi(2) + (y1 - y0).powi(2) + (z1 - z0).powi(2)).sqrt();
    let transfer = TransferFunction::default_for_range(lo, hi, 0.3, 0.01 * diagonal);
    let (width, height) = (400, 400);
    let options = RenderOptions::new(width, height, default_step(&mesh));
    // VTK's ResetCamera, then Azimuth(30), Elevation(20), Zoom(1).
    let camera = Camera::view(mesh.bounds(), width, height, 30.0, 20.0, 1.0);
    let topology = face_neighbours(&mesh, &accel);
    let renderer = Renderer::new(&volume, &transfer, &options)?.with_topology(&topology);
    let (image, stats) = renderer.render(&camera, None)?;
    image.write_png(std::path::Path::new(output), Some([0.0; 3]))?;
    println!(
        "{input}: {} cells, {kind}; {} samples, {} hexahedra tested; wrote {output}",
        mesh.cell_count(),
        stats.samples,
        stats.hex_tests
    );
    Ok(())
}
