//! One pose hypothesis followed through the touches: a Gaussian belief over the object's pose,
//! predicted through the moves between touches (Sec. V-B4: "the object pose is perturbed by a
//! small amount ... each time a sensor reading is taken"; none for an object that stays) and
//! updated by each new contact, an iterated extended Kalman filter on the pose with Petrovskaya
//! and Khatib's contact likelihood as its measurement. The hypothesis's evidence is the product of
//! each contact's predictive likelihood given those before it (Laplace's approximation about the
//! updated pose), so a hypothesis pays for the pose it had to learn.
//!
//! The object moves rigidly, so contacts taken before the same move keep their places relative to
//! one another on the object: what a move blurs is the object's pose, not the shape the contacts
//! trace. Discounting each older contact by the moves since, as independent noise on each (the
//! first design), threw that shape away; the filter keeps it in the belief's covariance. One
//! contact per update also keeps a touch's cost the same however many came before (refitting every
//! contact so far, the first design's fixed objects, grew with them).

use nalgebra::{Matrix6, Vector6};

use crate::locate::contact::Contact;
use crate::locate::pose_fit::{Hypothesis, Likelihood, Linearised};
use crate::locate::surface::ObjectSurface;

/// How much one move spreads the pose, per axis: variances of the turn about each world axis,
/// radians squared, and of the centre's move along each, metres squared.
#[derive(Debug, Clone, Copy)]
pub(crate) struct MoveSpread {
    pub turn_var_rad2: f64,
    pub shift_var_m2: f64,
    pub height_var_m2: f64,
}

/// The pose's spread where the object starts, per axis (standard deviations): the tilt about
/// each horizontal axis and the heading about the vertical, radians; the centre's horizontal and
/// vertical place, metres.
#[derive(Debug, Clone, Copy)]
pub(crate) struct StartSpread {
    pub tilt_sigma_rad: f64,
    pub heading_sigma_rad: f64,
    pub shift_sigma_m: f64,
    pub height_sigma_m: f64,
}

/// One hypothesis followed through the moves: its mean pose and the information (inverse
/// covariance) of the pose about it, in the coordinates of a step (a world turn about the centre,
/// then a move of the centre), and the log-evidence of the contacts it has seen.
#[derive(Debug, Clone)]
pub(crate) struct Track {
    pub pose: Hypothesis,
    information: Matrix6<f64>,
    /// The attempt the belief is current at.
    attempt: usize,
}

impl Track {
    /// A belief centred on `pose` with the spread of a start, before attempt 0; no evidence yet.
    pub fn start(pose: Hypothesis, spread: &StartSpread) -> Self {
        let variances = [
            spread.tilt_sigma_rad.powi(2),
            spread.tilt_sigma_rad.powi(2),
            spread.heading_sigma_rad.powi(2),
            spread.shift_sigma_m.powi(2),
            spread.shift_sigma_m.powi(2),
            spread.height_sigma_m.powi(2),
        ];
        Self {
            pose: Hypothesis { score: 0.0, ..pose },
            information: Matrix6::from_diagonal(&Vector6::from_iterator(variances.iter().map(|v| 1.0 / v))),
            attempt: 0,
        }
    }

    /// The covariance of the pose about [`pose`](Self::pose) (a step's coordinates, `pose_fit`),
    /// at the last contact; `None` where the information cannot be inverted.
    pub fn covariance(&self) -> Option<Matrix6<f64>> {
        self.information.try_inverse()
    }

    /// The log-evidence of the contacts seen (`ln p(c_1..c_n | this hypothesis)`).
    pub fn evidence(&self) -> f64 {
        self.pose.score
    }

    /// Predicts the belief through the moves up to `attempt`, then updates it with `contact`
    /// (up to `iterations` Gauss-Newton steps) and adds the contact's predictive log-likelihood
    /// to the evidence.
    pub fn observe(
        &mut self,
        surface: &ObjectSurface,
        contact: Contact,
        attempt: usize,
        likelihood: &Likelihood,
        moves: &MoveSpread,
        iterations: usize,
    ) {
        let predicted = self.predicted(attempt.saturating_sub(self.attempt), moves);
        self.attempt = self.attempt.max(attempt);
        let mean = self.pose;
        let evidence = self.pose.score;
        let fitted = self.pose.fitted(iterations, |h| {
            let mut at = h.linearise(surface, &contact, likelihood);
            add_gaussian_prior(&mut at, &offset(h, &mean), &predicted);
            at
        });
        // Laplace about the updated pose: the contact's likelihood and the prior there, times the
        // ratio of the prior's and the posterior's normalisers (the fit's Hessian holds both).
        let updated = fitted.hessian;
        let (Some(before), Some(after)) = (log_det(&predicted), log_det(&updated)) else {
            self.pose.score = evidence + fitted.score;
            return;
        };
        self.pose.score = evidence + fitted.score + 0.5 * (before - after);
        self.information = updated;
    }

    /// The information after `moves` more moves: the covariance grows by each move's spread.
    fn predicted(&self, moves: usize, spread: &MoveSpread) -> Matrix6<f64> {
        let still = spread.turn_var_rad2 == 0.0 && spread.shift_var_m2 == 0.0 && spread.height_var_m2 == 0.0;
        if moves == 0 || still {
            return self.information;
        }
        let Some(covariance) = self.information.try_inverse() else {
            return self.information;
        };
        let m = moves as f64;
        let q = [
            spread.turn_var_rad2,
            spread.turn_var_rad2,
            spread.turn_var_rad2,
            spread.shift_var_m2,
            spread.shift_var_m2,
            spread.height_var_m2,
        ];
        let grown = covariance + Matrix6::from_diagonal(&Vector6::from_iterator(q.iter().map(|v| m * v)));
        grown.try_inverse().unwrap_or(self.information)
    }
}

/// The step from `mean` to `h`: the world turn and the centre's move.
fn offset(h: &Hypothesis, mean: &Hypothesis) -> Vector6<f64> {
    let turn = (h.rotation * mean.rotation.inverse()).to_scaled_axis();
    let shift = h.center_w - mean.center_w;
    Vector6::new(turn.x, turn.y, turn.z, shift.x, shift.y, shift.z)
}

/// Adds the Gaussian prior `N(0, information^-1)` on the offset `delta` (score, gradient and
/// Hessian of the cost, as `pose_fit` keeps them), up to its normaliser.
fn add_gaussian_prior(at: &mut Linearised, delta: &Vector6<f64>, information: &Matrix6<f64>) {
    let pulled = information * delta;
    at.score -= 0.5 * delta.dot(&pulled);
    at.gradient += pulled;
    at.hessian += information;
}

fn log_det(m: &Matrix6<f64>) -> Option<f64> {
    let c = m.cholesky()?;
    let l = c.l();
    Some(2.0 * (0..6).map(|k| l[(k, k)].ln()).sum::<f64>())
}
