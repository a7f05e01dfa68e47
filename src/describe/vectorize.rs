//! Vectorize (Sec. IV-B1): the image's columns concatenated. The "do-nothing" negative control: it
//! is not rotation-invariant, so any descriptor that is should beat it.
//!
//! ```text
//! v[c * rows + r] = I(r, c)
//! ```

use super::{Descriptor, DescriptorKind, DescriptorParams, Feature};
use crate::tactile::TactileImage;

/// Sec. IV-B1: one feature, `rows * cols` long, column after column.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Vectorize;

impl Descriptor for Vectorize {
    fn kind(&self) -> DescriptorKind {
        DescriptorKind::Vectorize
    }

    fn params(&self) -> DescriptorParams {
        DescriptorParams::Vectorize
    }

    fn describe(&self, image: &TactileImage) -> Vec<Feature> {
        vec![columns_concatenated(image.rows(), image.cols(), image.values())]
    }
}

/// The row-major `rows x cols` `values` as one column-major vector (also the last step of
/// Moment-Normalized, Sec. IV-B4).
pub fn columns_concatenated(rows: usize, cols: usize, values: &[f64]) -> Feature {
    debug_assert_eq!(values.len(), rows * cols);
    let mut out = Vec::with_capacity(rows * cols);
    for col in 0..cols {
        out.extend((0..rows).map(|row| values[row * cols + col]));
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn columns_come_one_after_the_other() {
        // 2 rows x 3 cols:  [a b c; d e f]  ->  a d b e c f
        let image = TactileImage::new(2, 3, vec![0.1, 0.2, 0.3, 0.4, 0.5, 0.6]).unwrap();
        assert_eq!(
            Vectorize.describe(&image),
            vec![vec![0.1, 0.4, 0.2, 0.5, 0.3, 0.6]]
        );
    }
}
