//! VTK's empty cells ([`crate::mesh::VTK_EMPTY_CELL`]: no points, no volume), which VTK
//! writes where the blanked cells of a structured grid become an unstructured grid's
//! (`vtkAppendFilter`, ParaView's Merge Blocks): the cell conversion leaves them out
//! ([`crate::mesh::ConvertedCells::empty`]), and the readers drop their cell data tuples with
//! them and say so. VTK keeps them as cells that draw nothing.

use crate::mesh::DataArray;

/// Removes from each array of `tuples` tuples the tuples at `removed` (increasing indices);
/// an array of another length is left for the validation to report.
pub(crate) fn drop_tuples(arrays: &mut [DataArray], removed: &[usize], tuples: usize) {
    if removed.is_empty() {
        return;
    }
    let mut keep = vec![true; tuples];
    for &r in removed {
        if let Some(k) = keep.get_mut(r) {
            *k = false;
        }
    }
    for a in arrays {
        if a.components > 0 && a.values.len() == tuples * a.components {
            a.values = a
                .values
                .chunks_exact(a.components)
                .zip(&keep)
                .filter(|(_, &k)| k)
                .flat_map(|(v, _)| v.iter().copied())
                .collect();
        }
    }
}

/// What a user is told of `count` empty cells dropped (`None` for none).
pub(crate) fn note(count: usize) -> Option<String> {
    (count > 0).then(|| {
        format!(
            "{} dropped (VTK type 0, without points, as blanked cells become in an \
             unstructured grid) with their cell data",
            cells_were(count, "empty")
        )
    })
}

/// `1 empty cell was`, `3 empty cells were`.
pub(crate) fn cells_were(count: usize, what: &str) -> String {
    if count == 1 {
        format!("1 {what} cell was")
    } else {
        format!("{count} {what} cells were")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_tuples_of_dropped_cells_go_and_other_lengths_stay() {
        let mut arrays = vec![
            DataArray::scalar("c", vec![0.0, 1.0, 2.0, 3.0]),
            DataArray::vector("v", (0..12).map(f64::from).collect()),
            DataArray::scalar("short", vec![1.0; 3]),
        ];
        drop_tuples(&mut arrays, &[1, 2], 4);
        assert_eq!(arrays[0].values, [0.0, 3.0]);
        assert_eq!(arrays[1].values, [0.0, 1.0, 2.0, 9.0, 10.0, 11.0]);
        assert_eq!(arrays[2].values.len(), 3);
        assert_eq!(note(0), None);
    }
}
