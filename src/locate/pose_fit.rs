//! One pose of one object fitted to contacts (Petrovskaya and Khatib's contact likelihood, refined
//! by Gauss-Newton as point-to-plane ICP refines a pose): every contact should lie on the object's
//! surface with the surface's normal. `track` adds the belief so far as a Gaussian prior.
//!
//! A pose is a rotation `R` about the object's bounding-box centre `c` and where that centre is in
//! the world, `c_w`: a world point `p` is the object point `R^T (p - c_w) + c`. A step turns by a
//! small world rotation `w` about `c_w` and moves `c_w` by `d`.

use glam::{DMat3, DQuat, DVec3};
use nalgebra::{Matrix6, Vector6};

use crate::locate::contact::Contact;
use crate::locate::surface::ObjectSurface;

/// What the likelihood of a contact assumes (documented defaults in [`crate::locate::GeometryParams`]).
#[derive(Debug, Clone, Copy)]
pub(crate) struct Likelihood {
    /// The contact point's spread about the surface along its normal, metres.
    pub sigma_point_m: f64,
    /// The contact normal's spread about the surface normal, radians.
    pub sigma_normal_rad: f64,
    /// The share of contacts no pose explains (a slip, a reading of an edge).
    pub outlier: f64,
}

/// A pose of one object and its log-evidence given the contacts so far (`track`).
#[derive(Debug, Clone, Copy)]
pub(crate) struct Hypothesis {
    pub rotation: DQuat,
    pub center_w: DVec3,
    pub score: f64,
}

/// Everything one pass over the contacts gives at one pose: the score, and the Hessian and
/// gradient of its negative (the cost a step lowers).
pub(crate) struct Linearised {
    pub score: f64,
    pub hessian: Matrix6<f64>,
    pub gradient: Vector6<f64>,
}

/// A contact anywhere in a 0.2 m cube, with any normal: the density an outlier has, per cubic
/// metre and steradian.
const OUTLIER_DENSITY: f64 = 1.0 / (0.008 * 4.0 * std::f64::consts::PI);

/// Damping of a Gauss-Newton step: a turn of more than about 0.2 rad or a move of more than about
/// a centimetre needs contacts to ask for it.
const DAMPING_ROTATION: f64 = 1.0 / (0.2 * 0.2);
const DAMPING_TRANSLATION: f64 = 1.0 / (0.01 * 0.01);

impl Hypothesis {
    /// The object at heading `heading_rad` about the vertical through its centre, where it stands
    /// at the canonical pose.
    pub fn at_heading(surface: &ObjectSurface, heading_rad: f64) -> Self {
        Self {
            rotation: DQuat::from_rotation_z(heading_rad),
            center_w: surface.center_m(),
            score: 0.0,
        }
    }

    /// Up to `iterations` damped Gauss-Newton steps on the score `linearise` gives at a pose, each
    /// kept only when it raises the score; returns the linearisation at the pose kept.
    pub(crate) fn fitted(
        &mut self,
        iterations: usize,
        linearise: impl Fn(&Self) -> Linearised,
    ) -> Linearised {
        let mut current = linearise(self);
        for _ in 0..iterations {
            let Some(step) = solve(&current) else { break };
            let trial = self.stepped(&step);
            let next = linearise(&trial);
            if next.score.partial_cmp(&current.score) != Some(std::cmp::Ordering::Greater) {
                break;
            }
            *self = trial;
            current = next;
            if step.norm() < 1e-7 {
                break;
            }
        }
        current
    }

    fn stepped(&self, step: &Vector6<f64>) -> Self {
        let turn = DVec3::new(step[0], step[1], step[2]);
        Self {
            rotation: (DQuat::from_scaled_axis(turn) * self.rotation).normalize(),
            center_w: self.center_w + DVec3::new(step[3], step[4], step[5]),
            score: self.score,
        }
    }

    /// The score (the contact's log-likelihood, robust) and its Gauss-Newton approximation at
    /// this pose. The contact's weight in the step is the probability that it is not an outlier
    /// (EM's responsibility), so a contact the pose cannot explain stops pulling on it. One
    /// contact: the filter (`locate::track`) takes each as it comes, the belief so far standing
    /// for the ones before.
    pub(crate) fn linearise(
        &self,
        surface: &ObjectSurface,
        contact: &Contact,
        likelihood: &Likelihood,
    ) -> Linearised {
        let mut out = Linearised {
            score: 0.0,
            hessian: Matrix6::zeros(),
            gradient: Vector6::zeros(),
        };
        let to_object = self.rotation.inverse();
        let density_scale = (1.0 - likelihood.outlier) / surface.area_m2();
        let point_var = likelihood.sigma_point_m.powi(2);
        let normal_var = likelihood.sigma_normal_rad.powi(2);
        let a = contact.point_m - self.center_w;
        let q = to_object * a + surface.center_m();
        let outlier = likelihood.outlier * OUTLIER_DENSITY;
        let Some(nearest) = surface.nearest(q) else {
            out.score += outlier.ln();
            return out;
        };
        let g = self.rotation * surface.normals()[nearest.index];
        let r = nearest.signed_distance_m;
        let kappa = 1.0 / normal_var;
        let cos = g.dot(contact.normal).clamp(-1.0, 1.0);
        let log_inlier =
            density_scale.ln() - 0.5 * r * r / point_var - 0.5 * (std::f64::consts::TAU * point_var).ln()
                + kappa * (cos - 1.0)
                + (kappa / std::f64::consts::TAU).ln();
        let log_total = log_sum_exp(log_inlier, outlier.ln());
        out.score += log_total;
        let w = (log_inlier - log_total).exp();
        // Point-to-plane: dr/dw = -(a x g), dr/dd = -g.
        let j = Vector6::from_column_slice(&[
            -(a.cross(g)).x,
            -(a.cross(g)).y,
            -(a.cross(g)).z,
            -g.x,
            -g.y,
            -g.z,
        ]);
        out.hessian += j * j.transpose() * (w / point_var);
        out.gradient += j * (w * r / point_var);
        // Normal: e = g - n, de/dw = -[g]x.
        let e = g - contact.normal;
        let gx = cross_matrix(g);
        let h = (gx.transpose() * gx) * (w / normal_var);
        let grad = g.cross(e) * (w / normal_var);
        add_rotation_block(&mut out, h, grad);
        out
    }
}

fn add_rotation_block(out: &mut Linearised, h: DMat3, gradient: DVec3) {
    for i in 0..3 {
        for k in 0..3 {
            out.hessian[(i, k)] += h.col(k)[i];
        }
        out.gradient[i] += gradient[i];
    }
}

/// The damped Gauss-Newton step `-(H + D)^-1 g`, or `None` when it cannot be solved.
fn solve(at: &Linearised) -> Option<Vector6<f64>> {
    let mut h = at.hessian;
    for k in 0..3 {
        h[(k, k)] += DAMPING_ROTATION;
        h[(3 + k, 3 + k)] += DAMPING_TRANSLATION;
    }
    let step = h.cholesky()?.solve(&(-at.gradient));
    step.iter().all(|x| x.is_finite()).then_some(step)
}

/// `[v]x`, the matrix of `v x .`.
fn cross_matrix(v: DVec3) -> DMat3 {
    DMat3::from_cols(
        DVec3::new(0.0, v.z, -v.y),
        DVec3::new(-v.z, 0.0, v.x),
        DVec3::new(v.y, -v.x, 0.0),
    )
}

fn log_sum_exp(a: f64, b: f64) -> f64 {
    let m = a.max(b);
    if m == f64::NEG_INFINITY {
        return m;
    }
    m + ((a - m).exp() + (b - m).exp()).ln()
}
