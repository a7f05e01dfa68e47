//! Beyond the paper (issue 74): the object as a body MuJoCo moves. The paper's object is a mocap
//! body that no touch moves, and its perturbation (Sec. V-B4) teleports it. Here the same blind
//! explorations of the 3D set (L = 0.5, every object at a random start pose, the `fusion`
//! experiment's streams: the same starts and draws for every mount) are made with the object
//! held six more ways: on a free joint (`sim::free_object`), a uniform solid light (250 kg/m3),
//! of water (1000, the default) or heavy (2500), each slippery (sliding friction 0.2) or rough
//! (0.8, the default), standing on the table under the arm's presses; and the default free object
//! pushed between readings by a hand (`sim::push`) where the mocap one is teleported.
//!
//! Each exploration is judged by the product's model, the `fusion` experiment's (appearance,
//! where each touch landed, and both: `recognize::geometric`), trained and calibrated on the
//! mocap object as the product is, so the curves say what a free object costs a recogniser that
//! was never told objects move. The contacts are judged against a still object (a free one's
//! header says it is not perturbed), so a touch that moves the object misleads them.
//!
//! Besides the accuracy, per-object, reliability and attempt tables of `fusion`,
//! `free-object_motion.csv` ([`MotionRow`]) says for every (mount, trial, object) how far each
//! touch moved the object (its centre along the table and its turn, from the pose before the
//! attempt to the pose the reading was taken at, format 4's columns), how often one tipped it or
//! pushed it off the table, and how often Press converged: the displacement per touch and Press's
//! convergence rate against mass and friction.

use serde::Serialize;

use super::context::PaperContext;
use super::data::{DataRequest, Objects};
use super::fusion::{FusionBasis, FusionUnit, Rows, attempts_plot, extend};
use super::recognition::TEST_STREAM;
use super::scale::DataCounts;
use crate::bodies::FreeBody;
use crate::dataset::Dataset;
use crate::experiment::accuracy::{AccuracyRow, AttemptRow, PerObjectRow, ReliabilityRow};
use crate::experiment::factor::{Factor, Factors};
use crate::experiment::name::SafeName;
use crate::experiment::plot::PlotSpec;
use crate::experiment::runner::{Experiment, RunReport, run};
use crate::experiment::spec::ExperimentSpec;
use crate::experiment::tidy::tidy_row;
use crate::experiment::unit::{BoxError, DetailRow, Unit};
use crate::pose::StartPose;
use crate::recognize::{CodebookKind, Evidence, GeometricFusion, PosteriorRule, TrainConfig};
use crate::sim::{MotionSummary, ObjectMotion, ObjectSpec, PerturbationAct, PerturbationBounds};

pub const EXPERIMENT_NAME: &str = "free-object";
pub const DESCRIPTION: &str = "Beyond the paper: the object mocap, free on the table (light, default or heavy; slippery or rough) or pushed between touches (3D set, random start poses, blind L = 0.5): how far each touch moves it, how often Press converges, and recognition by appearance, contacts and both against readings";

/// The free objects' densities, kg/m3: light (a foam or balsa solid), water (the default) and
/// heavy (a solid of glass or stone).
pub const DENSITIES_KG_M3: [f64; 3] = [250.0, 1000.0, 2500.0];

/// The free objects' sliding frictions: slippery (polished plastic on a smooth table) and rough
/// (the default, rubber-like).
pub const FRICTIONS: [f64; 2] = [0.2, 0.8];

/// L of the blind explorations: the `fusion` experiment's first, so the mocap ones are its.
const LOCAL_PROBABILITY: f64 = 0.5;

/// The evidence each curve weighs, in the order of the legend.
const EVIDENCE: [Evidence; 3] = [Evidence::Appearance, Evidence::Contacts, Evidence::Fused];

/// The legend's name of a curve.
const CURVE_LABEL: &str = "{evidence} {mount} {object_motion}";

/// One way of holding and moving the object: a column of levels and the explorations' plan.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Mount {
    /// The free joint's material; `None`: the paper's mocap body.
    pub body: Option<FreeBody>,
    /// Sec. V-B4's perturbation after every reading (teleported for a mocap object, pushed for a
    /// free one); `NONE`: the object is left where the touches leave it.
    pub perturbation: PerturbationBounds,
}

impl Mount {
    /// Every mount of the experiment: the mocap object fixed and teleported, each material free,
    /// and the default free object pushed.
    pub fn all() -> Result<Vec<Mount>, BoxError> {
        let still = PerturbationBounds::NONE;
        let mut mounts = vec![
            Mount {
                body: None,
                perturbation: still,
            },
            Mount {
                body: None,
                perturbation: PerturbationBounds::PAPER,
            },
        ];
        for density in DENSITIES_KG_M3 {
            for friction in FRICTIONS {
                mounts.push(Mount {
                    body: Some(FreeBody::new(density, friction)?),
                    perturbation: still,
                });
            }
        }
        mounts.push(Mount {
            body: Some(FreeBody::DEFAULT),
            perturbation: PerturbationBounds::PAPER.by(PerturbationAct::Push),
        });
        Ok(mounts)
    }

    /// The `mount` column's level: `mocap`, or `free_d<density>_mu<friction>`.
    pub fn level(&self) -> String {
        match self.body {
            None => "mocap".to_string(),
            Some(body) => format!("free_d{}_mu{}", body.density_kg_m3(), body.friction()),
        }
    }

    /// The `object_motion` column's level: `fixed`, `perturbed` (teleported) or `pushed`.
    pub fn motion(&self) -> &'static str {
        match (self.perturbation.is_none(), self.perturbation.act()) {
            (true, _) => "fixed",
            (false, PerturbationAct::Teleport) => "perturbed",
            (false, PerturbationAct::Push) => "pushed",
        }
    }

    fn factors(&self, evidence: Option<Evidence>) -> Factors {
        let mut levels = Vec::new();
        if let Some(evidence) = evidence {
            levels.push((Factor::Evidence, evidence.name().to_string()));
        }
        levels.push((Factor::Mount, self.level()));
        levels.push((Factor::ObjectMotion, self.motion().to_string()));
        Factors::new(levels)
    }
}

tidy_row! {
    /// How the touches of one exploration of one object moved it, and how often they converged
    /// (`free-object_motion.csv`).
    ///
    /// | column | meaning |
    /// |---|---|
    /// | `experiment` | `free-object` |
    /// | `mount`, `object_motion` | how the object was held (`mocap`, or `free_d<kg/m3>_mu<friction>`) and moved between readings (`fixed`, `perturbed`: teleported, `pushed`) |
    /// | `trial` | the exploration (its random stream), 0-based |
    /// | `object` | the object's name |
    /// | `mass_g` | a free object's mass, its mesh a uniform solid of the mount's density, grams; empty for a mocap object |
    /// | `start_tilt_deg` | how far the object's up axis leaned from the vertical when the first attempt began, degrees: a mocap object's is the start pose's drawn tilt (at most 10); a free one's is where it came to rest, which is far more for a mesh that is not stable as the set orients it; empty with no attempt |
    /// | `attempts` | reading attempts (Approach, then Press and Orient), converged or not |
    /// | `converged` | the attempts Press and Orient settled (Algorithm 1) |
    /// | `convergence_rate` | `converged / attempts`; empty with no attempt |
    /// | `touches_measured` | attempts whose object pose after the touch is known (every attempt on a free object; none on a mocap one, which no touch moves) |
    /// | `shift_mean_mm`, `shift_p95_mm`, `shift_max_mm` | how far a touch moved the object's centre along the table, from the pose before the attempt to the pose its reading was taken at, millimetres: mean, 95th percentile, largest; empty when no touch was measured |
    /// | `turn_mean_deg`, `turn_p95_deg`, `turn_max_deg` | how far a touch turned it, degrees, likewise |
    /// | `tipped` | touches that left it more than 30 degrees from how it stood |
    /// | `off_table` | touches that left its centre off the table |
    /// | `seed` | the run's seed |
    #[derive(Debug, Clone, PartialEq)]
    pub struct MotionRow {
        pub experiment: String,
        #[factors]
        pub factors: Factors,
        pub trial: u32,
        pub object: String,
        pub mass_g: Option<f64>,
        pub start_tilt_deg: Option<f64>,
        pub attempts: u32,
        pub converged: u32,
        pub convergence_rate: Option<f64>,
        pub touches_measured: u32,
        pub shift_mean_mm: Option<f64>,
        pub shift_p95_mm: Option<f64>,
        pub shift_max_mm: Option<f64>,
        pub turn_mean_deg: Option<f64>,
        pub turn_p95_deg: Option<f64>,
        pub turn_max_deg: Option<f64>,
        pub tipped: u32,
        pub off_table: u32,
        pub seed: u64,
    }
    impl Deserialize;
}

impl DetailRow for MotionRow {
    const TABLE: Option<&'static str> = Some("motion");
}

impl MotionRow {
    /// The row of `object`'s attempts in one exploration under `mount`.
    fn of(
        mount: &Mount,
        trial: u32,
        object: &ObjectSpec,
        attempts: &[&crate::dataset::Reading],
        seed: u64,
    ) -> Self {
        let centre_local = object.mesh.bounding_box_centre().unwrap_or(glam::DVec3::ZERO);
        let motions: Vec<ObjectMotion> = attempts
            .iter()
            .filter_map(|r| {
                let after = r.object_pose_after?;
                Some(ObjectMotion::between(&r.object_pose, &after, centre_local))
            })
            .collect();
        let summary = MotionSummary::of(&motions);
        // Empty cells where no touch was measured (a mocap object), not zeros.
        let measured = !motions.is_empty();
        let converged = attempts.iter().filter(|r| r.is_converged()).count();
        let mm = |m: f64| measured.then_some(m * 1e3);
        let deg = |r: f64| measured.then_some(r.to_degrees());
        Self {
            experiment: EXPERIMENT_NAME.to_string(),
            factors: mount.factors(None),
            trial,
            object: object.name.clone(),
            mass_g: mount
                .body
                .and_then(|b| object.mounted(Some(b)).solid_mass_kg())
                .map(|kg| kg * 1e3),
            start_tilt_deg: attempts.first().map(|r| r.object_pose.tilt_rad().to_degrees()),
            attempts: attempts.len() as u32,
            converged: converged as u32,
            convergence_rate: (!attempts.is_empty()).then(|| converged as f64 / attempts.len() as f64),
            touches_measured: motions.len() as u32,
            shift_mean_mm: mm(summary.centre_shift_m.mean),
            shift_p95_mm: mm(summary.centre_shift_m.p95),
            shift_max_mm: mm(summary.centre_shift_m.max),
            turn_mean_deg: deg(summary.turn_rad.mean),
            turn_p95_deg: deg(summary.turn_rad.p95),
            turn_max_deg: deg(summary.turn_rad.max),
            tipped: summary.tipped as u32,
            off_table: summary.off_table as u32,
            seed,
        }
    }

    /// The rows of every object of `test`, one exploration under `mount`.
    fn of_exploration(
        mount: &Mount,
        trial: u32,
        objects: &Objects,
        test: &Dataset,
        seed: u64,
    ) -> Result<Vec<Self>, BoxError> {
        let by_object = test.by_object();
        objects
            .specs
            .iter()
            .map(|object| {
                let j = test
                    .header()
                    .object_index(&object.name)
                    .ok_or_else(|| format!("object '{}' is not in the test data", object.name))?;
                Ok(Self::of(mount, trial, object, &by_object[j], seed))
            })
            .collect()
    }
}

/// What the rows depend on, written as the run's `config.json`.
#[derive(Serialize)]
struct FreeObjectConfig {
    /// The model's: the `fusion` experiment's setting, descriptors and calibration.
    model_of: &'static str,
    local_probability: f64,
    start_pose: StartPose,
    mounts: Vec<Mount>,
    evidence: Vec<&'static str>,
    posterior: PosteriorRule,
    scale: f64,
    counts: DataCounts,
    seed: u64,
    object_set_id: String,
    objects: Vec<String>,
    training: TrainConfig,
}

/// The unit's rows: `fusion`'s, and the motion rows.
type FreeRows = (
    Vec<AccuracyRow>,
    (
        Vec<PerObjectRow>,
        Vec<ReliabilityRow>,
        Vec<AttemptRow>,
        Vec<MotionRow>,
    ),
);

/// Runs the experiment in `context` (one unit: the model, then every mount's explorations).
pub fn run_free_object(context: &PaperContext, codebook: CodebookKind) -> Result<RunReport, BoxError> {
    let basis = FusionBasis::of(context, codebook)?;
    let objects = &basis.objects;
    let name = SafeName::new(EXPERIMENT_NAME)?;
    let key = SafeName::builder("mounts").build()?;
    let dir = crate::experiment::layout::ExperimentDir::new(&context.options.out, &name);
    let work = FreeObjectUnit {
        fusion: basis.unit(context, EXPERIMENT_NAME),
        mounts: Mount::all()?,
    };
    if context.options.shard.contains(0) && !dir.unit_csv(&key).exists() {
        context.store.prepare(&work.requests()?, dir.root())?;
    }
    let config = FreeObjectConfig {
        model_of: super::fusion::EXPERIMENT_NAME,
        local_probability: LOCAL_PROBABILITY,
        start_pose: basis.start_pose,
        mounts: work.mounts.clone(),
        evidence: EVIDENCE.iter().map(Evidence::name).collect(),
        posterior: context.posterior(),
        scale: context.scale.fraction(),
        counts: basis.counts,
        seed: context.seed,
        object_set_id: objects.set.id(),
        objects: objects.names(),
        training: basis.training.clone(),
    };
    let experiment = Experiment {
        spec: ExperimentSpec {
            name: name.clone(),
            description: DESCRIPTION.to_string(),
            plots: plots(&name, objects.specs.len())?,
        },
        config,
        units: vec![
            Unit::<_, (PerObjectRow, ReliabilityRow, AttemptRow, MotionRow)>::with_detail(key, move || {
                work.rows()
            }),
        ],
    };
    Ok(run(&experiment, &context.options)?)
}

/// The accuracy plot, its reliability diagram and the accuracy against touch attempts.
fn plots(name: &SafeName, objects: usize) -> Result<Vec<PlotSpec>, BoxError> {
    let title = "A free object: recognition as the arm's touches move it (random start poses)";
    let attempts = attempts_plot(
        EXPERIMENT_NAME,
        "A free object: accuracy against touch attempts (converged or not)",
        &["evidence", "mount", "object_motion"],
        CURVE_LABEL,
    )?;
    Ok(vec![
        PlotSpec::accuracy(name.clone(), title)
            .with_chance(objects)
            .with_legend(CURVE_LABEL),
        PlotSpec::reliability(
            SafeName::new(format!("{EXPERIMENT_NAME}-reliability"))?,
            &format!("Calibration: {title}"),
        )?
        .with_legend(CURVE_LABEL),
        attempts,
    ])
}

/// What the experiment's one unit works from: the product's model and every mount.
struct FreeObjectUnit<'a> {
    fusion: FusionUnit<'a>,
    mounts: Vec<Mount>,
}

impl FreeObjectUnit<'_> {
    /// The test explorations under `mount`, one per trial, on the `fusion` experiment's streams.
    fn tests(&self, mount: &Mount) -> Result<Vec<DataRequest>, BoxError> {
        self.fusion.explorations(
            LOCAL_PROBABILITY,
            (mount.perturbation, mount.body),
            self.fusion.data.counts.test_per_object,
            TEST_STREAM,
        )
    }

    /// Every dataset the unit reads: the model's, then each mount's explorations.
    fn requests(&self) -> Result<Vec<DataRequest>, BoxError> {
        let mut requests = self.fusion.model_requests()?;
        for mount in &self.mounts {
            requests.extend(self.tests(mount)?);
        }
        Ok(requests)
    }

    /// The model, then each mount's explorations: described once, recognised with each
    /// evidence, and their motions measured.
    fn rows(&self) -> Result<FreeRows, BoxError> {
        let model = self.fusion.model()?;
        let mut rows: Rows = Default::default();
        let mut motion = Vec::new();
        for mount in &self.mounts {
            let requests = self.tests(mount)?;
            extend(&mut rows, self.mount_rows(&model, mount, &requests)?);
            for (trial, request) in requests.iter().enumerate() {
                let test = self.fusion.data.context.store.dataset(request)?;
                motion.extend(MotionRow::of_exploration(
                    mount,
                    trial as u32,
                    &self.fusion.objects,
                    &test,
                    self.fusion.data.context.seed,
                )?);
            }
        }
        let (accuracy, (per_object, reliability, attempts)) = rows;
        Ok((accuracy, (per_object, reliability, attempts, motion)))
    }

    /// One mount's curves: its explorations recognised with each evidence.
    fn mount_rows(
        &self,
        model: &GeometricFusion,
        mount: &Mount,
        requests: &[DataRequest],
    ) -> Result<Rows, BoxError> {
        let tests = self.fusion.test_runs(model, requests)?;
        let mut rows: Rows = Default::default();
        for evidence in EVIDENCE {
            let judge = model.clone().with_evidence(evidence);
            extend(
                &mut rows,
                self.fusion
                    .curve_rows(&judge, &mount.factors(Some(evidence)), &tests)?,
            );
        }
        Ok(rows)
    }
}

#[cfg(test)]
mod tests {
    use glam::{DQuat, DVec3};

    use super::*;
    use crate::dataset::{ContactStatus, Reading, Strategy};
    use crate::pose::Pose;
    use crate::tactile::TactileImage;

    /// An attempt on a cube standing at the origin, moved `shift_m` along x and turned `turn_deg`
    /// about the vertical by the touch (nothing known after it when `None`).
    fn attempt(moved: Option<(f64, f64)>, status: ContactStatus) -> Reading {
        let before = Pose::IDENTITY;
        Reading {
            image: TactileImage::zeros(2, 2).unwrap_or_else(|e| panic!("{e}")),
            object: "cube".into(),
            object_pose: before,
            object_pose_after: moved.map(|(shift_m, turn_deg)| Pose {
                position_m: DVec3::new(shift_m, 0.0, 0.0),
                rotation: DQuat::from_rotation_z(turn_deg.to_radians()),
            }),
            status,
            iterations: 1,
            strategy: Strategy::Local,
            cause: None,
            contact: None,
        }
    }

    /// A cube 4 cm wide whose centre is its frame's origin, so a turn about the vertical does not
    /// move its centre.
    fn cube() -> ObjectSpec {
        ObjectSpec::new("cube", crate::mesh::TriMesh::cuboid(DVec3::splat(0.02)))
    }

    /// Known answers: the touches' shifts and turns summarised, the convergence counted, a mocap
    /// object's touches unmeasured, the mass the mount's density times the cube's volume.
    #[test]
    fn a_motion_row_summarises_the_touches_of_one_exploration() {
        let free = Mount {
            body: Some(FreeBody::new(250.0, 0.2).unwrap_or_else(|e| panic!("{e}"))),
            perturbation: PerturbationBounds::NONE,
        };
        let attempts = [
            attempt(Some((0.001, 2.0)), ContactStatus::Converged),
            attempt(Some((0.003, 0.0)), ContactStatus::NoContact),
            attempt(Some((0.002, 4.0)), ContactStatus::Converged),
            attempt(Some((0.0, 0.0)), ContactStatus::Converged),
        ];
        let refs: Vec<&Reading> = attempts.iter().collect();
        let row = MotionRow::of(&free, 2, &cube(), &refs, 7);
        assert_eq!((row.attempts, row.converged, row.touches_measured), (4, 3, 4));
        assert_eq!(row.convergence_rate, Some(0.75));
        let close = |a: Option<f64>, b: f64| a.is_some_and(|a| (a - b).abs() < 1e-9);
        assert!(close(row.shift_mean_mm, 1.5), "{row:?}");
        assert!(close(row.shift_max_mm, 3.0), "{row:?}");
        assert!(close(row.turn_mean_deg, 1.5), "{row:?}");
        assert!(close(row.turn_max_deg, 4.0), "{row:?}");
        assert!(close(row.mass_g, 250.0 * 0.04f64.powi(3) * 1e3), "{row:?}");
        assert_eq!((row.tipped, row.off_table), (0, 0));
        assert_eq!(row.start_tilt_deg, Some(0.0), "standing as built");
        assert_eq!(
            row.factors.to_string(),
            "mount = free_d250_mu0.2, object_motion = fixed"
        );

        let mocap = Mount {
            body: None,
            perturbation: PerturbationBounds::NONE,
        };
        let fixed = [attempt(None, ContactStatus::Converged)];
        let row = MotionRow::of(&mocap, 0, &cube(), &fixed.iter().collect::<Vec<_>>(), 7);
        assert_eq!(
            (row.touches_measured, row.shift_mean_mm, row.mass_g),
            (0, None, None)
        );
        let none = MotionRow::of(&free, 0, &cube(), &[], 7);
        assert_eq!(
            (none.attempts, none.convergence_rate, none.start_tilt_deg),
            (0, None, None)
        );
        let mut lying = attempt(Some((0.0, 0.0)), ContactStatus::Converged);
        lying.object_pose.rotation = DQuat::from_rotation_x(90f64.to_radians()) * DQuat::from_rotation_z(1.0);
        let row = MotionRow::of(&free, 0, &cube(), &[&lying], 7);
        assert!((row.start_tilt_deg.unwrap_or(0.0) - 90.0).abs() < 1e-9, "{row:?}");
    }

    #[test]
    fn every_mount_is_one_curve_per_evidence_of_the_same_factor_columns() {
        let mounts = Mount::all().unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(mounts.len(), 2 + DENSITIES_KG_M3.len() * FRICTIONS.len() + 1);
        let mut names = std::collections::BTreeSet::new();
        for mount in &mounts {
            for evidence in EVIDENCE {
                let factors = mount.factors(Some(evidence));
                factors.check().unwrap_or_else(|e| panic!("{e}"));
                assert_eq!(
                    factors.factors().collect::<Vec<_>>(),
                    [Factor::Evidence, Factor::Mount, Factor::ObjectMotion]
                );
                names.insert(factors.to_string());
            }
        }
        assert_eq!(names.len(), mounts.len() * EVIDENCE.len(), "distinct curves");
        let default = mounts.iter().filter(|m| m.body == Some(FreeBody::DEFAULT));
        let levels: Vec<(String, &str)> = default.map(|m| (m.level(), m.motion())).collect();
        assert_eq!(
            levels,
            [
                ("free_d1000_mu0.8".to_string(), "fixed"),
                ("free_d1000_mu0.8".to_string(), "pushed")
            ]
        );
    }
}
