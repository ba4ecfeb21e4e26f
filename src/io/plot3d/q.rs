//! The Q (solution) file's body: for each grid, four floats (free-stream Mach number, angle
//! of attack, Reynolds number, time), then five blocks of one value per point (i fastest):
//! density, x, y and z momentum, stagnation energy per unit volume.

use super::detect::{FileKind, Layout};
use super::floats;
use crate::error::Error;
use crate::mesh::DataArray;

/// The point arrays a Q file gives, every grid's values after the one before's: `Density`,
/// `Momentum` (3 components) and `StagnationEnergy`, named as VTK's
/// `vtkMultiBlockPLOT3DReader` names them.
pub(super) fn read_solution(bytes: &[u8], layout: &Layout) -> Result<Vec<DataArray>, Error> {
    let kind = FileKind::Solution;
    let s = layout.precision.bytes();
    let total = layout.points();
    let mut density = Vec::with_capacity(total);
    let mut momentum = Vec::with_capacity(3 * total);
    let mut energy = Vec::with_capacity(total);
    let mut pos = layout.data_offset;
    for dims in &layout.grids {
        let n: usize = dims.iter().product();
        // The four free-stream values are not used, but must be there.
        let _conditions = floats(bytes, pos, 4, layout, kind)?;
        pos += 4 * s;
        if layout.record_markers {
            pos += 8; // the header record's end marker and the data record's start marker
        }
        let mut block = || -> Result<Vec<f64>, Error> {
            let values = floats(bytes, pos, n, layout, kind)?;
            pos += n * s;
            Ok(values)
        };
        density.extend(block()?);
        let mx = block()?;
        let my = block()?;
        let mz = block()?;
        energy.extend(block()?);
        momentum.extend(
            mx.iter()
                .zip(&my)
                .zip(&mz)
                .flat_map(|((&x, &y), &z)| [x, y, z]),
        );
        if layout.record_markers {
            pos += 8; // the data record's end marker and the next grid's start marker
        }
    }
    Ok(vec![
        DataArray::scalar("Density", density),
        DataArray::vector("Momentum", momentum),
        DataArray::scalar("StagnationEnergy", energy),
    ])
}
