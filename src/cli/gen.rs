//! `cylvol gen NAME[:CELLS] -o FILE`: writes a synthetic dataset as legacy VTK or VTU.

use std::path::PathBuf;
use std::time::Instant;

use super::log;
use cylvol::input::Input;
use cylvol::Error;

/// Arguments of `cylvol gen`.
#[derive(clap::Args, Debug)]
pub struct GenArgs {
    /// Dataset NAME[:CELLS]: pump-inlet, pump-rotor or pump-diffuser.
    spec: String,
    /// Output file: .vtk (legacy binary) or .vtu.
    #[arg(short, long, value_name = "FILE")]
    output: PathBuf,
}

pub fn run(args: &GenArgs) -> Result<(), Error> {
    let Input::Synthetic(dataset, cells) = Input::parse(&args.spec)? else {
        return Err(Error::Invalid(format!(
            "'{}' is not a dataset name (pump-inlet, pump-rotor, pump-diffuser, optionally :CELLS)",
            args.spec
        )));
    };
    let started = Instant::now();
    let mesh = cylvol::datasets::generate(dataset, cells)?;
    log(format_args!(
        "generated {}: {} cells, {} points in {:.2} s",
        dataset.name(),
        mesh.cell_count(),
        mesh.point_count(),
        started.elapsed().as_secs_f64()
    ));
    let started = Instant::now();
    cylvol::io::write_file(&mesh, &args.output)?;
    log(format_args!(
        "wrote {} in {:.2} s",
        args.output.display(),
        started.elapsed().as_secs_f64()
    ));
    Ok(())
}
