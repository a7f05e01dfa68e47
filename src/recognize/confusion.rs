//! The confusion matrix over a test set.

use serde::{Deserialize, Serialize};

/// `counts[true][guess]`: how often an object was recognised as each object, after
/// `n_readings` readings of it (or all of a trial's readings, when it has fewer).
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct ConfusionMatrix {
    objects: Vec<String>,
    counts: Vec<Vec<u64>>,
    n_readings: usize,
}

impl ConfusionMatrix {
    /// An all-zero matrix over `objects` of the decisions after `n_readings` readings.
    pub fn new(objects: Vec<String>, n_readings: usize) -> Self {
        let n = objects.len();
        Self {
            objects,
            counts: vec![vec![0; n]; n],
            n_readings,
        }
    }

    /// The number of readings the decisions were taken after.
    pub fn n_readings(&self) -> usize {
        self.n_readings
    }

    /// Records one decision. Indices are object indices of the model, known to be in range.
    pub fn add(&mut self, truth: usize, guess: usize) {
        self.counts[truth][guess] += 1;
    }

    pub fn objects(&self) -> &[String] {
        &self.objects
    }

    /// How often `truth` was recognised as `guess`.
    pub fn count(&self, truth: usize, guess: usize) -> u64 {
        self.counts[truth][guess]
    }

    pub fn total(&self) -> u64 {
        self.counts.iter().flatten().sum()
    }

    /// Fraction on the diagonal; 0 for an empty matrix.
    pub fn accuracy(&self) -> f64 {
        let correct: u64 = (0..self.objects.len()).map(|i| self.counts[i][i]).sum();
        let total = self.total();
        if total == 0 {
            0.0
        } else {
            correct as f64 / total as f64
        }
    }

    /// Tidy CSV (`n_readings,object_true,object_guess,count`, every pair including zeros).
    pub fn to_csv_string(&self) -> String {
        let mut out = String::from("n_readings,object_true,object_guess,count\n");
        let n = self.n_readings.to_string();
        for (i, t) in self.objects.iter().enumerate() {
            for (j, g) in self.objects.iter().enumerate() {
                out.push_str(&csv_row(&[&n, t, g, &self.counts[i][j].to_string()]));
            }
        }
        out
    }
}

/// One CSV line, quoting fields that need it.
pub(crate) fn csv_row(fields: &[&str]) -> String {
    let quoted: Vec<String> = fields
        .iter()
        .map(|f| {
            if f.contains([',', '"', '\n', '\r']) {
                format!("\"{}\"", f.replace('"', "\"\""))
            } else {
                f.to_string()
            }
        })
        .collect();
    quoted.join(",") + "\n"
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn counts_and_accuracy() {
        let mut m = ConfusionMatrix::new(vec!["a".into(), "b,c".into()], 30);
        m.add(0, 0);
        m.add(0, 1);
        m.add(1, 1);
        m.add(1, 1);
        assert_eq!(m.count(0, 1), 1);
        assert!((m.accuracy() - 0.75).abs() < 1e-15);
        let csv = m.to_csv_string();
        assert_eq!(
            csv,
            "n_readings,object_true,object_guess,count\n30,a,a,1\n30,a,\"b,c\",1\n30,\"b,c\",a,0\n30,\"b,c\",\"b,c\",2\n"
        );
    }
}
