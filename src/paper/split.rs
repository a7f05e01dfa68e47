//! The real-data division of Sec. V-E: per label, a random training / validation / testing split of
//! given sizes (the paper: 200, 50 and 100 readings per letter, repeated over 7 trials).

use std::collections::BTreeMap;

use rand::seq::SliceRandom;

use crate::rng;

/// Readings per label in each part.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct SplitSizes {
    pub train: usize,
    pub validation: usize,
    pub test: usize,
}

impl SplitSizes {
    /// Sec. V-E: 200 training, 50 validation, 100 testing readings per letter.
    pub const PAPER: SplitSizes = SplitSizes {
        train: 200,
        validation: 50,
        test: 100,
    };

    pub fn total(&self) -> usize {
        self.train + self.validation + self.test
    }
}

/// The three disjoint parts; within each, items keep their input order.
#[derive(Debug, Clone, PartialEq)]
pub struct Split<T> {
    pub train: Vec<T>,
    pub validation: Vec<T>,
    pub test: Vec<T>,
}

/// A label with too few items for the sizes asked.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("label '{label}' has {have} readings, the split needs {need} ({train} + {validation} + {test})")]
pub struct SplitError {
    pub label: String,
    pub have: usize,
    pub need: usize,
    pub train: usize,
    pub validation: usize,
    pub test: usize,
}

/// Splits `items` per label: for each label, its items are shuffled with the random stream
/// `rng::stream(seed, fnv1a(label))` (so a label's split does not depend on which other labels
/// exist) and the first `train`, next `validation` and next `test` are taken; leftovers are unused.
/// Each part then lists its items in input order. Same seed, same split.
pub fn split_per_label<T>(
    items: Vec<T>,
    label_of: impl Fn(&T) -> &str,
    sizes: SplitSizes,
    seed: u64,
) -> Result<Split<T>, SplitError> {
    let mut by_label: BTreeMap<&str, Vec<usize>> = BTreeMap::new();
    for (i, item) in items.iter().enumerate() {
        by_label.entry(label_of(item)).or_default().push(i);
    }
    // part[i]: 0 train, 1 validation, 2 test, 3 unused
    let mut part = vec![3u8; items.len()];
    for (label, mut indices) in by_label {
        if indices.len() < sizes.total() {
            return Err(SplitError {
                label: label.to_string(),
                have: indices.len(),
                need: sizes.total(),
                train: sizes.train,
                validation: sizes.validation,
                test: sizes.test,
            });
        }
        indices.shuffle(&mut rng::stream(seed, fnv1a(label.as_bytes())));
        let (train, rest) = indices.split_at(sizes.train);
        let (validation, rest) = rest.split_at(sizes.validation);
        for (which, chosen) in [(0u8, train), (1, validation), (2, &rest[..sizes.test])] {
            for &i in chosen {
                part[i] = which;
            }
        }
    }
    let mut split = Split {
        train: Vec::new(),
        validation: Vec::new(),
        test: Vec::new(),
    };
    for (item, which) in items.into_iter().zip(part) {
        match which {
            0 => split.train.push(item),
            1 => split.validation.push(item),
            2 => split.test.push(item),
            _ => {}
        }
    }
    Ok(split)
}

/// 64-bit FNV-1a: a fixed, portable hash of a label.
fn fnv1a(bytes: &[u8]) -> u64 {
    bytes.iter().fold(0xcbf2_9ce4_8422_2325, |h, &b| {
        (h ^ b as u64).wrapping_mul(0x0000_0100_0000_01b3)
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn items() -> Vec<(String, usize)> {
        (0..30).map(|i| (["A", "E", "I"][i % 3].to_string(), i)).collect()
    }

    #[test]
    fn parts_are_disjoint_sized_and_seeded() {
        let sizes = SplitSizes {
            train: 5,
            validation: 2,
            test: 2,
        };
        let a = split_per_label(items(), |x| &x.0, sizes, 7).unwrap();
        let b = split_per_label(items(), |x| &x.0, sizes, 7).unwrap();
        let c = split_per_label(items(), |x| &x.0, sizes, 8).unwrap();
        assert_eq!(a, b);
        assert_ne!(a, c);
        for label in ["A", "E", "I"] {
            let count = |part: &[(String, usize)]| part.iter().filter(|x| x.0 == label).count();
            assert_eq!((count(&a.train), count(&a.validation), count(&a.test)), (5, 2, 2));
        }
        let mut all: Vec<usize> = a
            .train
            .iter()
            .chain(&a.validation)
            .chain(&a.test)
            .map(|x| x.1)
            .collect();
        assert!(a.train.windows(2).all(|w| w[0].1 < w[1].1), "input order kept");
        all.sort();
        all.dedup();
        assert_eq!(all.len(), 27);
    }

    #[test]
    fn a_labels_split_ignores_other_labels() {
        let sizes = SplitSizes {
            train: 4,
            validation: 3,
            test: 3,
        };
        let a = split_per_label(items(), |x| &x.0, sizes, 3).unwrap();
        let only_a: Vec<_> = items().into_iter().filter(|x| x.0 == "A").collect();
        let b = split_per_label(only_a, |x| &x.0, sizes, 3).unwrap();
        let a_train: Vec<_> = a.train.into_iter().filter(|x| x.0 == "A").collect();
        assert_eq!(a_train, b.train);
    }

    #[test]
    fn too_few_names_the_label() {
        let sizes = SplitSizes {
            train: 8,
            validation: 1,
            test: 2,
        };
        let e = split_per_label(items(), |x| &x.0, sizes, 1)
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("'A'") && e.contains("10 readings") && e.contains("11"),
            "{e}"
        );
    }
}
