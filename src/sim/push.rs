//! Sec. V-B4's perturbation as a physical act (beyond the paper; issue 74): a free object is
//! pushed between readings, as a hand would nudge it, and the table's friction and its own
//! inertia answer.
//!
//! A push is a force at the object's base (just above the table, under its centre, so that it
//! slides rather than tips as it would if pushed high) and a twist about the vertical through its
//! centre of mass, applied through MuJoCo (`xfrc_applied`) step by step while the arm holds still.
//! The hand moves the object at a steady pace ([`SHOVE_M_PER_S`], [`TWIST_RAD_PER_S`]) toward the
//! draw's shift along the table and its turn about the vertical, each force a proportional-integral
//! answer to the object's speed against the pace (the integral finds the friction to overcome,
//! whatever the object's supports), brakes it there and lets go; the object then comes to rest
//! ([`Scene::settle_object`]). What it does on the way is the dynamics': how hard it must be
//! pushed to slide and turn (its mass, its supports, the table's friction), where it sticks and
//! jerks free. A standing object cannot be left tilted as a teleport leaves it, so the turn is the
//! draw's angle about the vertical (its sense the axis's); the shift is the draw's.
//!
//! The hand also holds the object upright as it goes, as a palm against its side does: a stiff
//! proportional-derivative torque about the horizontal axes toward the attitude it stood in
//! ([`STEADY_P_PER_S2`]). Without it the supports' friction and the push's start and stop rocked
//! the rounded shapes (turning the hand and the camel 15-26% more than the draw) and tipped those
//! standing with their weight near the edge of their supports: the bunny, its centre of mass 2 mm
//! inside them, under 20 of 40 pushes. And a stuck object frees itself in a jerk (a 3 x 3 x 10 cm
//! post turns in steps of about a degree), so an integral wound the way the object must no longer
//! go is dropped ([`Hand::wind`]): the hand goes back at once instead of pushing on past the draw,
//! which turned the post 15% more than the teleport.

use glam::{DMat3, DQuat, DVec3};

use crate::sim::SimError;
use crate::sim::free_object::{ObjectMotion, REST_SPEED_M_PER_S, REST_TURN_RAD_PER_S, TIPPED_RAD};
use crate::sim::perturb::Perturbation;
use crate::sim::scene::Scene;

/// The pace of a push along the table, metres per second: a slow hand, so that braking at the
/// end (a few millimetres a second lost in a step) neither tips a tall object nor lets it coast.
pub const SHOVE_M_PER_S: f64 = 0.05;

/// The pace of a push's twist, radians per second.
pub const TWIST_RAD_PER_S: f64 = 1.0;

/// The longest a push may last, seconds: a shift of 10% of a 12 cm object at the pace takes a
/// quarter of a second; an object held back (by the arm's links, say) is let go after this.
pub const PUSH_MAX_S: f64 = 2.0;

/// The push's proportional gain on the speed error, per second, and its integral gain, per second
/// squared: a speed loop critically damped at 50 rad/s, well inside the 2 ms step's stability.
const GAIN_P_PER_S: f64 = 300.0;
const GAIN_I_PER_S2: f64 = 2500.0;

/// The stiffness, per second squared, and damping, per second, of the hand's hold on the object's
/// attitude: critically damped at 100 rad/s (0.2 rad a 2 ms step), so that the moment of the
/// supports' friction (about 200 rad/s^2 over the bunny's inertia) tilts it about a degree while
/// it slides; held at 50 rad/s, the bunny still tipped under one push in 40.
const STEADY_P_PER_S2: f64 = 10_000.0;
const STEADY_D_PER_S: f64 = 200.0;

/// How much more than friction's estimate the hand may push with: enough to free an object the
/// estimate underrates.
const FRICTION_MARGIN: f64 = 1.5;

/// Standard gravity, m/s^2: the scene's (MuJoCo's default, which `mjcf/scene.xml` keeps).
const GRAVITY_M_PER_S2: f64 = 9.81;

/// How far above the table the push acts, metres.
const PUSH_HEIGHT_M: f64 = 0.002;

/// The hand slows over the last this-many seconds of its way at its pace (2.5 mm, 2.9 deg).
const SLOWING_S: f64 = 0.05;

/// Close enough to where the push takes the object, metres and radians.
const ARRIVED_M: f64 = 2e-4;
const ARRIVED_RAD: f64 = 2e-3;

/// The state of one push: where it began and what its loops have integrated.
struct Hand {
    start_centre_m: DVec3,
    start_rotation: DQuat,
    direction: DVec3,
    shift_m: f64,
    turn_rad: f64,
    sense: f64,
    slide_integral_m: DVec3,
    twist_integral_rad: f64,
    /// The object's tilt at the last step (a rotation vector about the horizontal axes).
    last_tilt: DVec3,
}

impl Hand {
    /// The object's centre's shift and its turn about the vertical since the push began.
    fn progress(&self, centre_m: DVec3, rotation: DQuat) -> (DVec3, f64) {
        let turn = rotation * self.start_rotation.inverse();
        let twist_rad = 2.0 * turn.z.atan2(turn.w);
        let twist_rad =
            (twist_rad + std::f64::consts::PI).rem_euclid(std::f64::consts::TAU) - std::f64::consts::PI;
        (
            (centre_m - self.start_centre_m) * DVec3::new(1.0, 1.0, 0.0),
            twist_rad,
        )
    }

    /// What is left to do: the shift along the push and the turn in its sense (negative past it).
    fn remaining(&self, shifted: DVec3, twisted_rad: f64) -> (f64, f64) {
        (
            self.shift_m - shifted.dot(self.direction),
            self.turn_rad - twisted_rad * self.sense,
        )
    }

    /// The pace wanted now: the hand's pace toward what is left, slowing over the last
    /// [`SLOWING_S`] of it so the object arrives rather than overshoots (back, gently, if it
    /// did); nothing across the push.
    fn pace(&self, shifted: DVec3, twisted_rad: f64) -> (DVec3, f64) {
        let (slide_left, turn_left) = self.remaining(shifted, twisted_rad);
        let slide = (slide_left / SLOWING_S).clamp(-SHOVE_M_PER_S, SHOVE_M_PER_S);
        let twist = (turn_left / SLOWING_S).clamp(-TWIST_RAD_PER_S, TWIST_RAD_PER_S);
        (self.direction * slide, self.sense * twist)
    }

    /// Adds the speed errors to the integrals, which find the friction to overcome and never much
    /// more (`bounds`, the slide's and the twist's): a stuck object is freed, not flung. An
    /// integral wound against the pace (the object went past where the hand takes it) is dropped
    /// first.
    fn wind(&mut self, paces: (DVec3, f64), errors: (DVec3, f64), dt: f64, bounds: (f64, f64)) {
        if self.slide_integral_m.dot(paces.0) < 0.0 {
            self.slide_integral_m = DVec3::ZERO;
        }
        if self.twist_integral_rad * paces.1 < 0.0 {
            self.twist_integral_rad = 0.0;
        }
        self.slide_integral_m = (self.slide_integral_m + errors.0 * dt).clamp_length_max(bounds.0);
        self.twist_integral_rad = (self.twist_integral_rad + errors.1 * dt).clamp(-bounds.1, bounds.1);
    }

    /// The angular acceleration, rad/s^2, that steadies an object at `rotation` back toward
    /// the attitude it started in, about the horizontal axes only (its turn is the twist's): its
    /// tilt is the swing that takes the vertical to where the object's motion has carried it.
    fn steadying(&mut self, rotation: DQuat, dt: f64) -> DVec3 {
        let up = rotation * self.start_rotation.inverse() * DVec3::Z;
        let tilt = DVec3::Z.cross(up).normalize_or_zero() * DVec3::Z.angle_between(up);
        let tilting = (tilt - self.last_tilt) / dt;
        self.last_tilt = tilt;
        -(STEADY_P_PER_S2 * tilt + STEADY_D_PER_S * tilting)
    }

    /// Whether the object is where the push takes it and nearly still there.
    fn is_done(&self, shifted: DVec3, twisted_rad: f64, speed_m_per_s: f64, turning_rad_per_s: f64) -> bool {
        let (slide_left, turn_left) = self.remaining(shifted, twisted_rad);
        slide_left.abs() <= ARRIVED_M
            && turn_left.abs() <= ARRIVED_RAD
            && speed_m_per_s <= REST_SPEED_M_PER_S
            && turning_rad_per_s <= REST_TURN_RAD_PER_S
    }
}

impl Scene {
    /// Pushes the free object by `p` (a teleport's draw, [`PerturbationBounds::draw`]): its
    /// centre `p.translation_m` along the table and a turn of `p.angle_rad` about the vertical
    /// (sense `p.axis.z`'s), then lets it come to rest. Returns how the object moved; an error for
    /// a mocap object, which has no dynamics to push.
    ///
    /// [`PerturbationBounds::draw`]: crate::sim::PerturbationBounds::draw
    pub fn push_object(&mut self, p: &Perturbation) -> Result<ObjectMotion, SimError> {
        if !self.object_is_free() {
            return Err(SimError::BadConfiguration {
                message: "a push needs a free object: a mocap object has no dynamics to push".into(),
            });
        }
        let start = self.object_pose().ok_or(SimError::NoObject)?;
        let shift = p.translation_m * DVec3::new(1.0, 1.0, 0.0);
        let mut hand = Hand {
            start_centre_m: self.object_center().ok_or(SimError::NoObject)?,
            start_rotation: start.rotation,
            direction: shift.normalize_or_zero(),
            shift_m: shift.length(),
            turn_rad: p.angle_rad.abs(),
            sense: if p.axis.z < 0.0 { -1.0 } else { 1.0 },
            slide_integral_m: DVec3::ZERO,
            twist_integral_rad: 0.0,
            last_tilt: DVec3::ZERO,
        };
        let pushed = self.push_with(&mut hand, &start);
        let body = self.object().ok_or(SimError::NoObject)?.body;
        self.data_mut().xfrc_applied_mut()[body] = [0.0; 6];
        pushed?;
        self.settle_object()?;
        self.object_motion_from(&start)
    }

    /// Steps the push's loops until the hand's motion is made, the object tips, or
    /// [`PUSH_MAX_S`] passes; the force is left on the object for the caller to take off.
    fn push_with(&mut self, hand: &mut Hand, start: &crate::pose::Pose) -> Result<(), SimError> {
        let dt = self.model().opt().timestep;
        let body = self.object().ok_or(SimError::NoObject)?.body;
        let mass_kg = self.model().body_mass()[body];
        let inertia_zz_kg_m2 = self.world_inertia(body).z_axis.z;
        let (slide_max, twist_max) = self.friction_decelerations(body, inertia_zz_kg_m2);
        let bounds = (slide_max / GAIN_I_PER_S2, twist_max / GAIN_I_PER_S2);
        let mut last = hand.progress(hand.start_centre_m, start.rotation);
        for _ in 0..(PUSH_MAX_S / dt).round() as usize {
            let pose = self.object_pose().ok_or(SimError::NoObject)?;
            let centre = self.object_center().ok_or(SimError::NoObject)?;
            let (shifted, twisted) = hand.progress(centre, pose.rotation);
            let (velocity, turning) = ((shifted - last.0) / dt, (twisted - last.1) / dt);
            let tilted = ObjectMotion::between(start, &pose, DVec3::ZERO).tilt_rad > TIPPED_RAD;
            if hand.is_done(shifted, twisted, velocity.length(), turning.abs()) || tilted {
                break;
            }
            let (slide_pace, twist_pace) = hand.pace(shifted, twisted);
            let slide_error = slide_pace - velocity;
            let twist_error = twist_pace - turning;
            hand.wind((slide_pace, twist_pace), (slide_error, twist_error), dt, bounds);
            last = (shifted, twisted);
            let force = mass_kg * (GAIN_P_PER_S * slide_error + GAIN_I_PER_S2 * hand.slide_integral_m);
            let twist =
                inertia_zz_kg_m2 * (GAIN_P_PER_S * twist_error + GAIN_I_PER_S2 * hand.twist_integral_rad);
            let com = DVec3::from_array(self.data().xipos()[body]);
            let at_base = DVec3::new(centre.x, centre.y, PUSH_HEIGHT_M);
            let steadying = self.world_inertia(body) * hand.steadying(pose.rotation, dt);
            let torque = (at_base - com).cross(force) + DVec3::Z * twist + steadying;
            self.data_mut().xfrc_applied_mut()[body] = [force.x, force.y, 0.0, torque.x, torque.y, torque.z];
            self.step_holding_the_arm(dt)?;
        }
        Ok(())
    }

    /// The most the friction of the body's supports can decelerate it, sliding (m/s^2) and
    /// turning about the vertical through its centre of mass (rad/s^2, `inertia_zz` its moment of
    /// inertia there), each with [`FRICTION_MARGIN`]: Coulomb's `mu g`, and each support's normal
    /// force (MuJoCo's contact forces at rest) resisting with `mu N r` and its torsional `mu_t N`.
    fn friction_decelerations(&mut self, body: usize, inertia_zz: f64) -> (f64, f64) {
        self.forward();
        let model = self.model();
        let geom_body = model.geom_bodyid();
        let friction = (0..geom_body.len())
            .find(|&g| geom_body[g] as usize == body)
            .map_or([0.0; 3], |g| model.geom_friction()[g]);
        let (slide_mu, torsion_m) = (friction[0], friction[1]);
        let com = DVec3::from_array(self.data().xipos()[body]);
        let mut torque = 0.0;
        for (i, c) in self.data().contact().iter().enumerate() {
            let touches = [c.geom1, c.geom2]
                .iter()
                .any(|&g| geom_body[g as usize] as usize == body);
            let normal_n = self.data().try_contact_force(i).map_or(0.0, |w| w[0].max(0.0));
            if touches {
                let lever_m = (DVec3::from_array(c.pos) - com).truncate().length();
                torque += normal_n * (slide_mu * lever_m + torsion_m);
            }
        }
        (
            FRICTION_MARGIN * slide_mu * GRAVITY_M_PER_S2,
            FRICTION_MARGIN * torque / inertia_zz.max(f64::MIN_POSITIVE),
        )
    }

    /// The body's inertia tensor about its centre of mass in world axes, kg m^2: `R I R^T`, `R`
    /// its principal axes (MuJoCo's `ximat`) and `I` its principal moments.
    fn world_inertia(&self, body: usize) -> DMat3 {
        let principal = DVec3::from_array(self.model().body_inertia()[body]);
        let axes = DMat3::from_cols_array(&self.data().ximat()[body]).transpose();
        axes * DMat3::from_diagonal(principal) * axes.transpose()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A hand taking an object 10 mm along x and turning it 0.2 rad clockwise.
    fn hand() -> Hand {
        Hand {
            start_centre_m: DVec3::new(0.1, 0.0, 0.05),
            start_rotation: DQuat::from_rotation_z(3.0),
            direction: DVec3::X,
            shift_m: 0.01,
            turn_rad: 0.2,
            sense: -1.0,
            slide_integral_m: DVec3::ZERO,
            twist_integral_rad: 0.0,
            last_tilt: DVec3::ZERO,
        }
    }

    #[test]
    fn the_hand_reads_the_turn_about_the_vertical_and_paces_toward_the_draw() {
        let hand = hand();
        // Turned -0.3 rad across the half-turn, shifted 4 mm along and 1 mm up (not counted).
        let rotation =
            DQuat::from_rotation_z(-0.3) * DQuat::from_rotation_z(3.0) * DQuat::from_rotation_x(0.05);
        let (shifted, twisted) = hand.progress(DVec3::new(0.104, 0.0, 0.051), rotation);
        assert!(
            (shifted - DVec3::new(0.004, 0.0, 0.0)).length() < 1e-12,
            "{shifted}"
        );
        assert!((twisted + 0.3).abs() < 1e-3, "{twisted}");
        assert!(
            !hand.is_done(shifted, twisted, 0.0, 0.0),
            "the shift is not covered"
        );
        let (slide, twist) = hand.pace(shifted, twisted);
        assert_eq!(slide, DVec3::X * SHOVE_M_PER_S, "6 mm to go: the full pace");
        assert_eq!(twist, TWIST_RAD_PER_S, "0.1 rad past the turn: back at the pace");
        let there = DVec3::new(0.01, 0.0, 0.0);
        let (slide, _) = hand.pace(DVec3::new(0.009, 0.0, 0.0), -0.2);
        assert!((slide.x - 0.001 / SLOWING_S).abs() < 1e-12, "1 mm to go: slowing");
        assert!(hand.is_done(there, -0.2, 0.0, 0.0));
        assert!(!hand.is_done(there, -0.2, 0.01, 0.0), "still moving");
    }

    #[test]
    fn an_integral_wound_against_the_pace_is_dropped_and_the_others_are_bounded() {
        let mut hand = hand();
        hand.slide_integral_m = DVec3::new(0.002, 0.0, 0.0);
        hand.twist_integral_rad = -0.3;
        // Past the shift (the pace now back along -x), short of the turn (still clockwise).
        hand.wind(
            (DVec3::new(-0.01, 0.0, 0.0), -0.5),
            (DVec3::new(-0.01, 0.0, 0.0), -0.5),
            0.002,
            (1.0, 0.3005),
        );
        assert!(
            (hand.slide_integral_m - DVec3::new(-2e-5, 0.0, 0.0)).length() < 1e-15,
            "dropped, then wound back"
        );
        assert_eq!(hand.twist_integral_rad, -0.3005, "kept, then bounded");
    }

    #[test]
    fn the_hand_steadies_a_tilt_and_leaves_the_turn_about_the_vertical_alone() {
        let mut hand = hand();
        let dt = 0.002;
        // Turned 0.3 rad about the vertical: nothing to steady.
        let turned = DQuat::from_rotation_z(0.3) * hand.start_rotation;
        assert!(hand.steadying(turned, dt).length() < 1e-9);
        // Tilted 0.01 rad about x as well, in one step: pushed back by stiffness and damping.
        let tilted = DQuat::from_rotation_x(0.01) * turned;
        let back = hand.steadying(tilted, dt);
        let want = -(STEADY_P_PER_S2 * 0.01 + STEADY_D_PER_S * 0.01 / dt);
        assert!(
            (back.x - want).abs() < 1e-6 * want.abs() && back.y.abs() < 1e-9 && back.z == 0.0,
            "{back}"
        );
    }
}
