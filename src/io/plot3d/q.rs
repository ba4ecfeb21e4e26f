//! The Q (solution) file's body: four floats (free-stream Mach number, angle of attack,
//! Reynolds number, time), then five blocks of one value per point (i fastest): density,
//! x, y and z momentum, stagnation energy per unit volume.

use super::detect::{FileKind, Layout};
use super::floats;
use crate::error::Error;
use crate::mesh::DataArray;

/// The point arrays a Q file gives: `Density`, `Momentum` (3 components) and
/// `StagnationEnergy`, named as VTK's `vtkMultiBlockPLOT3DReader` names them.
pub(super) fn read_solution(bytes: &[u8], layout: &Layout) -> Result<Vec<DataArray>, Error> {
    let kind = FileKind::Solution;
    let n = layout.points();
    let s = layout.precision.bytes();
    // The four free-stream values are not used, but must be there.
    let _conditions = floats(bytes, layout.data_offset, 4, layout, kind)?;
    let mut pos = layout.data_offset + 4 * s;
    if layout.record_markers {
        pos += 8; // the header record's end marker and the data record's start marker
    }
    let mut block = || -> Result<Vec<f64>, Error> {
        let values = floats(bytes, pos, n, layout, kind)?;
        pos += n * s;
        Ok(values)
    };
    let density = block()?;
    let mx = block()?;
    let my = block()?;
    let mz = block()?;
    let energy = block()?;
    let momentum = mx
        .iter()
        .zip(&my)
        .zip(&mz)
        .flat_map(|((&x, &y), &z)| [x, y, z])
        .collect();
    Ok(vec![
        DataArray::scalar("Density", density),
        DataArray::vector("Momentum", momentum),
        DataArray::scalar("StagnationEnergy", energy),
    ])
}
