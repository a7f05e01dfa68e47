//! Fig. 14 (Sec. V-C): convergence of the local controllers against sensor noise.
//!
//! "Both the percentage of approaches in which the controllers successfully converged and the average
//! number of iterations required for successful convergences were recorded under various levels of
//! noise. Noise was added in the same manner as in Sec. V-B7, ranged as a percentage of the total
//! observed force range. [...] At each noise level, sensor readings were collected until 100
//! successful convergences."
//!
//! Each (object, noise level) is one unit: the training sampler's placement (Sec. V-A3: an
//! area-weighted random surface point, the free-floating pad backed off along the face normal, facing
//! it, its orientation perturbed) followed by Approach -> Press <-> Orient, repeated until the wanted
//! number of convergences (or the sampler's attempt budget). The noise is the sensor's uniform
//! additive noise of width `noise_fraction` of the range (`SensorConfig::noise_fraction`), and the
//! controllers are told that width (`ControlConfig::expected_noise_fraction`), as a real controller
//! would know its sensor's noise floor. The object is the dragon-like mesh of the `shapes` set (the
//! paper used the Princeton Dragon "due to its variety of interesting surface features"); any object
//! can be given instead.

use serde::{Deserialize, Serialize};

use crate::control::ControlConfig;
use crate::control::FreePad;
use crate::control::orient::surface_normal;
use crate::dataset::ContactStatus;
use crate::explore::{SamplerConfig, TouchSetup, TrainingSampler};
use crate::mesh::{BuildOptions, MeshError, ObjectSet, TriMesh};
use crate::rng;
use crate::sim::{ObjectSpec, PerturbationBounds};
use crate::tactile::SensorConfig;
use crate::valid::{Check, Valid};

use crate::experiment::name::SafeName;
use crate::experiment::plot::{Axis, PlotSpec};
use crate::experiment::runner::Experiment;
use crate::experiment::spec::ExperimentSpec;
use crate::experiment::unit::{BoxError, Unit};

/// The experiment's name: its directory and CSV stem.
pub const EXPERIMENT_NAME: &str = "convergence";

/// The noise levels of Fig. 14, as fractions of the sensing range: 0 to 150%.
pub const PAPER_NOISE_FRACTIONS: [f64; 7] = [0.0, 0.10, 0.25, 0.50, 0.75, 1.00, 1.50];

/// Convergences collected per noise level in the paper.
pub const PAPER_CONVERGENCES: usize = 100;

/// The fewest convergences per noise level at any scale: fewer make the rate meaningless.
pub const MIN_CONVERGENCES: usize = 3;

/// The paper's object (the Dragon, Fig. 5h) in our `shapes` set.
pub const PAPER_OBJECT: &str = "dragon";

/// One row per (object, noise level) of `convergence.csv`: the approaches it took to collect the
/// convergences, and how good the converged readings are.
///
/// | column | meaning |
/// |---|---|
/// | `object` | the object's name (the paper's: `dragon`) |
/// | `noise_fraction` | width of the sensor's uniform additive noise, fraction of the sensing range (Sec. V-B7); the controllers are told it |
/// | `noise_percent` | the same in percent (the x axis of Fig. 14) |
/// | `attempts` | approaches made: a sampler placement (Sec. V-A3) followed by Approach -> Press <-> Orient, until `converged` reached the wanted number (100 at scale 1) or the sampler's attempt budget ran out |
/// | `converged` | approaches that ended converged |
/// | `convergence_rate` | `converged / attempts`, in [0, 1] (Fig. 14's convergence percentage as a fraction) |
/// | `mean_iterations` | mean Press/Orient iterations of the converged approaches (Fig. 14's iterations); the iteration budget when none converged, so the column is always a number |
/// | `mean_misalignment_deg` | mean angle between the pad normal and the plane Orient fits to a noise-free reading at each converged pad pose, degrees; 0 when none converged |
/// | `mean_pressure_error` | mean of abs(mean taxel value - Press's target) of those noise-free readings, fraction of the sensing range; 0 when none converged |
/// | `no_contact`, `saturated`, `max_iterations` | failed approaches that ended without contact, with a saturated taxel, or out of iterations |
/// | `other_failures` | the remaining failed approaches (`attempts` minus all of the above) |
/// | `seed` | the run's seed, as given with `--seed` |
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ConvergenceRow {
    pub object: String,
    pub noise_fraction: f64,
    pub noise_percent: f64,
    pub attempts: usize,
    pub converged: usize,
    pub convergence_rate: f64,
    pub mean_iterations: f64,
    pub mean_misalignment_deg: f64,
    pub mean_pressure_error: f64,
    pub no_contact: usize,
    pub saturated: usize,
    pub max_iterations: usize,
    pub other_failures: usize,
    pub seed: u64,
}

/// Identifies an object's mesh in the configuration, so a resumed run on another mesh is refused.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ObjectIdentity {
    pub name: String,
    pub triangles: usize,
    /// SHA-256 of the vertex coordinates (f64, little-endian) and triangle indices (u32, LE).
    pub mesh_sha256: String,
}

impl ObjectIdentity {
    pub fn of(object: &ObjectSpec) -> Self {
        Self {
            name: object.name.clone(),
            triangles: object.mesh.triangles.len(),
            mesh_sha256: mesh_sha256(&object.mesh),
        }
    }
}

fn mesh_sha256(mesh: &TriMesh) -> String {
    let mut bytes = Vec::with_capacity(mesh.vertices.len() * 24 + mesh.triangles.len() * 12);
    for v in &mesh.vertices {
        for c in v.to_array() {
            bytes.extend_from_slice(&c.to_le_bytes());
        }
    }
    for t in &mesh.triangles {
        for i in t {
            bytes.extend_from_slice(&i.to_le_bytes());
        }
    }
    crate::mesh::checksum::sha256_hex(&bytes)
}

/// Everything the rows depend on (written to `config.json`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ConvergenceConfig {
    pub objects: Vec<ObjectIdentity>,
    /// Noise widths, fractions of the sensing range.
    pub noise_fractions: Vec<f64>,
    /// Convergences wanted per (object, noise level).
    pub convergences: usize,
    /// The scale that gave `convergences` (1 = the paper's 100).
    pub scale: f64,
    pub seed: u64,
    /// The sensor at zero noise (the letters sensor: 6x6 taxels of 2 mm, 10% covering).
    pub sensor: SensorConfig,
    /// The controllers at zero noise; each level sets `expected_noise_fraction` to its noise.
    pub control: Valid<ControlConfig>,
    /// The training sampler's placement; no perturbation of the object.
    pub sampler: Valid<SamplerConfig>,
}

/// Why the experiment cannot be built.
#[derive(Debug, thiserror::Error)]
pub enum ConvergenceError {
    #[error("convergence experiment: scale {0} must be a positive finite number")]
    Scale(f64),
    #[error("convergence experiment: no objects")]
    NoObjects,
    #[error("convergence experiment: noise fraction {0} is outside [0, 2]")]
    Noise(f64),
    #[error("convergence experiment: object '{0}' has no triangles")]
    EmptyObject(String),
    #[error("convergence experiment: two objects are named '{0}'")]
    DuplicateObject(String),
    #[error("convergence experiment: sensor: {0}")]
    Sensor(String),
    #[error("convergence experiment: {0}")]
    Name(#[from] crate::experiment::name::NameError),
    #[error(transparent)]
    Mesh(#[from] MeshError),
}

/// Convergences per noise level at `scale` (1 = the paper's 100), at least [`MIN_CONVERGENCES`].
pub fn convergences_at(scale: f64) -> Result<usize, ConvergenceError> {
    if !(scale.is_finite() && scale > 0.0) {
        return Err(ConvergenceError::Scale(scale));
    }
    Ok(((PAPER_CONVERGENCES as f64 * scale).round() as usize).max(MIN_CONVERGENCES))
}

/// The paper's object: the dragon-like mesh of the built-in `shapes` set, scaled to its 12 cm
/// diagonal, resting on z = 0. `fetch` downloads the CGAL meshes when they are not cached yet.
pub fn paper_object(fetch: bool) -> Result<ObjectSpec, MeshError> {
    object_of_shapes(PAPER_OBJECT, fetch)
}

/// Object `name` of the `shapes` set (see [`paper_object`]).
pub fn object_of_shapes(name: &str, fetch: bool) -> Result<ObjectSpec, MeshError> {
    let built = ObjectSet::shapes().build_object(
        name,
        &BuildOptions {
            fetch,
            ..BuildOptions::default()
        },
    )?;
    Ok(ObjectSpec::from(built))
}

/// What a run of the experiment does, besides its objects: the paper's by [`ConvergencePlan::paper`].
#[derive(Debug, Clone, PartialEq)]
pub struct ConvergencePlan {
    /// Noise widths, fractions of the sensing range, each in [0, 2].
    pub noise_fractions: Vec<f64>,
    /// 1 = the paper's 100 convergences per noise level (see [`convergences_at`]).
    pub scale: f64,
    pub seed: u64,
    /// The sensor at zero noise.
    pub sensor: SensorConfig,
    /// The controllers; each level sets `expected_noise_fraction` to its noise.
    pub control: Valid<ControlConfig>,
    pub sampler: Valid<SamplerConfig>,
}

impl ConvergencePlan {
    /// The paper's noise levels, the letters sensor (6x6 taxels of 2 mm, 10% covering), the default
    /// controllers and the training sampler's placement.
    pub fn paper(scale: f64, seed: u64) -> Self {
        Self {
            noise_fractions: PAPER_NOISE_FRACTIONS.to_vec(),
            scale,
            seed,
            sensor: SensorConfig::square(
                6,
                6,
                crate::tactile::config::DEFAULT_PAD_M,
                crate::tactile::config::DEFAULT_THICKNESS_M,
            ),
            control: Valid::default(),
            sampler: Valid::default(),
        }
    }

    /// The experiment on `objects`: one unit per (object, noise level), in that order.
    pub fn experiment(
        &self,
        objects: Vec<ObjectSpec>,
    ) -> Result<Experiment<'static, ConvergenceRow, ConvergenceConfig>, ConvergenceError> {
        let convergences = convergences_at(self.scale)?;
        self.check(&objects)?;
        let config = ConvergenceConfig {
            objects: objects.iter().map(ObjectIdentity::of).collect(),
            noise_fractions: self.noise_fractions.clone(),
            convergences,
            scale: self.scale,
            seed: self.seed,
            sensor: self.sensor,
            control: self.control,
            sampler: self.sampler,
        };
        let units = self.units(objects, &config)?;
        Ok(Experiment {
            spec: spec(convergences)?,
            config,
            units,
        })
    }

    /// At least one object, each non-empty and named once; noise levels in [0, 2]; the sensor
    /// valid.
    fn check(&self, objects: &[ObjectSpec]) -> Result<(), ConvergenceError> {
        if objects.is_empty() {
            return Err(ConvergenceError::NoObjects);
        }
        if let Some(&bad) = self
            .noise_fractions
            .iter()
            .find(|f| !(f.is_finite() && (0.0..=2.0).contains(*f)))
        {
            return Err(ConvergenceError::Noise(bad));
        }
        for (i, o) in objects.iter().enumerate() {
            if o.mesh.triangles.is_empty() {
                return Err(ConvergenceError::EmptyObject(o.name.clone()));
            }
            if objects[..i].iter().any(|p| p.name == o.name) {
                return Err(ConvergenceError::DuplicateObject(o.name.clone()));
            }
        }
        self.sensor
            .check()
            .map_err(|e| ConvergenceError::Sensor(e.to_string()))
    }

    /// One unit per (object, noise level), in that order.
    fn units(
        &self,
        objects: Vec<ObjectSpec>,
        config: &ConvergenceConfig,
    ) -> Result<Vec<Unit<'static, ConvergenceRow>>, ConvergenceError> {
        let mut units = Vec::with_capacity(objects.len() * self.noise_fractions.len());
        for (object_index, object) in objects.into_iter().enumerate() {
            for (noise_index, &noise) in self.noise_fractions.iter().enumerate() {
                let key = SafeName::builder(EXPERIMENT_NAME)
                    .param("object", SafeName::new(object.name.clone())?)
                    .param("noise", noise)
                    .build()?;
                let object = object.clone();
                let config = config.clone();
                // One stream per (object, noise level): the rows do not depend on which units
                // run, in which order, or on how many threads.
                let unit_seed =
                    rng::substream(rng::substream(self.seed, object_index as u64), noise_index as u64);
                units.push(Unit::new(key, move || {
                    run_level(&object, noise, unit_seed, &config).map(|row| vec![row])
                }));
            }
        }
        Ok(units)
    }
}

/// What Fig. 14's run is and plots: convergence rate and iterations against noise, per object.
fn spec(convergences: usize) -> Result<ExperimentSpec, ConvergenceError> {
    Ok(ExperimentSpec {
        name: SafeName::new(EXPERIMENT_NAME)?,
        description: format!(
            "Fig. 14 (Sec. V-C): controller convergence vs sensor noise; sampler approaches until {convergences} convergences per noise level"
        ),
        plots: vec![PlotSpec::lines(
            SafeName::new(EXPERIMENT_NAME)?,
            "Convergence of the local controllers vs noise (Fig. 14)",
            Axis::new("noise_percent", "noise (% of the sensing range)"),
            vec![
                Axis::new("convergence_rate", "converged (fraction of approaches)"),
                Axis::new("mean_iterations", "iterations per convergence (-)"),
            ],
            &["object"],
        )],
    })
}

/// The Fig. 14 experiment on `objects` (e.g. [`paper_object`]) at `scale` (1 = 100 convergences
/// per noise level, the paper's; smaller scales collect fewer, at least [`MIN_CONVERGENCES`]),
/// seeded with `seed`: [`ConvergencePlan::paper`].
pub fn convergence_experiment(
    objects: Vec<ObjectSpec>,
    scale: f64,
    seed: u64,
) -> Result<Experiment<'static, ConvergenceRow, ConvergenceConfig>, ConvergenceError> {
    ConvergencePlan::paper(scale, seed).experiment(objects)
}

/// Collects approaches of `object` at noise width `noise` until `config.convergences` converge
/// (or the sampler's attempt budget runs out) and summarises them.
pub fn run_level(
    object: &ObjectSpec,
    noise: f64,
    unit_seed: u64,
    config: &ConvergenceConfig,
) -> Result<ConvergenceRow, BoxError> {
    let sensor = SensorConfig {
        noise_fraction: noise,
        noise_seed: rng::substream(unit_seed, 1),
        ..config.sensor
    };
    let control = Valid::new(ControlConfig {
        expected_noise_fraction: noise,
        ..*config.control
    })?;
    let mut pad = FreePad::new(object.clone(), &Valid::new(sensor)?)?;
    let placement = rng::stream(unit_seed, 0);
    let report = TrainingSampler::new(
        config.sampler,
        TouchSetup {
            sensor,
            control,
            perturbation: PerturbationBounds::NONE,
        },
        placement,
    )
    .sample(&mut pad, &object.name, config.convergences)?;
    level_row(object, noise, &report, control.max_iterations, config)
}

/// The row of one noise level: the approaches by outcome, the mean iterations of the converged
/// ones (`max_iterations_cap` when none converged) and their quality.
fn level_row(
    object: &ObjectSpec,
    noise: f64,
    report: &crate::explore::ExplorationReport,
    max_iterations_cap: usize,
    config: &ConvergenceConfig,
) -> Result<ConvergenceRow, BoxError> {
    let attempts = report.readings.len();
    let count = |s: ContactStatus| report.readings.iter().filter(|r| r.status == s).count();
    let converged = count(ContactStatus::Converged);
    let (no_contact, saturated, max_iterations) = (
        count(ContactStatus::NoContact),
        count(ContactStatus::Saturated),
        count(ContactStatus::MaxIterations),
    );
    let (mean_misalignment_deg, mean_pressure_error) = converged_quality(object, report, config)?;
    let iterations: u64 = report
        .readings
        .iter()
        .filter(|r| r.is_converged())
        .map(|r| u64::from(r.iterations))
        .sum();
    Ok(ConvergenceRow {
        object: object.name.clone(),
        noise_fraction: noise,
        noise_percent: 100.0 * noise,
        attempts,
        converged,
        convergence_rate: if attempts == 0 {
            0.0
        } else {
            converged as f64 / attempts as f64
        },
        mean_iterations: if converged == 0 {
            max_iterations_cap as f64
        } else {
            iterations as f64 / converged as f64
        },
        mean_misalignment_deg,
        mean_pressure_error,
        no_contact,
        saturated,
        max_iterations,
        other_failures: attempts - converged - no_contact - saturated - max_iterations,
        seed: config.seed,
    })
}

/// Mean misalignment (degrees) and mean pressure error of the converged readings of `report`, read
/// again without noise at the same pad poses (see [`ConvergenceRow::mean_misalignment_deg`]).
fn converged_quality(
    object: &ObjectSpec,
    report: &crate::explore::ExplorationReport,
    config: &ConvergenceConfig,
) -> Result<(f64, f64), BoxError> {
    let clean_sensor = SensorConfig {
        noise_fraction: 0.0,
        ..config.sensor
    };
    let clean_control = ControlConfig {
        expected_noise_fraction: 0.0,
        ..*config.control
    };
    let mut clean = FreePad::new(object.clone(), &Valid::new(clean_sensor)?)?;
    let (mut angle_sum, mut angles, mut error_sum, mut errors) = (0.0, 0usize, 0.0, 0usize);
    for reading in report.readings.iter().filter(|r| r.is_converged()) {
        let Some(pose) = reading.image.pose() else {
            continue;
        };
        let image = clean.read_at(pose)?;
        error_sum += (image.mean() - config.control.target_mean_pressure).abs();
        errors += 1;
        if let Some((normal, _)) = surface_normal(&image, &clean_sensor, &clean_control) {
            angle_sum += normal.angle_between(glam::DVec3::Z).to_degrees();
            angles += 1;
        }
    }
    let mean = |sum: f64, n: usize| if n == 0 { 0.0 } else { sum / n as f64 };
    Ok((mean(angle_sum, angles), mean(error_sum, errors)))
}
