//! Features of labelled readings: what training, validation and testing take.

use rayon::prelude::*;

use crate::dataset::{Dataset, Reading};
use crate::describe::{Descriptor, Feature};
use crate::recognize::RecognizeError;

/// Per object (in `objects` order), per reading, that reading's features `d(I)`.
#[derive(Debug, Clone, PartialEq)]
pub struct LabelledFeatures {
    objects: Vec<String>,
    readings: Vec<Vec<Vec<Feature>>>,
}

impl LabelledFeatures {
    /// `readings[j]` are the readings of `objects[j]`; names must be distinct.
    pub fn new(objects: Vec<String>, readings: Vec<Vec<Vec<Feature>>>) -> Result<Self, RecognizeError> {
        if objects.len() != readings.len() {
            return Err(RecognizeError::InvalidParameter {
                name: "readings",
                what: format!("{} objects but {} reading lists", objects.len(), readings.len()),
            });
        }
        if let Some(i) = (0..objects.len()).find(|&i| objects[..i].contains(&objects[i])) {
            return Err(RecognizeError::InvalidParameter {
                name: "objects",
                what: format!("'{}' is listed twice", objects[i]),
            });
        }
        Ok(Self { objects, readings })
    }

    /// Describes the [`Converged`](crate::dataset::ContactStatus::Converged) readings of `dataset`
    /// (the only ones recognition uses), in parallel, keeping dataset order within each object.
    pub fn from_dataset(dataset: &Dataset, descriptor: &dyn Descriptor) -> Self {
        let readings = dataset
            .by_object()
            .into_iter()
            .map(|group| {
                let converged: Vec<&Reading> = group.into_iter().filter(|r| r.is_converged()).collect();
                converged
                    .par_iter()
                    .map(|r| descriptor.describe(&r.image))
                    .collect()
            })
            .collect();
        Self {
            objects: dataset.header().objects.clone(),
            readings,
        }
    }

    pub fn objects(&self) -> &[String] {
        &self.objects
    }

    /// The readings of object `j`, each a list of features.
    pub fn readings(&self, j: usize) -> &[Vec<Feature>] {
        &self.readings[j]
    }

    /// Total number of readings.
    pub fn reading_count(&self) -> usize {
        self.readings.iter().map(Vec::len).sum()
    }

    /// Every feature, object by object, reading by reading.
    pub fn features(&self) -> impl Iterator<Item = &Feature> {
        self.readings.iter().flatten().flatten()
    }

    /// Splits off the last `fraction` of each object's readings (at least one, leaving at least
    /// one) as a validation set: the paper's 1000 + 100 sampler readings per object (Sec. V-B)
    /// are `fraction = 1/11`.
    pub fn split_validation(
        &self,
        fraction: f64,
    ) -> Result<(LabelledFeatures, LabelledFeatures), RecognizeError> {
        if !(fraction > 0.0 && fraction < 1.0) {
            return Err(RecognizeError::InvalidParameter {
                name: "holdout",
                what: format!("{fraction} is not a fraction in (0, 1)"),
            });
        }
        let mut train = Vec::with_capacity(self.objects.len());
        let mut validation = Vec::with_capacity(self.objects.len());
        for (name, readings) in self.objects.iter().zip(&self.readings) {
            let n = readings.len();
            if n < 2 {
                return Err(RecognizeError::InvalidParameter {
                    name: "holdout",
                    what: format!(
                        "object '{name}' has {n} converged readings; holding out a validation set needs at least 2"
                    ),
                });
            }
            let held = ((n as f64 * fraction).round() as usize).clamp(1, n - 1);
            train.push(readings[..n - held].to_vec());
            validation.push(readings[n - held..].to_vec());
        }
        Ok((
            Self {
                objects: self.objects.clone(),
                readings: train,
            },
            Self {
                objects: self.objects.clone(),
                readings: validation,
            },
        ))
    }
}
