//! What `collect` and `dataset show` print about a dataset: readings per object and status, and
//! what ended the failed attempts, by the names of the dataset's `cause` column.

use std::collections::BTreeMap;
use std::fmt;

use crate::dataset::{CauseKind, ContactStatus, Dataset, DatasetHeader};

impl Dataset {
    /// Counts per object and status, for `taction dataset show`.
    pub fn summary(&self) -> DatasetSummary {
        let mut per_object: Vec<BTreeMap<ContactStatus, usize>> =
            vec![BTreeMap::new(); self.header.objects.len()];
        for r in &self.readings {
            if let Some(i) = self.header.object_index(&r.object) {
                *per_object[i].entry(r.status).or_insert(0) += 1;
            }
        }
        let mut by_strategy = BTreeMap::new();
        for r in &self.readings {
            *by_strategy.entry(r.strategy.name()).or_insert(0) += 1;
        }
        let mut causes = vec![BTreeMap::new(); self.header.objects.len()];
        for r in &self.readings {
            if let (Some(i), Some(cause)) = (self.header.object_index(&r.object), &r.cause) {
                *causes[i].entry(cause.kind()).or_insert(0) += 1;
            }
        }
        let grouped: Vec<u32> = self.readings.iter().filter_map(|r| r.contact).collect();
        let presses = (!grouped.is_empty()).then(|| {
            let contacts = grouped.iter().collect::<std::collections::BTreeSet<_>>().len();
            (contacts, grouped.len())
        });
        DatasetSummary {
            header: self.header.clone(),
            per_object,
            causes,
            by_strategy,
            presses,
        }
    }
}

/// Counts for `taction dataset show`.
#[derive(Debug, Clone, PartialEq)]
pub struct DatasetSummary {
    pub header: DatasetHeader,
    /// Contacts of several frames (a recording's presses, the `contact` column) and the frames
    /// they hold; `None` when every reading is a contact of its own.
    pub presses: Option<(usize, usize)>,
    /// Per object (header order): readings by status.
    pub per_object: Vec<BTreeMap<ContactStatus, usize>>,
    /// Per object (header order): failed attempts by what ended them.
    pub causes: Vec<BTreeMap<CauseKind, usize>>,
    /// Readings by strategy name.
    pub by_strategy: BTreeMap<&'static str, usize>,
}

impl DatasetSummary {
    pub fn total(&self) -> usize {
        self.per_object.iter().flat_map(|m| m.values()).sum()
    }
}

impl fmt::Display for DatasetSummary {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let h = &self.header;
        write!(
            f,
            "format version {}, object set '{}', generator '{}', seed {}",
            h.format_version, h.object_set, h.generator, h.seed
        )?;
        // Only a random start is said: a canonical one is every dataset's before start poses.
        if !h.start_pose.is_canonical() {
            write!(f, ", start pose {}", h.start_pose)?;
        }
        // Only a free object is said: a mocap one is the paper's and every dataset's before.
        if let Some(body) = &h.free_object {
            write!(
                f,
                ", free object ({} kg/m3, friction {})",
                body.density_kg_m3(),
                body.friction()
            )?;
        }
        writeln!(f)?;
        self.write_sensor(f)?;
        let width = h
            .objects
            .iter()
            .map(String::len)
            .max()
            .unwrap_or(0)
            .max("object".len());
        self.write_statuses(f, width)?;
        if self.causes.iter().any(|c| !c.is_empty()) {
            self.write_causes(f, width)?;
        }
        let strategies: Vec<String> = self.by_strategy.iter().map(|(k, v)| format!("{k} {v}")).collect();
        write!(
            f,
            "strategies: {}",
            if strategies.is_empty() {
                "none".to_string()
            } else {
                strategies.join(", ")
            }
        )?;
        match self.presses {
            Some((contacts, frames)) => write!(
                f,
                "\ncontacts: {frames} frames in {contacts} presses, each press kept whole by every split"
            ),
            None => Ok(()),
        }
    }
}

impl DatasetSummary {
    /// The sensor line: shape, pad, covering, PSF, rays, noise; a recording's unknown pad size
    /// is said, not its placeholder printed.
    fn write_sensor(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let s = &self.header.sensor;
        let length = crate::units::length;
        if !self.header.pad_size.is_known() {
            return writeln!(
                f,
                "sensor: {}x{} taxels, pad size unknown (the taxel pitch was not given on import)",
                s.rows, s.cols
            );
        }
        writeln!(
            f,
            "sensor: {}x{} taxels, pad {} x {}, covering {}, PSF sigma {}, {} rays/taxel ({}), noise {} (seed {})",
            s.rows,
            s.cols,
            length(s.pad_width_m),
            length(s.pad_height_m),
            length(s.thickness_m),
            length(s.psf_sigma_m),
            s.rays_per_taxel,
            match crate::tactile::config::rays_per_side(s.rays_per_taxel) {
                Some(k) => format!("{k}x{k} grid"),
                None => "not a square grid".to_string(),
            },
            crate::units::significant(s.noise_fraction),
            s.noise_seed
        )
    }

    /// The table of readings per object and status, with a total row; names `width` wide.
    fn write_statuses(&self, f: &mut fmt::Formatter<'_>, width: usize) -> fmt::Result {
        write!(f, "{:<width$} {:>8}", "object", "readings")?;
        for status in ContactStatus::ALL {
            write!(f, " {:>14}", status.name())?;
        }
        writeln!(f)?;
        let mut totals = [0usize; ContactStatus::ALL.len()];
        for (name, counts) in self.header.objects.iter().zip(&self.per_object) {
            write!(f, "{name:<width$} {:>8}", counts.values().sum::<usize>())?;
            for (i, status) in ContactStatus::ALL.iter().enumerate() {
                let n = counts.get(status).copied().unwrap_or(0);
                totals[i] += n;
                write!(f, " {n:>14}")?;
            }
            writeln!(f)?;
        }
        write!(f, "{:<width$} {:>8}", "total", self.total())?;
        for n in totals {
            write!(f, " {n:>14}")?;
        }
        writeln!(f)
    }

    /// The table of failed attempts per object by what ended them; names `width` wide.
    fn write_causes(&self, f: &mut fmt::Formatter<'_>, width: usize) -> fmt::Result {
        write!(f, "{:<width$} {:>8}", "causes", "")?;
        for cause in CauseKind::ALL {
            write!(f, " {:>17}", cause.name())?;
        }
        writeln!(f)?;
        for (name, counts) in self.header.objects.iter().zip(&self.causes) {
            write!(f, "{name:<width$} {:>8}", "")?;
            for cause in CauseKind::ALL {
                write!(f, " {:>17}", counts.get(&cause).copied().unwrap_or(0))?;
            }
            writeln!(f)?;
        }
        Ok(())
    }
}
