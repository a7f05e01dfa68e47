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
    /// Per object, per reading, the contact it is one frame of (`Reading::contact`): a held-out
    /// validation set takes whole contacts.
    contacts: Vec<Vec<Option<u32>>>,
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
        let contacts = readings.iter().map(|r| vec![None; r.len()]).collect();
        Ok(Self {
            objects,
            readings,
            contacts,
        })
    }

    /// Describes the [`Converged`](crate::dataset::ContactStatus::Converged) readings of `dataset`
    /// (the only ones recognition uses), in parallel, keeping dataset order within each object.
    pub fn from_dataset(dataset: &Dataset, descriptor: &dyn Descriptor) -> Self {
        let converged: Vec<Vec<&Reading>> = dataset
            .by_object()
            .into_iter()
            .map(|group| group.into_iter().filter(|r| r.is_converged()).collect())
            .collect();
        let readings = converged
            .iter()
            .map(|group| group.par_iter().map(|r| descriptor.describe(&r.image)).collect())
            .collect();
        let contacts = converged
            .iter()
            .map(|group| group.iter().map(|r| r.contact).collect())
            .collect();
        Self {
            objects: dataset.header().objects.clone(),
            readings,
            contacts,
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
    /// are `fraction = 1/11`. A contact's frames stay on one side: the cut moves back to the
    /// start of the contact it would cut (or forward past it when that leaves no training
    /// reading), so validation never scores a press the model was trained on.
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
        let empty = || Self {
            objects: self.objects.clone(),
            readings: Vec::with_capacity(self.objects.len()),
            contacts: Vec::with_capacity(self.objects.len()),
        };
        let (mut train, mut validation) = (empty(), empty());
        for ((name, readings), contacts) in self.objects.iter().zip(&self.readings).zip(&self.contacts) {
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
            let cut = contact_edge(contacts, n - held).ok_or_else(|| RecognizeError::InvalidParameter {
                name: "holdout",
                what: format!(
                    "object '{name}' has its {n} converged readings in one contact; holding out a validation set needs at least 2 contacts"
                ),
            })?;
            train.readings.push(readings[..cut].to_vec());
            train.contacts.push(contacts[..cut].to_vec());
            validation.readings.push(readings[cut..].to_vec());
            validation.contacts.push(contacts[cut..].to_vec());
        }
        Ok((train, validation))
    }
}

/// The cut nearest below `at` (else above it) that splits no contact and leaves readings on both
/// sides, if any: readings `i - 1` and `i` of one contact are never cut apart.
fn contact_edge(contacts: &[Option<u32>], at: usize) -> Option<usize> {
    let inside = |i: usize| contacts[i].is_some() && contacts[i - 1] == contacts[i];
    let below = (1..=at).rev().find(|&i| !inside(i));
    let above = (at..contacts.len()).find(|&i| !inside(i));
    below.or(above)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Two objects of ten readings each, one feature a reading holding its index; `contacts[j]`
    /// the contact of each of object `j`'s readings.
    fn features(contacts: [Vec<Option<u32>>; 2]) -> LabelledFeatures {
        let readings = (0..2)
            .map(|j| (0..10).map(|i| vec![vec![(10 * j + i) as f64]]).collect())
            .collect();
        LabelledFeatures {
            contacts: contacts.to_vec(),
            ..LabelledFeatures::new(vec!["a".into(), "b".into()], readings).unwrap()
        }
    }

    fn first_held(part: &LabelledFeatures, j: usize) -> f64 {
        part.readings(j)[0][0][0]
    }

    #[test]
    fn a_held_out_validation_set_takes_whole_contacts() {
        let own = vec![None; 10];
        // Readings 7-9 of `a` one press: the cut at 8 (a fifth held) moves back to 7.
        let pressed = (0..10).map(|i| Some(if i < 7 { i } else { 7 })).collect();
        let (train, validation) = features([pressed, own.clone()]).split_validation(0.2).unwrap();
        assert_eq!((train.readings(0).len(), first_held(&validation, 0)), (7, 7.0));
        assert_eq!((train.readings(1).len(), first_held(&validation, 1)), (8, 18.0));
        assert_eq!(
            validation.contacts[0],
            vec![Some(7); 3],
            "the contacts go with their readings"
        );
        // Readings 0-8 one press: nothing below it to cut at, so the cut moves past it.
        let long = (0..10).map(|i| Some(u32::from(i == 9))).collect();
        let (train, validation) = features([long, own.clone()]).split_validation(0.2).unwrap();
        assert_eq!((train.readings(0).len(), validation.readings(0).len()), (9, 1));
        // One press holds every reading: nothing to hold out.
        let e = features([vec![Some(0); 10], own])
            .split_validation(0.2)
            .unwrap_err();
        assert!(
            e.to_string()
                .contains("object 'a' has its 10 converged readings in one contact"),
            "{e}"
        );
    }
}
