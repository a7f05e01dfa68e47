//! Poses in the world frame (metres, unit quaternions): the rigid transform of a body ([`Pose`]:
//! objects, mocap bodies, the arm's links) and where the sensor pad is ([`PadPose`]: its centre,
//! normal and up, the frame a tactile image is taken in and the dataset's nine `pad_*` columns).
//!
//! The two meet at the pad site (`mjcf/arm.xml`'s `pad`, the free pad's `pad`), whose frame is the
//! pad frame by this convention: site +z is the pad normal, site +y is `up` (toward image row 0),
//! and site +x is `up x normal`, which is `-PadPose::right()` (the image's columns run along
//! `normal x up`, the viewer's right looking along the normal from behind the pad; a rotation needs
//! the right-handed frame). [`PadPose::of_site`] and [`PadPose::site_pose`] are the one conversion
//! between the two, and [`rotation_from_xmat`] the one reading of MuJoCo's `xmat`.
//!
//! [`StartPose`] says where an object starts before it is explored: the pose it was built in, or
//! one drawn at random (the draw is the scene's, `sim::Scene::place_at_start`). It is plain data
//! here, beside the poses, because both the world that draws it and the dataset header that
//! records it (`dataset`, which knows no MuJoCo) name it.

use glam::{DMat3, DQuat, DVec3};
use serde::{Deserialize, Serialize};

/// The world rotation of MuJoCo's row-major 3x3 `xmat` (`site_xmat`, `geom_xmat`, `xmat`, nine
/// values from `xmat[0]`): its columns are the frame's x, y and z axes in world coordinates.
#[inline]
pub fn rotation_from_xmat(xmat: &[f64]) -> DMat3 {
    DMat3::from_cols(
        DVec3::new(xmat[0], xmat[3], xmat[6]),
        DVec3::new(xmat[1], xmat[4], xmat[7]),
        DVec3::new(xmat[2], xmat[5], xmat[8]),
    )
}

/// A rigid transform: a point `p` of the body frame is at `rotation * p + position_m` in the world.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Pose {
    pub position_m: DVec3,
    pub rotation: DQuat,
}

impl Default for Pose {
    fn default() -> Self {
        Self::IDENTITY
    }
}

impl Pose {
    pub const IDENTITY: Self = Self {
        position_m: DVec3::ZERO,
        rotation: DQuat::IDENTITY,
    };

    /// How far the body's up axis (its frame's z) leans from the world's vertical, radians: 0
    /// for an object standing as it was built, whatever its heading.
    pub fn tilt_rad(&self) -> f64 {
        (self.rotation * DVec3::Z).angle_between(DVec3::Z)
    }

    pub fn new(position_m: DVec3, rotation: DQuat) -> Self {
        Self {
            position_m,
            rotation: rotation.normalize(),
        }
    }

    /// A body point in world coordinates.
    pub fn transform_point(&self, p: DVec3) -> DVec3 {
        self.rotation * p + self.position_m
    }

    /// A body direction in world coordinates.
    pub fn transform_vector(&self, v: DVec3) -> DVec3 {
        self.rotation * v
    }

    /// The inverse transform (world to body).
    pub fn inverse(&self) -> Self {
        let r = self.rotation.inverse();
        Self {
            position_m: -(r * self.position_m),
            rotation: r,
        }
    }

    /// `self` after `other`: first `other`, then `self` (`(self * other)(p) = self(other(p))`).
    pub fn compose(&self, other: &Pose) -> Self {
        Self::new(
            self.transform_point(other.position_m),
            self.rotation * other.rotation,
        )
    }

    /// MuJoCo's quaternion order (w, x, y, z).
    pub fn mujoco_quat(&self) -> [f64; 4] {
        [self.rotation.w, self.rotation.x, self.rotation.y, self.rotation.z]
    }

    /// From MuJoCo's position and row-major rotation matrix (`site_xpos`, `site_xmat`).
    pub fn from_xmat(pos: [f64; 3], xmat: &[f64]) -> Self {
        Self::new(
            DVec3::from_array(pos),
            DQuat::from_mat3(&rotation_from_xmat(xmat)),
        )
    }

    /// From MuJoCo's position and (w, x, y, z) quaternion.
    pub fn from_mujoco(pos: [f64; 3], quat: [f64; 4]) -> Self {
        Self::new(
            DVec3::from_array(pos),
            DQuat::from_xyzw(quat[1], quat[2], quat[3], quat[0]),
        )
    }
}

/// Where an object starts on the table before it is explored.
///
/// A recogniser learns whatever tells its training objects apart. Started at the pose its mesh was
/// built in, every object stands at the same place in the same heading run after run, and "a
/// model that uses contact positions could learn the canonical pose instead of the object": a
/// random start, which the explorer is not told, leaves the pose nothing to teach. The draw
/// (`sim::Scene::place_at_start`) is the demo's: a heading about the vertical through the
/// object's bounding-box centre within [`MaxHeading`], then the perturbation of Sec. V-B4 (a tilt
/// of up to 10 degrees about a random axis, a shift of up to 10% of the object's width), the
/// object resting on the table.
///
/// Serialised as `"canonical"`, `{"random":{"max_heading_rad":...}}` or
/// `{"turned":{"heading_rad":...}}`; what records it (a
/// collection plan, a dataset header) leaves a canonical start out, so that everything written
/// before start poses existed reads, and is written, as it was.
///
/// ```
/// use taction::pose::{MaxHeading, StartPose};
///
/// assert!(StartPose::default().is_canonical());
/// let letters = StartPose::parse("random", MaxHeading::LETTERS).unwrap();
/// assert_eq!(letters.name(), "random");
/// assert_eq!(letters.max_heading(), Some(MaxHeading::LETTERS));
/// let quarter = StartPose::parse("turned:90", MaxHeading::ANY).unwrap();
/// assert_eq!(quarter.to_string(), "turned (heading 90 deg)");
/// // A letter turned by 90 degrees is not the letter any more.
/// assert_eq!(StartPose::parse("turned:90", MaxHeading::LETTERS), None);
/// assert_eq!(StartPose::parse("upside-down", MaxHeading::ANY), None);
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum StartPose {
    /// The pose the object was built in (the identity): every run's start before start poses
    /// existed, and still the default.
    #[default]
    Canonical,
    /// A pose drawn from the run's seed, turned at most `max_heading` from the built heading.
    Random {
        #[serde(rename = "max_heading_rad")]
        max_heading: MaxHeading,
    },
    /// A random start at one fixed heading: the same tilt and shift as [`Random`](Self::Random),
    /// drawn from the seed, every object turned by `heading` about the vertical. The control that
    /// shows whether a recogniser of contact positions learnt the canonical heading: its accuracy
    /// must not change when every object faces one way, whichever.
    Turned {
        #[serde(rename = "heading_rad")]
        heading: Heading,
    },
}

/// A turn about the vertical in (-pi, pi] radians, finite: the heading of
/// [`StartPose::Turned`].
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "f64", into = "f64")]
pub struct Heading {
    rad: f64,
}

impl Heading {
    /// `deg` degrees, wrapped into (-180, 180]; `None` when not finite.
    pub fn from_deg(deg: f64) -> Option<Self> {
        deg.is_finite().then(|| {
            let wrapped = -(180.0 - deg).rem_euclid(360.0) + 180.0;
            Self {
                rad: wrapped.to_radians(),
            }
        })
    }

    pub fn rad(&self) -> f64 {
        self.rad
    }

    pub fn deg(&self) -> f64 {
        self.rad.to_degrees()
    }
}

impl TryFrom<f64> for Heading {
    type Error = String;

    /// Radians in [-pi, pi], as a plan or a header records it.
    fn try_from(rad: f64) -> Result<Self, String> {
        if (-std::f64::consts::PI..=std::f64::consts::PI).contains(&rad) {
            Ok(Self { rad })
        } else {
            Err(format!("heading_rad {rad} is outside [-pi, pi]"))
        }
    }
}

impl From<Heading> for f64 {
    fn from(heading: Heading) -> f64 {
        heading.rad
    }
}

impl StartPose {
    /// The names [`name`](Self::name) gives and [`parse`](Self::parse) takes (the CLI's
    /// `--start-pose` values); a turned start is written `turned:DEG`.
    pub const NAMES: [&'static str; 3] = ["canonical", "random", "turned:DEG"];

    /// A random start turned at most `max_heading` about the vertical.
    pub fn random(max_heading: MaxHeading) -> Self {
        Self::Random { max_heading }
    }

    /// Whether this is [`Canonical`](Self::Canonical), the start a record leaves out.
    pub fn is_canonical(&self) -> bool {
        matches!(self, Self::Canonical)
    }

    /// `canonical`, `random` or `turned`.
    pub fn name(&self) -> &'static str {
        match self {
            Self::Canonical => Self::NAMES[0],
            Self::Random { .. } => Self::NAMES[1],
            Self::Turned { .. } => "turned",
        }
    }

    /// The start called `name` ([`NAMES`](Self::NAMES)): a random one turned at most
    /// `max_heading` (the heading is the object set's to say, [`MaxHeading`], not the name's), or
    /// `turned:DEG`, which must lie within `max_heading` too (a raised letter turned further is
    /// another letter).
    pub fn parse(name: &str, max_heading: MaxHeading) -> Option<Self> {
        match name {
            "canonical" => Some(Self::Canonical),
            "random" => Some(Self::random(max_heading)),
            _ => {
                let deg: f64 = name.strip_prefix("turned:")?.trim().parse().ok()?;
                let heading = Heading::from_deg(deg)?;
                (heading.rad().abs() <= max_heading.rad() + 1e-12).then_some(Self::Turned { heading })
            }
        }
    }

    /// The largest turn about the vertical of a random start; `None` for the canonical one.
    pub fn max_heading(&self) -> Option<MaxHeading> {
        match self {
            Self::Canonical | Self::Turned { .. } => None,
            Self::Random { max_heading } => Some(*max_heading),
        }
    }
}

impl std::fmt::Display for StartPose {
    /// `canonical`, `random (any heading)`, `random (heading within 10 deg)` or
    /// `turned (heading 90 deg)`.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::Canonical => f.write_str(self.name()),
            Self::Turned { heading } => write!(
                f,
                "{} (heading {} deg)",
                self.name(),
                crate::units::significant(heading.deg())
            ),
            Self::Random { max_heading } if max_heading.is_any() => {
                write!(f, "{} (any heading)", self.name())
            }
            Self::Random { max_heading } => write!(
                f,
                "{} (heading within {} deg)",
                self.name(),
                crate::units::significant(max_heading.rad().to_degrees())
            ),
        }
    }
}

/// The largest turn about the vertical a random [`StartPose`] gives an object, from the heading
/// it was built in, in [0, pi] radians; pi is any heading.
///
/// How far is the object set's to say (`mesh::ObjectSet::start_heading`): an object that looks
/// the same from every side, or whose identity does not change with where it faces, takes any
/// heading; a raised letter does not, since its heading is part of its identity ('b' turned by
/// 180 degrees about the vertical is 'q', 'd' is 'p', 'n' is 'u', 'M' is 'W'), so it keeps its
/// face up and its heading within [`LETTERS`](Self::LETTERS).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "f64", into = "f64")]
pub struct MaxHeading {
    rad: f64,
}

impl MaxHeading {
    /// Any heading: a turn drawn uniformly over the full turn.
    pub const ANY: Self = Self {
        rad: std::f64::consts::PI,
    };
    /// Objects whose heading is part of their identity, the raised letters: within 10 degrees,
    /// the tilt of Sec. V-B4's perturbation, of the heading they were built in.
    pub const LETTERS: Self = Self {
        rad: 10.0_f64.to_radians(),
    };

    /// At most `deg` degrees either way, in [0, 180] (180: any heading); `None` outside it or not
    /// finite.
    pub fn from_deg(deg: f64) -> Option<Self> {
        if deg == 180.0 {
            Some(Self::ANY)
        } else {
            (0.0..180.0).contains(&deg).then(|| Self {
                rad: deg.to_radians(),
            })
        }
    }

    /// The largest turn, radians.
    pub fn rad(&self) -> f64 {
        self.rad
    }

    /// Whether every heading can be drawn.
    pub fn is_any(&self) -> bool {
        self.rad >= std::f64::consts::PI
    }
}

impl TryFrom<f64> for MaxHeading {
    type Error = String;

    /// Radians in [0, pi], as a plan or a header records it.
    fn try_from(rad: f64) -> Result<Self, String> {
        if (0.0..=std::f64::consts::PI).contains(&rad) {
            Ok(Self { rad })
        } else {
            Err(format!("max_heading_rad {rad} is outside [0, pi]"))
        }
    }
}

impl From<MaxHeading> for f64 {
    fn from(heading: MaxHeading) -> f64 {
        heading.rad
    }
}

/// Where the pad is: its frame in world coordinates, as a tactile image records it (see the module
/// docs for how it relates to the pad site's [`Pose`]).
///
/// ```
/// use glam::DVec3;
/// use taction::pose::PadPose;
///
/// // A pad 5 cm above the origin, pressing down, image row 0 toward +y.
/// let pad = PadPose::new(DVec3::new(0.0, 0.0, 0.05), -DVec3::Z, DVec3::Y).unwrap();
/// let back = PadPose::of_site(&pad.site_pose());
/// assert!((back.normal - pad.normal).length() < 1e-12 && (back.up - pad.up).length() < 1e-12);
/// assert_eq!(pad.right(), DVec3::X);
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct PadPose {
    /// Centre of the pad surface (the back of the covering), metres.
    pub center_m: DVec3,
    /// Unit normal pointing from the pad into the covering, toward the object.
    pub normal: DVec3,
    /// Unit vector in the pad plane toward image row 0.
    pub up: DVec3,
}

impl PadPose {
    /// Builds a pose from any normal and a hint for `up`; `up` is made orthogonal to the normal
    /// (Gram-Schmidt). Returns `None` when the normal is zero or not finite, or `up` is parallel to it.
    pub fn new(center_m: DVec3, normal: DVec3, up_hint: DVec3) -> Option<Self> {
        let normal = normal.try_normalize()?;
        let up = (up_hint - normal * up_hint.dot(normal)).try_normalize()?;
        center_m.is_finite().then_some(Self { center_m, normal, up })
    }

    /// Unit vector in the pad plane toward the last image column: `normal x up`: the image's right
    /// as seen from behind the pad, looking along the normal ((right, up, -normal) is right-handed).
    pub fn right(&self) -> DVec3 {
        self.normal.cross(self.up)
    }

    /// A direction in the pad frame (`x` along [`right`](Self::right), `y` along `up`, `z` along
    /// the normal) in world coordinates.
    pub fn transform_vector(&self, v: DVec3) -> DVec3 {
        self.right() * v.x + self.up * v.y + self.normal * v.z
    }

    /// A point in the pad frame (metres from the centre, axes as
    /// [`transform_vector`](Self::transform_vector)'s) in world coordinates.
    pub fn transform_point(&self, p: DVec3) -> DVec3 {
        self.center_m + self.right() * p.x + self.up * p.y + self.normal * p.z
    }

    /// The pad frame of a pad site at world pose `site`: centre at the site, normal its +z, up its
    /// +y (the module's convention).
    pub fn of_site(site: &Pose) -> Self {
        Self {
            center_m: site.position_m,
            normal: site.transform_vector(DVec3::Z).normalize(),
            up: site.transform_vector(DVec3::Y).normalize(),
        }
    }

    /// The pad frame of the site at MuJoCo's `site_xpos` / `site_xmat`; `None` when `xmat` is no
    /// rotation (all zeros before the first kinematics) or the position is not finite.
    pub fn of_site_xmat(pos: [f64; 3], xmat: &[f64]) -> Option<Self> {
        let frame = rotation_from_xmat(xmat);
        let rotation = frame.is_finite() && (frame.determinant() - 1.0).abs() < 1e-6;
        let pose = Self::of_site(&Pose::from_xmat(pos, xmat));
        (rotation && pose.center_m.is_finite()).then_some(pose)
    }

    /// The world rotation of the pad site at this pose: site (x, y, z) = (`up x normal`, `up`,
    /// `normal`), the module's convention.
    pub fn site_rotation(&self) -> DQuat {
        DQuat::from_mat3(&DMat3::from_cols(
            self.up.cross(self.normal),
            self.up,
            self.normal,
        ))
        .normalize()
    }

    /// The world pose of the pad site at this pose; [`PadPose::of_site`] inverts it.
    pub fn site_pose(&self) -> Pose {
        Pose::new(self.center_m, self.site_rotation())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_turned_start_wraps_its_heading_and_reads_back_from_a_header() {
        let deg = |d: f64| Heading::from_deg(d).map(|h| (h.deg() * 1e9).round() / 1e9);
        assert_eq!(deg(270.0), Some(-90.0));
        assert_eq!(deg(-180.0), Some(180.0));
        assert_eq!(deg(540.0), Some(180.0));
        assert_eq!(deg(f64::NAN), None);
        let turned = StartPose::parse("turned:-45", MaxHeading::ANY).expect("a turn");
        let json = serde_json::to_string(&turned).expect("encodes");
        assert!(
            json.starts_with(r#"{"turned":{"heading_rad":-0.785398"#),
            "{json}"
        );
        assert_eq!(serde_json::from_str::<StartPose>(&json).expect("decodes"), turned);
        let beyond = r#"{"turned":{"heading_rad":4.0}}"#;
        let e = serde_json::from_str::<StartPose>(beyond).expect_err("refused");
        assert!(
            e.to_string().contains("heading_rad 4 is outside [-pi, pi]"),
            "{e}"
        );
        // A letter turned within its 10 degrees is still the letter; further, another one.
        assert!(StartPose::parse("turned:10", MaxHeading::LETTERS).is_some());
        assert_eq!(StartPose::parse("turned:11", MaxHeading::LETTERS), None);
    }

    #[test]
    fn inverse_and_compose_round_trip() {
        let a = Pose::new(
            DVec3::new(0.1, -0.2, 0.3),
            DQuat::from_euler(glam::EulerRot::XYZ, 0.3, -0.7, 1.1),
        );
        let b = Pose::new(DVec3::new(-0.5, 0.05, 0.2), DQuat::from_rotation_z(0.4));
        let p = DVec3::new(0.7, 0.1, -0.9);
        assert!((a.inverse().transform_point(a.transform_point(p)) - p).length() < 1e-12);
        assert!(
            (a.compose(&b).transform_point(p) - a.transform_point(b.transform_point(p))).length() < 1e-12
        );
        let m = Pose::from_mujoco(a.position_m.to_array(), a.mujoco_quat());
        assert!((m.transform_point(p) - a.transform_point(p)).length() < 1e-12);
    }

    #[test]
    fn the_site_frame_and_the_pad_frame_convert_both_ways() {
        let pad = PadPose::new(
            DVec3::new(0.1, -0.2, 0.3),
            DVec3::new(0.3, -1.0, 0.2),
            DVec3::new(0.5, 0.2, 1.0),
        )
        .unwrap();
        let site = pad.site_pose();
        // Site x is up x normal = -right; the frame is right-handed.
        assert!((site.transform_vector(DVec3::X) + pad.right()).length() < 1e-12);
        let back = PadPose::of_site(&site);
        assert!((back.center_m - pad.center_m).length() < 1e-15);
        assert!((back.normal - pad.normal).length() < 1e-12 && (back.up - pad.up).length() < 1e-12);
        // The same frame read from MuJoCo's row-major xmat.
        let m = DMat3::from_quat(site.rotation);
        let xmat = m.transpose().to_cols_array();
        assert_eq!(rotation_from_xmat(&xmat), m);
        let from_xmat = PadPose::of_site_xmat(pad.center_m.to_array(), &xmat).unwrap();
        assert_eq!(PadPose::of_site_xmat([0.0; 3], &[0.0; 9]), None);
        assert!((from_xmat.normal - pad.normal).length() < 1e-12 && (from_xmat.up - pad.up).length() < 1e-12);
    }

    #[test]
    fn pad_right_is_the_image_right_seen_from_behind() {
        let pose = PadPose::new(DVec3::ZERO, DVec3::new(0.0, 0.0, -2.0), DVec3::new(0.0, 1.0, 0.3)).unwrap();
        assert!((pose.normal - DVec3::NEG_Z).length() < 1e-12);
        assert!((pose.up - DVec3::Y).length() < 1e-12);
        // Looking down -z with +y up, the right of the image is +x.
        assert!((pose.right() - DVec3::X).length() < 1e-12);
        assert!(PadPose::new(DVec3::ZERO, DVec3::Z, DVec3::Z).is_none());
    }
}
