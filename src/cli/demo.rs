//! `cylvol demo [--out DIR]`: the main job on the built-in default dataset.
//!
//! Today it generates the default dataset (`pump-rotor` at a demo size), describes it (counts,
//! scalars, detected axis) and writes it as VTU into `DIR`. The acceleration structures and the
//! ray caster, as they land, add their statistics and images here.

use std::path::PathBuf;
use std::time::Instant;

use super::log;
use cylvol::datasets::Dataset;
use cylvol::Error;

/// The dataset and size the demo uses.
pub const DEMO_DATASET: Dataset = Dataset::PumpRotor;
/// Cells in the demo's dataset: large enough to be a real mesh, small enough for seconds.
pub const DEMO_CELLS: usize = 400_000;

/// Arguments of `cylvol demo`.
#[derive(clap::Args, Debug)]
pub struct DemoArgs {
    /// Folder for the demo's outputs (created if missing).
    #[arg(long, value_name = "DIR", default_value = "cylvol-demo")]
    out: PathBuf,
}

pub fn run(args: &DemoArgs) -> Result<(), Error> {
    std::fs::create_dir_all(&args.out).map_err(|source| Error::Io {
        path: args.out.clone(),
        source,
    })?;
    let started = Instant::now();
    let mesh = cylvol::datasets::generate(DEMO_DATASET, DEMO_CELLS)?;
    log(format_args!(
        "generated {}:{}: {} cells in {:.2} s",
        DEMO_DATASET.name(),
        DEMO_CELLS,
        mesh.cell_count(),
        started.elapsed().as_secs_f64()
    ));
    let detection = cylvol::axis::detect_with_report(&mesh);
    let info = super::info::describe(&mesh, detection.axis, Some(detection.clear));
    let text = serde_json::to_string_pretty(&info)
        .map_err(|e| Error::Invalid(format!("JSON output failed: {e}")))?;
    println!("{text}");
    let path = args.out.join(format!("{}.vtu", DEMO_DATASET.name()));
    cylvol::io::write_file(&mesh, &path)?;
    log(format_args!(
        "wrote {} ({} s in all)",
        path.display(),
        format_args!("{:.2}", started.elapsed().as_secs_f64())
    ));
    Ok(())
}
