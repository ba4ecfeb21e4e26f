//! `cylvol gen INPUT [--refine N] [--periodic auto|N [--copies K0:K1]] -o FILE`: writes a
//! synthetic dataset, or any mesh it can read, as legacy VTK or VTU, optionally with every
//! hexahedron cut into `N × N × N` ([`cylvol::Mesh::refined`]), e.g. the OpenFOAM mixer
//! refined to 2.15 M cells, and optionally as the wheel of a periodic sector's copies
//! ([`cylvol::axis::periodic::replicate`]).

use std::path::PathBuf;
use std::time::Instant;

use super::log;
use cylvol::input::Input;
use cylvol::Error;

/// Arguments of `cylvol gen`.
#[derive(clap::Args, Debug)]
pub struct GenArgs {
    /// Dataset NAME[:CELLS] (pump-inlet, pump-rotor or pump-diffuser) or a mesh file (.vtk,
    /// .vtu, .pvtu, PLOT3D *xyz.bin).
    spec: String,
    /// Output file: .vtk (legacy binary) or .vtu.
    #[arg(short, long, value_name = "FILE")]
    output: PathBuf,
    /// Cut every hexahedron into N × N × N (1 to 16; hexahedral meshes only): the same
    /// geometry and fields with N³ times the cells.
    #[arg(long, value_name = "N", default_value_t = 1, value_parser = parse_refinement, allow_hyphen_values = true)]
    refine: u32,
    /// Write the wheel that copies of a rotationally periodic sector make (`auto`, or N
    /// copies each turned by 360°/N, vectors turned with them), as VTK's angular periodic
    /// filter does; `off` writes the mesh as it is.
    #[command(flatten)]
    periodic: super::periodic::PeriodicArgs,
    /// The machine's axis the copies turn about (`x`, `y`, `z` or `ox,oy,oz:dx,dy,dz`;
    /// default: detected).
    #[arg(long, value_name = "AXIS")]
    axis: Option<cylvol::axis::Axis>,
}

/// Parses `--refine N`, 1 to [`cylvol::mesh::MAX_REFINEMENT`].
fn parse_refinement(s: &str) -> Result<u32, String> {
    let max = cylvol::mesh::MAX_REFINEMENT;
    super::number::whole_in(s, "refinement", 1, max.into()).map(|n| n as u32)
}

pub fn run(args: &GenArgs) -> Result<(), Error> {
    // An output we cannot write is refused before anything is generated.
    cylvol::io::writer_for(&args.output)?;
    super::output::check_folder("-o", &args.output)?;
    let input = Input::parse(&args.spec)?;
    let started = Instant::now();
    let mesh = input.load_logged(&Default::default(), &mut |note| log(format_args!("{note}")))?;
    let verb = match input {
        Input::Synthetic(..) => "generated",
        Input::File(_) => "read",
    };
    log(format_args!(
        "{verb} {}: {} cells, {} points in {:.2} s",
        input.label(),
        mesh.cell_count(),
        mesh.point_count(),
        started.elapsed().as_secs_f64()
    ));
    let mesh = if args.refine == 1 {
        mesh
    } else {
        let started = Instant::now();
        let fine = mesh.refined(args.refine)?;
        log(format_args!(
            "refined by {}: {} cells, {} points in {:.2} s",
            args.refine,
            fine.cell_count(),
            fine.point_count(),
            started.elapsed().as_secs_f64()
        ));
        fine
    };
    let axis = args.axis.unwrap_or_else(|| cylvol::axis::detect(&mesh));
    let mesh = match args.periodic.copies(&mesh, &axis)? {
        None => mesh,
        Some(copies) => {
            let started = Instant::now();
            let wheel =
                cylvol::axis::periodic::replicate(&mesh, copies.periodicity(), copies.range())?;
            log(format_args!(
                "{} copies: {} cells, {} points in {:.2} s",
                copies.count(),
                wheel.cell_count(),
                wheel.point_count(),
                started.elapsed().as_secs_f64()
            ));
            wheel
        }
    };
    let started = Instant::now();
    cylvol::io::write_file(&mesh, &args.output)?;
    log(format_args!(
        "wrote {} in {:.2} s",
        args.output.display(),
        started.elapsed().as_secs_f64()
    ));
    Ok(())
}
