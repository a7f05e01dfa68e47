//! The covering presses back (beyond the paper; issue 74): the penetration the sensor measures,
//! as the force the soft covering exerts on what it touches and, equal and opposite, on the pad.
//!
//! The paper's covering only forms an image (Sec. V-A2); a mocap object feels nothing. An object
//! on a free joint, though, answers a press only if the covering pushes it, and the pad's rigid
//! back does not collide with the object (`mjcf/arm.xml`), so this force is the whole of the
//! pad's push. The model is the elastic foundation (Winkler) of a thin layer with a viscous
//! term (Kelvin-Voigt): each sample of the pad grid is a column of covering of its area `dA`,
//! compressed by the penetration `d` the sensor computes (`covering.rs`), pushing along the pad
//! normal with pressure
//!
//! ```text
//! p = (E / t) (d + tau * dd/dt),   p >= 0 (a covering does not pull)
//! ```
//!
//! `E` the covering's Young's modulus ([`CoveringModulus`]), `t` its thickness, `tau`
//! ([`RELAXATION_S`]) its relaxation time. The force acts where the object's surface meets the
//! column. The plugin applies it in MuJoCo's passive stage (`plugin.rs`), so `mj_step` integrates
//! it with gravity and contacts, and MuJoCo's own tools (its viewer, its Python bindings with the
//! plugin library) step the same physics. A modulus of zero, every scene's default, applies
//! nothing: the paper's sensor.

use glam::DVec3;

use crate::valid::checked_f64;

/// The largest covering modulus accepted: 1 GPa, a hard plastic, far beyond any soft skin.
pub const MAX_MODULUS_PA: f64 = 1e9;

checked_f64! {
    /// The covering's Young's modulus `E`, pascals: how hard it pushes back per unit strain
    /// (`d / t`). Zero: it pushes nothing (the paper's sensor, and every mocap object's scene).
    pub struct CoveringModulus(modulus_pa) where (0.0..=MAX_MODULUS_PA).contains(&modulus_pa);
    /// A covering modulus out of range, or no number.
    pub enum CoveringModulusError {
        OutOfRange = "covering modulus {0} Pa is out of range: want pascals in [0, 1e9]",
        NotANumber = "'{0}' is not a covering modulus in pascals",
    }
}

impl CoveringModulus {
    /// No force: the paper's covering.
    pub const NONE: Self = Self(0.0);

    /// The covering of a free object's scene: an ultra-soft gel of 300 Pa (hydrogels and the
    /// softest silicone gels are 0.1-10 kPa). Press's target, a mean penetration of 0.3 t under
    /// the whole 12 mm pad (Sec. III-B), is then 13 mN: the shapes at 12 cm are light (28-125 g
    /// as solids of 1000 kg/m3: thin legs and tails), and a press of this size leaves every one
    /// of them where it stood, a few micrometres a touch (docs/measurements.md, "The object is a
    /// body MuJoCo moves"), where 1 kPa tipped Homer by 4 degrees a touch on average.
    pub const SOFT_GEL: Self = Self(300.0);

    /// Whether the covering pushes at all.
    pub fn is_none(self) -> bool {
        self.0 == 0.0
    }
}

/// The covering's relaxation time `tau`, seconds: the viscous part of its pressure, which damps
/// an object bouncing on it, as a real gel's losses do. On the whole 12 mm pad of the
/// [`CoveringModulus::SOFT_GEL`] (`K = E A / t`, 36 N/m) a 28 g object is damped at half of
/// critical (`tau / (2 sqrt(m / K))`), a 125 g one at a quarter. The force is explicit in MuJoCo's
/// step, stable while `tau K dt / m < 2`: a stiffer covering set by hand (`modulus_pa`) wants a
/// heavier object or a shorter timestep.
pub const RELAXATION_S: f64 = 0.03;

/// The pressure of one column of covering, pascals (the module docs' law): `penetration_m` the
/// compression `d`, `rate_m_per_s` how fast it grows.
pub fn column_pressure_pa(
    modulus: CoveringModulus,
    thickness_m: f64,
    penetration_m: f64,
    rate_m_per_s: f64,
) -> f64 {
    if penetration_m <= 0.0 {
        return 0.0;
    }
    (modulus.get() / thickness_m * (penetration_m + RELAXATION_S * rate_m_per_s)).max(0.0)
}

/// What the covering does to one body it touches: the force on the body and its moment about
/// the pad's origin, both in the world frame. The pad feels the opposite of both.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BodyPress {
    /// The MuJoCo body pressed.
    pub body: usize,
    /// Newtons, world frame.
    pub force_n: DVec3,
    /// Newton-metres about `about_m`, world frame.
    pub torque_nm: DVec3,
    /// The point the torque is about: the pad site's origin, metres, world frame.
    pub about_m: DVec3,
}

impl BodyPress {
    /// No push yet on `body`, its moments about `about_m`.
    pub fn none(body: usize, about_m: DVec3) -> Self {
        Self {
            body,
            force_n: DVec3::ZERO,
            torque_nm: DVec3::ZERO,
            about_m,
        }
    }

    /// Adds a column's force `force_n` acting at `point_m` (world).
    pub fn add(&mut self, force_n: DVec3, point_m: DVec3) {
        self.force_n += force_n;
        self.torque_nm += (point_m - self.about_m).cross(force_n);
    }
}

/// The sum of the forces of `presses`.
pub fn total_force_n(presses: &[BodyPress]) -> DVec3 {
    presses.iter().map(|p| p.force_n).sum()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_column_pushes_by_the_elastic_foundation_and_never_pulls() {
        let e = CoveringModulus::new(20_000.0).unwrap();
        // Half the thickness compressed, at rest: E/2.
        assert!((column_pressure_pa(e, 0.002, 0.001, 0.0) - 10_000.0).abs() < 1e-9);
        // Compressing adds the viscous part; a fast release cannot pull.
        assert!((column_pressure_pa(e, 0.002, 0.001, 0.5 / 0.03 * 0.001) - 10_000.0 * 1.5).abs() < 1e-9);
        assert_eq!(column_pressure_pa(e, 0.002, 0.001, -10.0), 0.0);
        assert_eq!(column_pressure_pa(e, 0.002, 0.0, 1.0), 0.0);
        assert_eq!(column_pressure_pa(CoveringModulus::NONE, 0.002, 0.001, 0.0), 0.0);
        assert!(CoveringModulus::new(-1.0).is_err() && CoveringModulus::new(2e9).is_err());
    }

    #[test]
    fn a_column_off_the_axis_turns_the_body_about_the_pad() {
        let mut press = BodyPress::none(1, DVec3::ZERO);
        press.add(DVec3::Z, DVec3::new(0.01, 0.0, 0.001));
        press.add(DVec3::Z, DVec3::new(-0.01, 0.0, 0.001));
        assert_eq!(press.force_n, DVec3::new(0.0, 0.0, 2.0));
        assert!(press.torque_nm.length() < 1e-15, "symmetric columns balance");
        press.add(DVec3::Z, DVec3::new(0.0, 0.02, 0.0));
        assert!((press.torque_nm - DVec3::new(0.02, 0.0, 0.0)).length() < 1e-15);
    }
}
