//! Argument parsing and dispatch of the `cylvol` subcommands, one file per subcommand.

/// `println!` that returns from the enclosing function with an error, instead of panicking,
/// where standard output cannot be written (a reader that closed the pipe, a full disk).
macro_rules! outln {
    () => {
        $crate::cli::write_out(format_args!("\n"))?
    };
    ($($arg:tt)*) => {
        $crate::cli::write_out(format_args!("{}\n", format_args!($($arg)*)))?
    };
}

mod accuracy;
mod bench;
mod camera;
mod demo;
mod gen;
mod info;
mod number;
mod output;
mod periodic;
mod render;
mod scene;
mod stats;
mod transfer;

use std::path::PathBuf;

use clap::{Parser, Subcommand};

/// Volume rendering of large hexahedral CFD meshes with cylindrical acceleration structures.
#[derive(Parser, Debug)]
#[command(name = "cylvol", version, about, long_about = None)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand, Debug)]
enum Command {
    /// Describe a mesh: counts, cell types, scalars, bounds and the detected machine axis.
    Info(info::InfoArgs),
    /// Build the four acceleration structures and report their size, with cyl ÷ cart ratios.
    Stats(stats::StatsArgs),
    /// Volume-render a mesh to a PNG image.
    Render(Box<render::RenderArgs>),
    /// Render with each structure, paper and fast paths, and report the work and times.
    Bench(bench::BenchArgs),
    /// Error against a converged reference, and time, as the sample step shrinks.
    Accuracy(accuracy::AccuracyArgs),
    /// Write a synthetic dataset or a mesh file, optionally refined (--refine N), to .vtk or .vtu.
    Gen(gen::GenArgs),
    /// The main job on the built-in default dataset.
    Demo(demo::DemoArgs),
}

/// Options every command that loads an `INPUT` shares.
#[derive(clap::Args, Debug, Clone)]
pub struct InputArgs {
    /// A mesh file (.vtk, .vtu, .pvtu, .vts, .pvts, PLOT3D *xyz.bin) or a dataset
    /// NAME[:CELLS], e.g. pump-rotor:200000.
    pub input: String,
    /// PLOT3D Q file to use instead of the one found beside the grid by name.
    #[arg(long = "q", value_name = "FILE")]
    pub q_file: Option<PathBuf>,
    /// Scalar array to use (`NAME`, `point:NAME`, `cell:NAME`, `NAME[k]` for a component).
    #[arg(long)]
    pub scalar: Option<String>,
    /// Machine axis instead of the detected one: `x`, `y`, `z`, or `ox,oy,oz:dx,dy,dz`.
    #[arg(long, value_name = "AXIS", allow_hyphen_values = true)]
    pub axis: Option<cylvol::axis::Axis>,
}

impl InputArgs {
    /// Loads the mesh and selects the requested scalar (a `--q` file for an input that is not
    /// a PLOT3D grid is refused by the reader, [`cylvol::io::read_file`]).
    pub fn load(&self) -> Result<cylvol::Mesh, cylvol::Error> {
        let options = cylvol::io::ReadOptions {
            q_file: self.q_file.clone(),
        };
        let started = std::time::Instant::now();
        let mut mesh = cylvol::input::Input::parse(&self.input)?
            .load_logged(&options, &mut |note| log(format_args!("{note}")))?;
        if let Some(name) = &self.scalar {
            mesh.set_active_scalar(name)?;
        }
        log(format_args!(
            "loaded {}: {} cells, {} points in {:.2} s",
            self.input,
            mesh.cell_count(),
            mesh.point_count(),
            started.elapsed().as_secs_f64()
        ));
        Ok(mesh)
    }

    /// The axis given with `--axis`, or the one detected in the mesh, and whether the latter is
    /// clear (`None` when given).
    pub fn axis(&self, mesh: &cylvol::Mesh) -> (cylvol::axis::Axis, Option<bool>) {
        match self.axis {
            Some(axis) => (axis, None),
            None => {
                let d = cylvol::axis::detect_with_report(mesh);
                (d.axis, Some(d.clear))
            }
        }
    }
}

/// Builds a structure and logs its size and build time.
pub fn build_logged(
    mesh: &cylvol::Mesh,
    kind: cylvol::accel::StructureKind,
    axis: &cylvol::axis::Axis,
    params: &cylvol::accel::AccelParams,
) -> Result<cylvol::accel::Accel, cylvol::Error> {
    let accel = cylvol::accel::Accel::build(mesh, kind, axis, params)?;
    let s = accel.stats();
    log(format_args!(
        "built {kind}: {} references, {:.1} MB, {:.2} s",
        s.references(),
        s.bytes() as f64 / 1e6,
        s.build_s()
    ));
    Ok(accel)
}

/// What [`write_out`]'s errors name as the file.
const STANDARD_OUTPUT: &str = "standard output";

/// Writes to standard output (through [`outln!`]).
pub fn write_out(args: std::fmt::Arguments<'_>) -> Result<(), cylvol::Error> {
    use std::io::Write;
    std::io::stdout()
        .lock()
        .write_fmt(args)
        .map_err(|source| cylvol::Error::Io {
            path: STANDARD_OUTPUT.into(),
            source,
        })
}

/// Writes a log line to standard error.
pub fn log(args: std::fmt::Arguments<'_>) {
    eprintln!("cylvol: {args}");
}

/// Parses the command line, runs the command and returns the process exit code.
pub fn run() -> i32 {
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Info(a) => info::run(&a),
        Command::Stats(a) => stats::run(&a),
        Command::Render(a) => render::run(&a),
        Command::Bench(a) => bench::run(&a),
        Command::Accuracy(a) => accuracy::run(&a),
        Command::Gen(a) => gen::run(&a),
        Command::Demo(a) => demo::run(&a),
    };
    match result {
        Ok(()) => 0,
        // The reader of our output is gone (`cylvol info --json | head`): stop without a
        // word, with the status a shell gives a program SIGPIPE ended.
        Err(cylvol::Error::Io { path, source })
            if path.as_os_str() == STANDARD_OUTPUT
                && source.kind() == std::io::ErrorKind::BrokenPipe =>
        {
            141
        }
        Err(e) => {
            eprintln!("cylvol: error: {e}");
            1
        }
    }
}
