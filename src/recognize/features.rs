//! Feature vectors gathered into a matrix whose shape and finiteness are checked once, at the edge.

use nalgebra::DMatrix;

use crate::describe::Feature;
use crate::recognize::RecognizeError;

/// `rows` features of `dim` finite values each, row-major. Non-empty: `rows >= 1`, `dim >= 1`.
#[derive(Debug, Clone, PartialEq)]
pub struct FeatureMatrix {
    rows: usize,
    dim: usize,
    data: Vec<f64>,
}

impl FeatureMatrix {
    /// Stacks `features`; `origin` names them in errors (e.g. "the training set").
    pub fn from_features<'a>(
        features: impl IntoIterator<Item = &'a Feature>,
        origin: &str,
    ) -> Result<Self, RecognizeError> {
        let mut data = Vec::new();
        let mut dim = None;
        let mut rows = 0;
        for (index, f) in features.into_iter().enumerate() {
            let expected = *dim.get_or_insert(f.len());
            check_feature(f, expected, origin, index)?;
            data.extend_from_slice(f);
            rows += 1;
        }
        match dim {
            None => Err(RecognizeError::NoFeatures(format!("{origin} has no features"))),
            Some(0) => Err(RecognizeError::NoFeatures(format!(
                "{origin} has features of zero length"
            ))),
            Some(dim) => Ok(Self { rows, dim, data }),
        }
    }

    /// Number of features.
    pub fn rows(&self) -> usize {
        self.rows
    }

    /// Values per feature.
    pub fn dim(&self) -> usize {
        self.dim
    }

    /// Feature `i`.
    pub fn row(&self, i: usize) -> &[f64] {
        &self.data[i * self.dim..(i + 1) * self.dim]
    }

    pub fn iter_rows(&self) -> impl ExactSizeIterator<Item = &[f64]> {
        self.data.chunks_exact(self.dim)
    }

    /// Row-major values.
    pub fn as_slice(&self) -> &[f64] {
        &self.data
    }

    /// The `rows x dim` matrix for linear algebra (nalgebra stores it column-major).
    pub fn to_dmatrix(&self) -> DMatrix<f64> {
        DMatrix::from_row_slice(self.rows, self.dim, &self.data)
    }

    /// Wraps row-major values already known to be finite and `rows x dim`, rows >= 1, dim >= 1.
    pub(crate) fn from_trusted(rows: usize, dim: usize, data: Vec<f64>) -> Self {
        debug_assert!(rows >= 1 && dim >= 1 && data.len() == rows * dim);
        Self { rows, dim, data }
    }
}

/// Checks that `f` has `expected` finite values.
pub fn check_feature(f: &[f64], expected: usize, origin: &str, index: usize) -> Result<(), RecognizeError> {
    if f.len() != expected {
        return Err(RecognizeError::FeatureDimension {
            origin: origin.to_string(),
            index,
            got: f.len(),
            expected,
        });
    }
    if let Some((position, &value)) = f.iter().enumerate().find(|(_, v)| !v.is_finite()) {
        return Err(RecognizeError::NonFiniteFeature {
            origin: origin.to_string(),
            index,
            position,
            value,
        });
    }
    Ok(())
}

/// The training features a codebook is fitted on: PCA-reduced, row `r` from object `objects[r]`'s
/// reading `readings[r]` (the neighbour codebook needs both; the clusterings ignore them).
#[derive(Debug, Clone, Copy)]
pub struct TrainingFeatures<'a> {
    pub data: &'a FeatureMatrix,
    pub objects: &'a [u32],
    pub object_count: usize,
    pub readings: &'a [u32],
}
