//! A trial (Sec. V-B2): consecutive readings of one object, given to the recogniser one at a time.
//! Below both the recogniser's evaluation and its calibration, which fits the tempering on the
//! trials' evidence paths.

use crate::describe::Feature;
use crate::recognize::RecognizeError;
use crate::recognize::labelled::LabelledFeatures;

/// Consecutive readings of one object, given to the recogniser one at a time. A reading is its
/// features (`R = Vec<Feature>`), or for a fused recogniser one feature list per descriptor.
#[derive(Debug, Clone, PartialEq)]
pub struct Trial<R = Vec<Feature>> {
    /// The true object, as an index of the model's objects.
    pub object: usize,
    /// Each reading's features.
    pub readings: Vec<R>,
}

/// Splits each object's readings, in order, into trials of `readings_per_trial` consecutive
/// readings (the last trial of an object may be shorter); an object of the data with no reading at
/// all (the exploration never read it) is one trial with no readings, which
/// [`evaluate`](crate::recognize::evaluate()) counts as a miss. Objects are matched to `model_objects` by name; one the model does not know is an
/// error.
pub fn make_trials(
    data: &LabelledFeatures,
    model_objects: &[String],
    readings_per_trial: usize,
) -> Result<Vec<Trial>, RecognizeError> {
    if readings_per_trial == 0 {
        return Err(RecognizeError::InvalidParameter {
            name: "readings per trial",
            what: "must be at least 1".into(),
        });
    }
    let mut trials = Vec::new();
    for (j, name) in data.objects().iter().enumerate() {
        let object =
            model_objects
                .iter()
                .position(|o| o == name)
                .ok_or_else(|| RecognizeError::UnknownObject {
                    object: name.clone(),
                    known: model_objects.to_vec(),
                })?;
        if data.readings(j).is_empty() {
            trials.push(Trial {
                object,
                readings: Vec::new(),
            });
        }
        for chunk in data.readings(j).chunks(readings_per_trial) {
            trials.push(Trial {
                object,
                readings: chunk.to_vec(),
            });
        }
    }
    Ok(trials)
}
