//! The geometric recogniser: for every known object, a few pose hypotheses followed through the
//! contacts so far; the evidence for the object is how well they predicted them.
//!
//! `ln p(contacts | O_j)` is the log of the mean, over the object's hypotheses, of each
//! hypothesis's evidence: the hypotheses start at headings spread over the range the object may
//! stand at (any heading, or a few degrees for the letters), each a Gaussian belief over the pose
//! that every contact updates (`track`: one Gauss-Newton fit of the new contact against the belief
//! so far, its predictive likelihood the evidence), so the mean over them stands for the integral
//! over the unknown pose. Nothing of the object's true pose is read: only contacts.

use serde::{Deserialize, Serialize};

use crate::dataset::Perturbed;
use crate::locate::contact::{Contact, Touch};
use crate::locate::pose_fit::{Hypothesis, Likelihood};
use crate::locate::surface::ObjectSurface;
use crate::locate::track::{MoveSpread, StartSpread, Track};
use crate::mesh::TriMesh;
use crate::pose::{MaxHeading, Pose};
use crate::valid::{Check, FieldChecks, RangeError, Valid};

/// What the geometric recogniser assumes of contacts and of where objects stand. The defaults
/// are the documented arm and start pose; each is a spread, not a bound, so a pose or contact a
/// little beyond it costs likelihood rather than being refused.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GeometryParams {
    /// Spread of a contact point about the surface along its normal, metres: the contact noise
    /// (1.7 mm RMS) and the image's estimate of the contact (the covering's blur).
    pub sigma_point_m: f64,
    /// Spread of the contact normal about the surface normal, degrees: Orient's alignment
    /// (Algorithm 1) on a surface curved under the pad, and the 2 deg of noise.
    pub sigma_normal_deg: f64,
    /// Share of contacts no pose of the object explains.
    pub outlier_fraction: f64,
    /// Spread of the object's tilt from upright at the start, degrees (start poses tilt up to 10).
    pub tilt_sigma_deg: f64,
    /// Spread of the object's horizontal shift at the start, as a fraction of its width (start
    /// poses shift up to 10%).
    pub shift_sigma_fraction: f64,
    /// Spread of the height of the object's centre, metres (a tilt of an object resting on the
    /// table raises or lowers it).
    pub height_sigma_m: f64,
    /// The heading range objects stand at (the object set's, `mesh::ObjectSet::start_heading`):
    /// any heading, or within a few degrees of the canonical one for the letters, whose heading is
    /// part of their identity.
    pub max_heading: MaxHeading,
    /// Pose hypotheses per object, at headings spread evenly over the range.
    pub hypotheses: usize,
    /// Gauss-Newton steps per hypothesis after each contact.
    pub iterations: usize,
}

impl Default for GeometryParams {
    fn default() -> Self {
        Self {
            sigma_point_m: 0.0025,
            sigma_normal_deg: 12.0,
            outlier_fraction: 0.05,
            tilt_sigma_deg: 6.0,
            shift_sigma_fraction: 0.05,
            height_sigma_m: 0.01,
            max_heading: MaxHeading::ANY,
            hypotheses: 36,
            iterations: 3,
        }
    }
}

impl Check for GeometryParams {
    type Error = RangeError;

    fn check(&self) -> Result<(), RangeError> {
        let Self {
            sigma_point_m,
            sigma_normal_deg,
            outlier_fraction,
            tilt_sigma_deg,
            shift_sigma_fraction,
            height_sigma_m,
            max_heading: _,
            hypotheses,
            iterations,
        } = *self;
        let positive = |v: f64| v > 0.0;
        FieldChecks::of("geometry params")
            .real(
                "sigma_point_m",
                sigma_point_m,
                positive(sigma_point_m) && sigma_point_m <= 0.1,
                "(0, 0.1]",
            )
            .real(
                "sigma_normal_deg",
                sigma_normal_deg,
                positive(sigma_normal_deg) && sigma_normal_deg <= 90.0,
                "(0, 90]",
            )
            .real(
                "outlier_fraction",
                outlier_fraction,
                positive(outlier_fraction) && outlier_fraction < 1.0,
                "(0, 1)",
            )
            .real(
                "tilt_sigma_deg",
                tilt_sigma_deg,
                positive(tilt_sigma_deg) && tilt_sigma_deg <= 90.0,
                "(0, 90]",
            )
            .real(
                "shift_sigma_fraction",
                shift_sigma_fraction,
                positive(shift_sigma_fraction) && shift_sigma_fraction <= 1.0,
                "(0, 1]",
            )
            .real(
                "height_sigma_m",
                height_sigma_m,
                positive(height_sigma_m) && height_sigma_m <= 1.0,
                "(0, 1]",
            )
            .count(
                "hypotheses",
                hypotheses,
                (1..=720).contains(&hypotheses),
                "1 to 720",
            )
            .count(
                "iterations",
                iterations,
                (1..=50).contains(&iterations),
                "1 to 50",
            )
            .finish()
    }
}

// How far the object moves between touches is a `dataset::Perturbed`, what a dataset's header
// records (Sec. V-B4's perturbation after every reading, or nothing); `track` follows a moving
// object through the spread each move adds to its pose.

/// Mean square turn of one move (a uniform angle up to the bound).
fn turn_var_rad2(motion: &Perturbed) -> f64 {
    motion.max_rotation_deg.to_radians().powi(2) / 3.0
}

/// Variance one move adds to the object's horizontal place, per axis.
fn shift_var_m2(motion: &Perturbed, width_m: f64) -> f64 {
    (motion.max_translation_fraction * width_m).powi(2) / 4.0
}

/// How one move spreads the pose of an object `width_m` wide, per axis: a third of the turn's
/// mean square about each axis; the shift; and the rise or fall of its centre as it comes to rest
/// again, the turn at half its width.
fn move_spread(motion: &Perturbed, width_m: f64) -> MoveSpread {
    let turn_var_rad2 = turn_var_rad2(motion) / 3.0;
    MoveSpread {
        turn_var_rad2,
        shift_var_m2: shift_var_m2(motion, width_m),
        height_var_m2: turn_var_rad2 * (0.5 * width_m).powi(2),
    }
}

/// Why a geometric model could not be built or read.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum GeometryError {
    #[error(transparent)]
    Params(#[from] RangeError),
    #[error("object '{0}': its mesh has no triangle of positive area to match contacts against")]
    EmptySurface(String),
    #[error("no mesh of object '{object}' among the objects given ({})", given.join(", "))]
    NoMesh { object: String, given: Vec<String> },
}

/// Every known object's surface, and what the recogniser assumes (the module docs).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct GeometryModel {
    pub params: Valid<GeometryParams>,
    objects: Vec<String>,
    surfaces: Vec<ObjectSurface>,
}

impl GeometryModel {
    /// The surfaces of `objects` (name and mesh in its canonical frame, metres, as the object
    /// stands at the identity pose).
    pub fn build<'m>(
        objects: impl IntoIterator<Item = (String, &'m TriMesh)>,
        params: Valid<GeometryParams>,
    ) -> Result<Self, GeometryError> {
        let (names, surfaces) = objects
            .into_iter()
            .map(|(name, mesh)| match ObjectSurface::of_mesh(mesh) {
                Some(s) => Ok((name, s)),
                None => Err(GeometryError::EmptySurface(name)),
            })
            .collect::<Result<(Vec<_>, Vec<_>), _>>()?;
        Ok(Self {
            params,
            objects: names,
            surfaces,
        })
    }

    /// The surfaces of the objects `names` (a recogniser's, in its order) picked by name from
    /// `meshes` (any order, more allowed), with the default assumptions for objects that stand
    /// within `max_heading` of their canonical heading: what `taction train --objects`, Python's
    /// `train(objects=...)` and the `fusion` experiment build.
    pub fn of_named(
        names: &[String],
        meshes: &[(String, &TriMesh)],
        max_heading: MaxHeading,
    ) -> Result<Self, GeometryError> {
        let picked = names
            .iter()
            .map(|name| match meshes.iter().find(|(n, _)| n == name) {
                Some(&(_, mesh)) => Ok((name.clone(), mesh)),
                None => Err(GeometryError::NoMesh {
                    object: name.clone(),
                    given: meshes.iter().map(|(n, _)| n.clone()).collect(),
                }),
            })
            .collect::<Result<Vec<_>, _>>()?;
        let params = Valid::new(GeometryParams {
            max_heading,
            ..GeometryParams::default()
        })?;
        Self::build(picked, params)
    }

    pub fn objects(&self) -> &[String] {
        &self.objects
    }

    pub fn surfaces(&self) -> &[ObjectSurface] {
        &self.surfaces
    }

    /// A posterior with no contact yet, for an object that moves as `motion` says between touches
    /// (not at all, for `Perturbed::FIXED`).
    pub fn posterior(&self, motion: Perturbed) -> GeometryPosterior<'_> {
        let headings = self.headings();
        let tracks = self
            .surfaces
            .iter()
            .map(|s| {
                let spread = self.start_spread(s.width_m());
                headings
                    .iter()
                    .map(|&h| Track::start(Hypothesis::at_heading(s, h), &spread))
                    .collect()
            })
            .collect();
        GeometryPosterior {
            model: self,
            motion,
            tracks,
            log_likelihoods: vec![0.0; self.objects.len()],
        }
    }

    /// The spread of a start pose about a hypothesis, for an object `width_m` wide: the prior's
    /// tilt, shift and height, and half the gap between neighbouring hypotheses' headings (or the
    /// prior's heading spread for a set whose heading is bounded).
    fn start_spread(&self, width_m: f64) -> StartSpread {
        let p = &self.params;
        let heading_sigma_rad = if p.max_heading.is_any() {
            std::f64::consts::PI / p.hypotheses as f64
        } else {
            (0.5 * p.max_heading.rad()).max(1e-3)
        };
        StartSpread {
            tilt_sigma_rad: p.tilt_sigma_deg.to_radians(),
            heading_sigma_rad,
            shift_sigma_m: p.shift_sigma_fraction * width_m,
            height_sigma_m: p.height_sigma_m,
        }
    }

    /// The hypotheses' starting headings: evenly over the full turn, or over `+-max` (both ends).
    fn headings(&self) -> Vec<f64> {
        let n = self.params.hypotheses;
        let max = self.params.max_heading;
        if max.is_any() {
            (0..n)
                .map(|k| std::f64::consts::TAU * k as f64 / n as f64)
                .collect()
        } else if n > 1 {
            (0..n)
                .map(|k| max.rad() * (2.0 * k as f64 / (n - 1) as f64 - 1.0))
                .collect()
        } else {
            vec![0.0]
        }
    }

    fn likelihood(&self) -> Likelihood {
        Likelihood {
            sigma_point_m: self.params.sigma_point_m,
            sigma_normal_rad: self.params.sigma_normal_deg.to_radians(),
            outlier: self.params.outlier_fraction,
        }
    }
}

/// The geometric evidence after each touch (the module docs): `observe` a touch, read
/// `log_likelihoods`.
#[derive(Debug, Clone)]
pub struct GeometryPosterior<'a> {
    model: &'a GeometryModel,
    motion: Perturbed,
    /// Per object, its pose hypotheses.
    tracks: Vec<Vec<Track>>,
    log_likelihoods: Vec<f64>,
}

impl GeometryPosterior<'_> {
    /// Adds one touch (a touch without a contact adds no evidence, but its attempt still counts
    /// the object's moves). Returns `ln p(contacts | O_j)` for every object, up to one constant.
    pub fn observe(&mut self, touch: Touch) -> &[f64] {
        if let Some(c) = touch.contact {
            self.track(c, touch.attempt);
        }
        &self.log_likelihoods
    }

    /// `ln p(contacts | O_j)` for every object (0 before any contact).
    pub fn log_likelihoods(&self) -> &[f64] {
        &self.log_likelihoods
    }

    pub(crate) fn model(&self) -> &GeometryModel {
        self.model
    }

    /// Per object, its pose hypotheses now.
    pub(crate) fn tracks(&self) -> &[Vec<Track>] {
        &self.tracks
    }

    /// Object `object`'s most likely pose now (mesh frame in the world), from its best
    /// hypothesis: where the recogniser believes it stands if it is that object.
    pub fn best_pose(&self, object: usize) -> Option<Pose> {
        let surface = self.model.surfaces.get(object)?;
        let best = self
            .tracks
            .get(object)?
            .iter()
            .map(|t| &t.pose)
            .max_by(|a, b| a.score.total_cmp(&b.score))?;
        // p = R (q - c) + c_w = R q + (c_w - R c).
        Some(Pose::new(
            best.center_w - best.rotation * surface.center_m(),
            best.rotation,
        ))
    }

    /// Moves every track on to `attempt` (the moves since its last contact, for a moving object)
    /// and updates it with `contact`.
    fn track(&mut self, contact: Contact, attempt: usize) {
        let model = self.model;
        let likelihood = model.likelihood();
        let iterations = model.params.iterations;
        let objects = model.surfaces.iter().zip(&mut self.tracks);
        for ((surface, tracks), l) in objects.zip(&mut self.log_likelihoods) {
            let moves = move_spread(&self.motion, surface.width_m());
            for t in tracks.iter_mut() {
                t.observe(surface, contact, attempt, &likelihood, &moves, iterations);
            }
            *l = log_mean_exp(tracks.iter().map(Track::evidence));
        }
    }
}

/// `ln (mean of exp(x))` over `scores`, without overflow.
fn log_mean_exp(scores: impl Iterator<Item = f64> + Clone) -> f64 {
    let best = scores.clone().fold(f64::NEG_INFINITY, f64::max);
    let (sum, n) = scores.fold((0.0, 0usize), |(s, n), x| (s + (x - best).exp(), n + 1));
    best + (sum / n as f64).ln()
}

#[cfg(test)]
mod tests {
    use glam::{DQuat, DVec3};

    use super::*;

    /// A box 12 x 6 x 4 cm resting on z = 0, centred on the vertical axis: no turn about the
    /// vertical but the half turn maps it onto itself.
    fn slab() -> TriMesh {
        TriMesh::cuboid(DVec3::new(0.06, 0.03, 0.02)).translated(DVec3::new(0.0, 0.0, 0.02))
    }

    /// A cube of 8 cm resting on z = 0.
    fn cube() -> TriMesh {
        TriMesh::cuboid(DVec3::splat(0.04)).translated(DVec3::new(0.0, 0.0, 0.04))
    }

    fn model() -> GeometryModel {
        let (slab, cube) = (slab(), cube());
        GeometryModel::build(
            [("slab".to_string(), &slab), ("cube".to_string(), &cube)],
            Valid::default(),
        )
        .expect("two boxes")
    }

    /// Contacts on the slab's sides and top (the faces an arm from above reaches) at `pose`.
    fn slab_contacts(pose: &Pose) -> Vec<Contact> {
        let local = [
            (DVec3::new(0.06, 0.01, 0.02), DVec3::X),
            (DVec3::new(-0.02, 0.03, 0.01), DVec3::Y),
            (DVec3::new(0.03, -0.01, 0.04), DVec3::Z),
            (DVec3::new(-0.06, -0.02, 0.03), -DVec3::X),
            (DVec3::new(0.01, -0.03, 0.02), -DVec3::Y),
            (DVec3::new(-0.04, 0.02, 0.04), DVec3::Z),
        ];
        local
            .iter()
            .map(|&(p, n)| Contact {
                point_m: pose.transform_point(p),
                normal: pose.transform_vector(n),
            })
            .collect()
    }

    #[test]
    fn contacts_on_an_object_at_an_untold_pose_name_it_and_find_its_pose() {
        let model = model();
        let pose = Pose::new(DVec3::new(0.004, -0.003, 0.0), DQuat::from_rotation_z(0.7));
        let mut posterior = model.posterior(Perturbed::FIXED);
        for (attempt, contact) in slab_contacts(&pose).into_iter().enumerate() {
            posterior.observe(Touch {
                contact: Some(contact),
                attempt,
            });
        }
        let l = posterior.log_likelihoods();
        assert!(l[0] > l[1] + 10.0, "slab {} vs cube {}", l[0], l[1]);
        let found = posterior.best_pose(0).expect("a pose");
        // The slab is the same turned half round: either heading is right.
        let turn = (found.rotation * pose.rotation.inverse()).to_axis_angle().1;
        let off = turn.min((turn - std::f64::consts::PI).abs());
        assert!(off < 0.03, "heading off by {off} rad");
        assert!((found.position_m - pose.position_m).length() < 0.03);
    }

    #[test]
    fn a_touch_without_a_contact_adds_no_evidence() {
        let model = model();
        let mut posterior = model.posterior(Perturbed::FIXED);
        let l = posterior
            .observe(Touch {
                contact: None,
                attempt: 0,
            })
            .to_vec();
        assert_eq!(l, vec![0.0, 0.0]);
    }

    #[test]
    fn a_moving_object_is_followed_through_its_moves() {
        let model = model();
        let moving = Perturbed {
            max_rotation_deg: 10.0,
            max_translation_fraction: 0.1,
            ..Perturbed::FIXED
        };
        // The slab is touched on four of its faces at each of three poses, moved between them by
        // a perturbation's size (8 deg about a tilted axis, 9 mm).
        let poses: Vec<Pose> = (0..3)
            .map(|k| {
                let turn = DQuat::from_axis_angle(DVec3::new(0.3, -0.2, 1.0).normalize(), 0.14 * k as f64);
                Pose::new(
                    DVec3::new(0.008, -0.004, 0.0) * k as f64,
                    turn * DQuat::from_rotation_z(0.3),
                )
            })
            .collect();
        let contacts: Vec<(usize, Contact)> = poses
            .iter()
            .enumerate()
            .flat_map(|(k, pose)| {
                let faces = slab_contacts(pose);
                (0..4).map(move |i| (4 * k + i, faces[(2 * k + i) % faces.len()]))
            })
            .collect();
        let mut posterior = model.posterior(moving);
        for &(attempt, contact) in &contacts {
            posterior.observe(Touch {
                contact: Some(contact),
                attempt,
            });
        }
        let l = posterior.log_likelihoods();
        assert!(l[0] > l[1] + 5.0, "slab {} vs cube {}", l[0], l[1]);
        // Where the slab stands now, not where it started.
        let found = posterior.best_pose(0).expect("a pose");
        let now = poses[2];
        let turn = (found.rotation * now.rotation.inverse()).to_axis_angle().1;
        let off = turn.min((turn - std::f64::consts::PI).abs());
        let start_off = (poses[0].rotation * now.rotation.inverse()).to_axis_angle().1;
        assert!(
            off < 0.5 * start_off,
            "turn off by {off} rad (the start is {start_off} rad away)"
        );
        let (d, start_d) = (
            (found.position_m - now.position_m).length(),
            (poses[0].position_m - now.position_m).length(),
        );
        assert!(
            d < start_d,
            "{d} m from where it stands (the start is {start_d} m away)"
        );
    }

    #[test]
    fn the_same_contacts_give_the_same_bits() {
        let model = model();
        let pose = Pose::new(DVec3::ZERO, DQuat::from_rotation_z(2.0));
        let run = || {
            let mut posterior = model.posterior(Perturbed::FIXED);
            for (attempt, contact) in slab_contacts(&pose).into_iter().enumerate() {
                posterior.observe(Touch {
                    contact: Some(contact),
                    attempt,
                });
            }
            posterior.log_likelihoods().to_vec()
        };
        assert_eq!(run(), run());
    }

    #[test]
    fn a_model_file_round_trips() {
        let model = model();
        let json = serde_json::to_string(&model).expect("encodes");
        let back: GeometryModel = serde_json::from_str(&json).expect("decodes");
        assert_eq!(back, model);
    }

    #[test]
    fn params_out_of_range_are_refused_by_name() {
        let bad = GeometryParams {
            outlier_fraction: 1.5,
            ..GeometryParams::default()
        };
        let e = Valid::new(bad).expect_err("refused");
        assert_eq!(e.field, "outlier_fraction");
        assert!(Valid::new(GeometryParams::default()).is_ok());
    }
}
