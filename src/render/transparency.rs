//! Which cells the transfer function leaves wholly transparent: one bit a cell, so that the
//! fast path's per-sample question "can this cell contribute at all?" is a load from a few
//! hundred kilobytes (32 k cells a cache line) rather than a look-up of the cell's scalar
//! range (16 bytes a cell) and two table positions.
//!
//! A cell is transparent when every scalar its corners span maps to zero opacity
//! ([`TransferTable::transparent_over`] of its range), the same test a look-up of the cell's
//! range would make, so the mask changes the work, never the image.

use rayon::prelude::*;

use super::transfer::TransferTable;

/// One bit per cell: set where the transfer table makes the cell wholly transparent.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub(crate) struct TransparentCells {
    bits: Vec<u64>,
    len: usize,
}

/// Cells a word of the mask covers.
const WORD: usize = 64;

impl TransparentCells {
    /// The mask of `ranges` (each cell's `[min, max]` scalar) under `table`, built in
    /// parallel.
    pub(crate) fn new(ranges: &[[f64; 2]], table: &TransferTable) -> TransparentCells {
        TransparentCells {
            bits: ranges
                .par_chunks(WORD)
                .map(|chunk| word(chunk, table))
                .collect(),
            len: ranges.len(),
        }
    }

    /// [`TransparentCells::new`] on the calling thread only (for a lazily made mask, whose
    /// builder must not wait on work the thread pool might hand back to it).
    pub(crate) fn new_sequential(ranges: &[[f64; 2]], table: &TransferTable) -> TransparentCells {
        TransparentCells {
            bits: ranges
                .chunks(WORD)
                .map(|chunk| word(chunk, table))
                .collect(),
            len: ranges.len(),
        }
    }

    /// Whether `cell` is wholly transparent; `false` for a cell out of range.
    #[inline]
    pub(crate) fn contains(&self, cell: u32) -> bool {
        let c = cell as usize;
        c < self.len && (self.bits[c / WORD] >> (c % WORD)) & 1 == 1
    }

    /// Number of cells covered.
    #[cfg(test)]
    pub(crate) fn len(&self) -> usize {
        self.len
    }

    /// Whether the mask covers no cell.
    #[cfg(test)]
    pub(crate) fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// Number of transparent cells.
    #[cfg(test)]
    pub(crate) fn count(&self) -> usize {
        self.bits.iter().map(|w| w.count_ones() as usize).sum()
    }
}

/// The bits of up to 64 cells.
fn word(chunk: &[[f64; 2]], table: &TransferTable) -> u64 {
    chunk
        .iter()
        .enumerate()
        .filter(|(_, &[a, b])| table.transparent_over(a, b))
        .fold(0u64, |w, (i, _)| w | (1u64 << i))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::TransferFunction;

    #[test]
    fn a_cell_is_transparent_where_the_table_is_over_its_range() {
        // Opacity zero over the lowest quarter of the range, positive above.
        let tf = TransferFunction::default_for_range(0.0, 1.0, 0.5, 1.0);
        let table = tf.table(0.0, 1.0, 1.0, 256).unwrap();
        let ranges = [[0.0, 0.0], [0.2, 0.9], [1.0, 1.0]];
        let mask = TransparentCells::new(&ranges, &table);
        assert_eq!(mask.len(), 3);
        for (c, [a, b]) in ranges.iter().enumerate() {
            assert_eq!(mask.contains(c as u32), table.transparent_over(*a, *b));
        }
        assert!(!mask.contains(3)); // out of range: not known to be transparent
    }

    #[test]
    fn mask_agrees_with_the_table_across_word_boundaries() {
        let tf = TransferFunction::default_for_range(0.0, 1.0, 0.5, 1.0);
        let table = tf.table(0.0, 1.0, 1.0, 256).unwrap();
        // 200 cells (three full words and a partial one), ranges sweeping the threshold.
        let ranges: Vec<[f64; 2]> = (0..200)
            .map(|i| {
                let a = (i % 17) as f64 / 51.0;
                [a, a + (i % 5) as f64 * 0.05]
            })
            .collect();
        let mask = TransparentCells::new(&ranges, &table);
        let sequential = TransparentCells::new_sequential(&ranges, &table);
        assert_eq!(mask, sequential);
        let expected: Vec<bool> = ranges
            .iter()
            .map(|&[a, b]| table.transparent_over(a, b))
            .collect();
        assert!(expected.iter().any(|&t| t) && expected.iter().any(|&t| !t));
        for (c, &e) in expected.iter().enumerate() {
            assert_eq!(mask.contains(c as u32), e, "cell {c}");
        }
        assert_eq!(mask.count(), expected.iter().filter(|&&t| t).count());
        assert!(!mask.contains(200) && !mask.contains(u32::MAX));
        assert!(TransparentCells::new(&[], &table).is_empty());
    }
}
