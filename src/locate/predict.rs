//! What a touch toward a target would tell through where it lands (issue 71, item 1): the expected
//! information gain of its contact, about the object's identity with its pose marginalised, or
//! about identity and pose together.
//!
//! Every pose hypothesis the recogniser follows (`model`: a few per object, each a Gaussian
//! belief over the pose) predicts the contact of a touch toward `x`: the surface point of that
//! object, at that hypothesis's mean pose, nearest `x`, with its normal. The planner carries the
//! pad toward `x` until the sensor feels something (`explore::planner`), so the touch lands only
//! where `x` lies inside the surface, or outside it by less than the reach (the pad's half-width:
//! its edge meets a surface its centre would pass); a hypothesis that puts `x` farther out
//! predicts no touch. With `w_i` the weight of hypothesis `i` (its object's probability times its
//! share of the object's evidence) and `D_ik` the Bhattacharyya distance between the likelihoods
//! of the contacts `i` and `k` predict, the expected gain about identity is the pairwise estimate
//! (Kolchinsky and Tracey, Entropy 2017) of how far a contact moves the belief toward the object
//! that made it:
//!
//! ```text
//! EIG_J(x)  = sum_{i touches} w_i ln [ sum_{k of i's object} w_k exp(-D_ik) / (pi_{j_i} sum_k w_k exp(-D_ik)) ]
//! EIG_JP(x) = - sum_{i touches} w_i ln sum_k w_k exp(-D_ik)        (identity and pose together)
//! ```
//!
//! the outer sums over the hypotheses that predict a touch (a touch that meets nothing gives the
//! recogniser no reading, and tells it nothing), the inner over every hypothesis, as the
//! recogniser weighs a contact against every pose of every object (one whose surface lies far
//! from the contact explains it badly: `D` large). The gain is not divided by the weight of the
//! hypotheses that touch (the gain of a touch that touches, as the appearance gain is): where only
//! unlikely hypotheses put a surface, a touch would tell much if it touched, but most likely it
//! will not; measured, the divided gain chose such places, up to 4 nats where identity holds
//! ln 12 = 2.5, and recognised worse than the appearance gain alone (docs/measurements.md,
//! "Touches chosen for where they land"). The planner's own chance of touching
//! (`explore::TouchOdds`) still multiplies the sum with the appearance gain.
//!
//! For two contacts at points `p` and normals `n`, `D` is the Bhattacharyya distance of two
//! isotropic Gaussians, `|p_i - p_k|^2 / (4 (v_i + v_k)) + (d / 2) ln((v_i + v_k) / (2 sqrt(v_i
//! v_k)))` in `d` dimensions, for the points (3) and the normals (2), summed. A predicted
//! contact's variance `v` is the likelihood's (`sigma^2 / s`, the spreads of `GeometryParams` and
//! `s` the weight the next contact's log-likelihood has in the posterior, the fused weight `lambda` times the tempering's `w(n + 1)`: a likelihood raised to
//! `s` is a Gaussian of variance `sigma^2 / s`) plus the spread the hypothesis's own pose
//! uncertainty gives the point (or the normal) there, per axis: early on, when every hypothesis
//! is uncertain by several degrees and millimetres, its predictions are as vague and say less.
//!
//! How the model knows that a place touched again is worth less: every hypothesis that survived
//! the earlier contacts there predicts the contact they showed, and is sure of its pose there, so
//! their predictions agree (`D` near 0) and the touch is expected to tell nothing new; places
//! where the likely objects' surfaces, or one object's likely poses, part ways score high. The
//! object moving between touches is not predicted: a perturbed object's tracks already widen with
//! its moves.

use glam::DVec3;
use nalgebra::{Matrix3, Matrix6, SMatrix};

use crate::locate::model::GeometryPosterior;
use crate::locate::pose_fit::Hypothesis;
use crate::locate::surface::ObjectSurface;
use crate::locate::track::Track;

/// What the expected gain of a contact is about.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum GainOf {
    /// The object's identity, its pose marginalised: what the recogniser is asked.
    Identity,
    /// Identity and pose together (the comparison): a touch that only pins the pose counts too.
    IdentityAndPose,
}

/// The weight below which hypotheses are left out of a prediction, as a share of all: each
/// candidate costs a nearest-point query per hypothesis kept, and the weight left out is at most
/// this share.
const NEGLIGIBLE_WEIGHT: f64 = 1e-3;

/// Hypotheses kept at most, the heaviest first: a bound on a candidate's cost (pairs of them)
/// before the first contacts have told the hypotheses apart.
const MAX_HYPOTHESES: usize = 96;

/// One hypothesis of one object, with its weight.
struct Weighted<'s> {
    object: usize,
    surface: &'s ObjectSurface,
    pose: Hypothesis,
    /// The pose's covariance (`track`), zero where it cannot be had.
    covariance: Matrix6<f64>,
    weight: f64,
}

/// A contact a hypothesis predicts: point and normal in the world with their variances per axis
/// (module docs), and how far the target lies outside the surface there (negative inside).
#[derive(Clone, Copy)]
struct Predicted {
    point_m: DVec3,
    normal: DVec3,
    point_var_m2: f64,
    normal_var: f64,
    outside_m: f64,
}

/// The spreads of a contact's likelihood raised to the weight `s`: variances `sigma^2 / s`.
#[derive(Clone, Copy)]
struct LikelihoodSpread {
    point_var_m2: f64,
    normal_var: f64,
}

impl GeometryPosterior<'_> {
    /// The expected gain of a contact (the module docs), nats, of a touch toward each of
    /// `targets_m` (world frame): `object_probabilities` the belief over identity now (one per
    /// object of the model), `weight` the weight `s` of the next contact's log-likelihood, a touch
    /// meets a surface its target lies inside or less than `reach_m` outside.
    pub fn contact_gains_nats(
        &self,
        object_probabilities: &[f64],
        targets_m: &[DVec3],
        weight: f64,
        reach_m: f64,
        of: GainOf,
    ) -> Vec<f64> {
        let params = &self.model().params;
        let spread = LikelihoodSpread {
            point_var_m2: params.sigma_point_m.powi(2) / weight,
            normal_var: params.sigma_normal_deg.to_radians().powi(2) / weight,
        };
        contact_gains(
            &self.weighted(object_probabilities),
            targets_m,
            &spread,
            reach_m,
            of,
        )
    }

    /// The hypotheses worth predicting: every object's tracks weighted by the object's
    /// probability times the track's share of the object's evidence, the heaviest first, until all
    /// but [`NEGLIGIBLE_WEIGHT`] of the weight (at most [`MAX_HYPOTHESES`]), their weights then
    /// summing to 1.
    fn weighted(&self, object_probabilities: &[f64]) -> Vec<Weighted<'_>> {
        let surfaces = self.model().surfaces();
        let mut all: Vec<(usize, &Track, f64)> = Vec::new();
        for (object, (tracks, &p)) in self.tracks().iter().zip(object_probabilities).enumerate() {
            if p.is_nan() || p <= 0.0 || tracks.is_empty() {
                continue;
            }
            let best = tracks
                .iter()
                .map(|t| t.evidence())
                .fold(f64::NEG_INFINITY, f64::max);
            let total: f64 = tracks.iter().map(|t| (t.evidence() - best).exp()).sum();
            all.extend(
                tracks
                    .iter()
                    .map(|t| (object, t, p * (t.evidence() - best).exp() / total)),
            );
        }
        // Heaviest first; equal weights keep the objects' and tracks' order (a stable sort).
        all.sort_by(|a, b| b.2.total_cmp(&a.2));
        let mut kept = 0.0;
        let keep = all
            .iter()
            .take(MAX_HYPOTHESES)
            .take_while(|h| {
                let more = kept < 1.0 - NEGLIGIBLE_WEIGHT;
                kept += h.2;
                more
            })
            .count();
        all.truncate(keep);
        let total: f64 = all.iter().map(|h| h.2).sum();
        // Only the kept hypotheses' covariances: an inversion each, asked for every candidate.
        all.into_iter()
            .map(|(object, track, weight)| Weighted {
                object,
                surface: &surfaces[object],
                pose: track.pose,
                covariance: track.covariance().unwrap_or_else(Matrix6::zeros),
                weight: weight / total,
            })
            .collect()
    }
}

/// [`GeometryPosterior::contact_gains_nats`] over given hypotheses.
fn contact_gains(
    hypotheses: &[Weighted<'_>],
    targets_m: &[DVec3],
    spread: &LikelihoodSpread,
    reach_m: f64,
    of: GainOf,
) -> Vec<f64> {
    targets_m
        .iter()
        .map(|&x| {
            let predicted: Vec<Predicted> = hypotheses.iter().map(|h| predict(h, x, spread)).collect();
            gain(hypotheses, &predicted, reach_m, of)
        })
        .collect()
}

/// The contact hypothesis `h` predicts for a touch toward `x_m`: the surface point nearest it,
/// its spread the likelihood's and the pose's there.
fn predict(h: &Weighted<'_>, x_m: DVec3, spread: &LikelihoodSpread) -> Predicted {
    let pose = &h.pose;
    let center = h.surface.center_m();
    // World to object: q = R^T (p - c_w) + c (pose_fit's frame).
    let query = pose.rotation.inverse() * (x_m - pose.center_w) + center;
    let i = h.surface.nearest_anywhere(query);
    let (point, normal) = (h.surface.points()[i], h.surface.normals()[i]);
    let point_m = pose.rotation * (point - center) + pose.center_w;
    let normal_w = pose.rotation * normal;
    // A step (turn w about the centre, move d) moves the point by w x a + d, a = p - c_w, and
    // turns the normal by w x n.
    let (a, n) = (point_m - pose.center_w, normal_w);
    let mut jacobian = SMatrix::<f64, 3, 6>::zeros();
    jacobian.fixed_view_mut::<3, 3>(0, 0).copy_from(&-cross_matrix(a));
    jacobian
        .fixed_view_mut::<3, 3>(0, 3)
        .copy_from(&Matrix3::identity());
    let point_cov = jacobian * h.covariance * jacobian.transpose();
    let turn_cov = h.covariance.fixed_view::<3, 3>(0, 0);
    let normal_cov = cross_matrix(n) * turn_cov * cross_matrix(n).transpose();
    Predicted {
        point_m,
        normal: normal_w,
        point_var_m2: spread.point_var_m2 + point_cov.trace() / 3.0,
        normal_var: spread.normal_var + normal_cov.trace() / 2.0,
        outside_m: (query - point).dot(normal),
    }
}

/// `[v]x`: the matrix of the cross product with `v`.
fn cross_matrix(v: DVec3) -> Matrix3<f64> {
    Matrix3::new(0.0, -v.z, v.y, v.z, 0.0, -v.x, -v.y, v.x, 0.0)
}

/// The Bhattacharyya distance of two isotropic Gaussians of `dims` dimensions, means
/// `squared_gap` apart, variances per axis `va` and `vb`.
fn bhattacharyya(squared_gap: f64, va: f64, vb: f64, dims: f64) -> f64 {
    let sum = va + vb;
    squared_gap / (4.0 * sum) + 0.5 * dims * (sum / (2.0 * (va * vb).sqrt())).ln()
}

/// `D` between the contacts two hypotheses predict (module docs).
fn distance(a: &Predicted, b: &Predicted) -> f64 {
    bhattacharyya(
        a.point_m.distance_squared(b.point_m),
        a.point_var_m2,
        b.point_var_m2,
        3.0,
    ) + bhattacharyya(
        a.normal.distance_squared(b.normal),
        a.normal_var,
        b.normal_var,
        2.0,
    )
}

/// The pairwise estimate (module docs), over the hypotheses that predict a touch (the target
/// inside their surface or less than `reach_m` outside); 0 when none does.
fn gain(hypotheses: &[Weighted<'_>], predicted: &[Predicted], reach_m: f64, of: GainOf) -> f64 {
    let mut sum = 0.0;
    for (hi, pi) in hypotheses.iter().zip(predicted) {
        if pi.outside_m > reach_m {
            continue;
        }
        let (mut all, mut same, mut share) = (0.0, 0.0, 0.0);
        for (hk, pk) in hypotheses.iter().zip(predicted) {
            let kernel = hk.weight * (-distance(pi, pk)).exp();
            all += kernel;
            if hk.object == hi.object {
                same += kernel;
                share += hk.weight;
            }
        }
        let log_ratio = match of {
            GainOf::Identity => (same / (share * all)).ln(),
            GainOf::IdentityAndPose => -all.ln(),
        };
        sum += hi.weight * log_ratio;
    }
    sum.max(0.0)
}

#[cfg(test)]
mod tests {
    use glam::DQuat;

    use super::*;
    use crate::dataset::Perturbed;
    use crate::locate::contact::{Contact, Touch};
    use crate::locate::model::{GeometryModel, GeometryParams};
    use crate::mesh::TriMesh;
    use crate::valid::Valid;

    /// A box of half-sizes `half` resting on z = 0.
    fn resting_box(half: DVec3) -> TriMesh {
        TriMesh::cuboid(half).translated(DVec3::new(0.0, 0.0, half.z))
    }

    /// Two boxes with the same footprint (12 x 6 cm), 4 and 8 cm tall, each followed at
    /// `hypotheses` headings spread over any heading.
    fn two_boxes(hypotheses: usize) -> GeometryModel {
        let (low, tall) = (
            resting_box(DVec3::new(0.06, 0.03, 0.02)),
            resting_box(DVec3::new(0.06, 0.03, 0.04)),
        );
        let params = GeometryParams {
            hypotheses,
            ..GeometryParams::default()
        };
        GeometryModel::build(
            [("low".to_string(), &low), ("tall".to_string(), &tall)],
            Valid::new(params).expect("valid"),
        )
        .expect("two boxes")
    }

    /// Each box at each of `headings_deg`, its pose known exactly (no covariance), all equally
    /// likely.
    fn exact<'m>(model: &'m GeometryModel, headings_deg: &[f64]) -> Vec<Weighted<'m>> {
        let count = (model.surfaces().len() * headings_deg.len()) as f64;
        model
            .surfaces()
            .iter()
            .enumerate()
            .flat_map(|(object, surface)| {
                headings_deg.iter().map(move |h| Weighted {
                    object,
                    surface,
                    pose: Hypothesis::at_heading(surface, h.to_radians()),
                    covariance: Matrix6::zeros(),
                    weight: 1.0 / count,
                })
            })
            .collect()
    }

    /// The likelihood's spreads at weight 1.
    fn spread() -> LikelihoodSpread {
        let p = GeometryParams::default();
        LikelihoodSpread {
            point_var_m2: p.sigma_point_m.powi(2),
            normal_var: p.sigma_normal_deg.to_radians().powi(2),
        }
    }

    /// Half the width of a 12 mm pad.
    const REACH_M: f64 = 0.006;

    /// The known answers, both boxes' poses known: 5 mm below the low box's top, the tall box's
    /// nearest face is its long side 2 cm away, so a touch there names the box (the whole prior
    /// entropy, ln 2); 5 mm inside their shared end face it tells nothing; far from both, or
    /// outside both, nothing is touched.
    #[test]
    fn a_touch_where_the_surfaces_part_tells_all_and_one_where_they_meet_nothing() {
        let model = two_boxes(1);
        let targets = [
            DVec3::new(0.0, 0.01, 0.035),
            DVec3::new(0.055, 0.0, 0.02),
            DVec3::new(0.3, 0.3, 0.3),
            DVec3::new(0.0, 0.0, 0.1),
        ];
        let known = exact(&model, &[0.0]);
        let gains = contact_gains(&known, &targets, &spread(), REACH_M, GainOf::Identity);
        assert!((gains[0] - 2f64.ln()).abs() < 1e-5, "{gains:?}");
        // The faces' surface points differ by the meshes' tessellation, a millimetre at most.
        assert!(gains[1].abs() < 0.01, "{gains:?}");
        assert_eq!(gains[2..], [0.0, 0.0]);
        // A contact that weighs little in the posterior tells little.
        let faint = LikelihoodSpread {
            point_var_m2: 100.0 * spread().point_var_m2,
            normal_var: 100.0 * spread().normal_var,
        };
        let gains_faint = contact_gains(&known, &targets, &faint, REACH_M, GainOf::Identity);
        assert!(gains_faint[0] < 0.5 * gains[0], "{gains_faint:?}");
    }

    /// Each box at three headings (-90, 0, 90 deg), the target 1.5 cm beside the long side at
    /// the canonical heading: there the touch meets nothing; turned a quarter turn (either way) the
    /// box holds the target, its nearest face 3 cm from the first, and both boxes show the same
    /// face. A touch there pins the heading (the joint gain, by hand ln 3/2 from each of the four
    /// hypotheses it touches, of weight 4/6) and tells nothing of identity. Above, inside the tall
    /// box only, a touch names the box at any heading (ln 2) when it touches, half the time; the
    /// joint gain is never below the identity gain. Surface points are 1.5 mm apart and lie
    /// differently on each mesh and turn, so predicted contacts that should coincide differ by a
    /// millimetre or two: hence the tolerances.
    #[test]
    fn a_touch_that_pins_only_the_pose_tells_nothing_of_identity() {
        let model = two_boxes(1);
        let known = exact(&model, &[-90.0, 0.0, 90.0]);
        let gains = |target: DVec3, of| contact_gains(&known, &[target], &spread(), REACH_M, of)[0];
        let beside = DVec3::new(0.0, 0.045, 0.02);
        let identity = gains(beside, GainOf::Identity);
        let joint = gains(beside, GainOf::IdentityAndPose);
        assert!(identity.abs() < 0.01, "{identity}");
        assert!((joint - 4.0 / 6.0 * 1.5f64.ln()).abs() < 0.05, "{joint}");
        let above = DVec3::new(0.0, 0.0, 0.06);
        let identity = gains(above, GainOf::Identity);
        let joint = gains(above, GainOf::IdentityAndPose);
        assert!((identity - 0.5 * 2f64.ln()).abs() < 1e-5, "{identity}");
        assert!(joint >= identity - 1e-12, "{joint} {identity}");
    }

    /// A hypothesis unsure of its pose predicts a vague contact: the same boxes at the start's
    /// spread (6 deg of tilt, 5 deg of heading, 6 mm and 1 cm of place) expect less of a touch
    /// 1.5 cm below the low box's top than where their poses are known.
    #[test]
    fn an_unsure_pose_expects_less_of_a_touch() {
        let model = two_boxes(36);
        let posterior = model.posterior(Perturbed::FIXED);
        let target = [DVec3::new(0.0, 0.01, 0.025)];
        let unsure = posterior.contact_gains_nats(&[0.5, 0.5], &target, 1.0, REACH_M, GainOf::Identity)[0];
        let headings: Vec<f64> = (0..36).map(|k| 10.0 * k as f64).collect();
        let sure = contact_gains(
            &exact(&model, &headings),
            &target,
            &spread(),
            REACH_M,
            GainOf::Identity,
        )[0];
        assert!(unsure > 0.0 && unsure < sure, "unsure {unsure}, sure {sure}");
    }

    /// The model knows a place touched before: once contacts there have left the hypotheses that
    /// fit them, those all predict the contact they showed, and a touch there is expected to tell
    /// less than before it was touched.
    #[test]
    fn a_place_touched_before_is_worth_less() {
        let model = two_boxes(36);
        let turn = Turn::about_vertical(0.7);
        let mut posterior = model.posterior(Perturbed::FIXED);
        let place = turn.0 * DVec3::new(0.06, 0.0, 0.02);
        let target = [turn.0 * DVec3::new(0.055, 0.0, 0.02)];
        let gain = |p: &GeometryPosterior<'_>| {
            p.contact_gains_nats(&[0.5, 0.5], &target, 1.0, REACH_M, GainOf::IdentityAndPose)[0]
        };
        let before = gain(&posterior);
        for attempt in 0..3 {
            posterior.observe(Touch {
                contact: Some(Contact {
                    point_m: place,
                    normal: turn.0 * DVec3::X,
                }),
                attempt,
            });
        }
        let after = gain(&posterior);
        assert!(after < 0.5 * before, "before {before}, after {after}");
    }

    /// A turn about the vertical through the origin (the boxes' centres lie on it).
    struct Turn(DQuat);

    impl Turn {
        fn about_vertical(rad: f64) -> Self {
            Self(DQuat::from_rotation_z(rad))
        }
    }
}
