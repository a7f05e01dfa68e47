//! Clearing a sample of a kinematic motion without MuJoCo's collision detection.
//!
//! A kinematic motion (`Arm::move_kinematic`) asks at every sample whether an arm link or the pad's
//! rigid back touches anything (Sec. III-A: collision-free motions). `mj_collision` answers for the
//! whole world: its broad phase bounds every geom of every body, the object's collision shell among
//! them (40-200 convex pieces, `collision_shell.rs`), and it collides the resting object with the
//! table although nothing moved there. Settling the sensor on the surface (Algorithm 1) takes about
//! a thousand samples per reading, at 6 us each: half of a planner's run (issue 39).
//!
//! The screen asks only what the motion needs: is every geom of the arm clear of everything it may
//! touch by more than [`CLEARANCE_M`]? For each arm geom it looks for the other body's geoms in a
//! tree of their bounding spheres (in the body's frame, so the object's tree is built once), within
//! the arm geom's bounding sphere and oriented box; each geom found is bounded by MuJoCo's bounding
//! spheres (`geom_rbound`), then its oriented boxes (`geom_aabb`, the separating-axis theorem), and
//! only a pair whose boxes come within the clearance is measured exactly, with MuJoCo's own
//! `mj_geomDistance` (the same convex hulls and primitives its narrow phase collides). A sample
//! whose every pair is clear cannot have a contact of the arm: it is cleared. Any pair nearer than
//! the clearance leaves the sample to `mj_collision`, which then decides as before. So the motion
//! stops at the same sample with the same [`Collision`](crate::sim::Collision), contact for
//! contact: the screen only skips work on samples where MuJoCo would find no contact of the arm. The clearance is a hundred times MuJoCo's
//! convex-collision tolerance (`ccd_tolerance`, 1e-6), so a pair cleared by its measured distance is
//! apart by far more than either computation's error.
//!
//! Successive samples of a motion are a fraction of a millimetre apart, and the link nearest the
//! surface (the sensor's holder, behind the pad) stays millimetres from it, so bounds are kept
//! (conservative advancement): a pair's distance, and each arm geom's distance from everything
//! outside the arm within 5 mm ([`SETTLE_REACH_M`]), clear later samples while that distance less
//! how far the arm geom can have come nearer since still exceeds the clearance and nothing outside
//! the arm has moved (to the bit). How far a geom can have come nearer: its centre's travel plus
//! the turn of its orientation times its bounding radius; for a capsule, the turn of its axis
//! times its half length (a capsule is the points within its radius of that segment).
//!
//! The pairs screened are those MuJoCo's filters let through (`engine_collision_driver.c`): geoms of
//! different bodies whose contact bits match, bodies not welded together, not both without degrees of
//! freedom, not parent and child (unless the model disables that filter), not excluded. A model
//! with predefined `<pair>`s, flexes, a geom of the arm or one it may touch without bounds (a
//! plane, a height field, a signed distance field), a margin override, sleeping bodies, libccd in
//! place of MuJoCo's native convex collision, or a `ccd_tolerance` above the default is not
//! screened; nor is a process that installs a global contact filter (`mjcb_contactfilter`, which
//! replaces the contact bits; taction never does).

use glam::{DMat3, DVec3};
use mujoco_rs::prelude::*;
use mujoco_rs::wrappers::mj_model::traits::ModelType;

/// How far apart a geom of the arm must be from everything it may touch for a sample to be cleared
/// without `mj_collision`, metres.
pub const CLEARANCE_M: f64 = 1e-4;

/// The largest `ccd_tolerance` the screen trusts `mj_geomDistance` at (MuJoCo's default): its
/// convex distances are within about that of the true ones, far below [`CLEARANCE_M`].
const MAX_CCD_TOLERANCE: f64 = 1e-6;

/// Rounding allowance of the screen's own bounds (sums and products of numbers under a metre),
/// metres.
const ROUNDING_M: f64 = 1e-9;

/// What the screen says of a sample.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Screened {
    /// Every geom of the arm is clear of everything it may touch: no contact of the arm.
    Clear,
    /// Some pair is too near to clear (or cannot be bounded): `mj_collision` decides.
    Undecided,
}

/// The arm's geoms and what each may touch, read once from a compiled model, with the distances
/// last measured between them.
#[derive(Debug, Clone)]
pub struct ContactScreen {
    arm_geoms: Vec<ArmGeom>,
    /// The largest contact margin plus gap of any geom: no contact is made farther apart.
    margin_m: f64,
    /// The last distance measured of each pair (`Neighbour::geoms` holds each pair's slot).
    measured: Vec<Option<Measured>>,
    /// Each arm geom's last clearance from everything outside the arm (`arm_geoms`' order).
    settled: Vec<Option<Settled>>,
}

/// An arm geom found at one sample at least `gap_m` from every geom outside the arm it may touch,
/// with where it was and where those geoms' bodies were.
#[derive(Debug, Clone)]
struct Settled {
    gap_m: f64,
    arm_center: DVec3,
    arm_xmat: [f64; 9],
    /// Each outside body's position and orientation, to the bit, in the order of the neighbours.
    bodies: Vec<([f64; 3], [f64; 9])>,
}

/// A pair's distance as measured at one sample, with where both geoms were then.
#[derive(Debug, Clone)]
struct Measured {
    distance_m: f64,
    /// The arm geom's centre and orientation (row-major) at the measurement.
    arm_center: DVec3,
    arm_xmat: [f64; 9],
    /// The other geom's position and orientation, to the bit.
    other_xpos: [f64; 3],
    other_xmat: [f64; 9],
}

/// A geom of the arm and the bodies holding geoms it may touch.
#[derive(Debug, Clone)]
struct ArmGeom {
    geom: usize,
    neighbours: Vec<Neighbour>,
}

/// A body's geoms that one arm geom may touch.
#[derive(Debug, Clone)]
struct Neighbour {
    body: usize,
    /// Whether the body is the arm's own (it moves with the geom).
    on_arm: bool,
    /// Each geom with its pair's slot in [`ContactScreen::measured`], in the order of `tree`.
    geoms: Vec<(usize, usize)>,
    /// The geoms' bounding spheres in the body's frame, in a tree of boxes.
    tree: SphereTree,
}

/// Bounding spheres in a body's frame, grouped in a binary tree of boxes: the object's shell has
/// 40-200 pieces, of which an arm geom near the object is near a handful.
#[derive(Debug, Clone, Default)]
struct SphereTree {
    /// Each sphere's centre and radius, in tree order.
    spheres: Vec<(DVec3, f64)>,
    nodes: Vec<TreeNode>,
}

/// A box holding the spheres `first..end` (tree order); an inner node's children follow it (the
/// left at the next index, the right at `right`).
#[derive(Debug, Clone)]
struct TreeNode {
    low: DVec3,
    high: DVec3,
    first: usize,
    end: usize,
    right: Option<usize>,
}

impl SphereTree {
    /// Spheres per leaf.
    const LEAF: usize = 4;

    /// The tree of `spheres`, and the order it keeps them in (indices into `spheres`).
    fn new(spheres: &[(DVec3, f64)]) -> (Self, Vec<usize>) {
        let mut order: Vec<usize> = (0..spheres.len()).collect();
        let mut tree = Self::default();
        if !spheres.is_empty() {
            tree.split(spheres, &mut order, 0);
        }
        tree.spheres = order.iter().map(|&i| spheres[i]).collect();
        (tree, order)
    }

    /// Adds the node of `order[first..]` (its spheres split at the median centre along the
    /// longest side of their centres' box until a leaf holds at most [`Self::LEAF`]).
    fn split(&mut self, spheres: &[(DVec3, f64)], order: &mut [usize], first: usize) {
        let (mut low, mut high) = (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY));
        let (mut c_low, mut c_high) = (low, high);
        for &i in order.iter() {
            let (c, r) = spheres[i];
            low = low.min(c - DVec3::splat(r));
            high = high.max(c + DVec3::splat(r));
            c_low = c_low.min(c);
            c_high = c_high.max(c);
        }
        let node = self.nodes.len();
        self.nodes.push(TreeNode {
            low,
            high,
            first,
            end: first + order.len(),
            right: None,
        });
        if order.len() <= Self::LEAF {
            return;
        }
        let axis = (c_high - c_low).max_position();
        let half = order.len() / 2;
        order.select_nth_unstable_by(half, |&i, &j| spheres[i].0[axis].total_cmp(&spheres[j].0[axis]));
        let (left, right) = order.split_at_mut(half);
        self.split(spheres, left, first);
        self.nodes[node].right = Some(self.nodes.len());
        self.split(spheres, right, first + half);
    }

    /// Calls `visit` with the tree-order index of every sphere that meets `region`, until it
    /// returns `false`; whether every call returned `true`.
    fn all_near(&self, region: &Region, mut visit: impl FnMut(usize) -> bool) -> bool {
        let mut stack = Vec::with_capacity(16);
        if !self.nodes.is_empty() {
            stack.push(0);
        }
        while let Some(n) = stack.pop() {
            let node = &self.nodes[n];
            if !region.meets_box(node.low, node.high) {
                continue;
            }
            match node.right {
                Some(right) => {
                    stack.push(right);
                    stack.push(n + 1);
                }
                None => {
                    for i in node.first..node.end {
                        let (c, r) = self.spheres[i];
                        if region.meets_sphere(c, r) && !visit(i) {
                            return false;
                        }
                    }
                }
            }
        }
        true
    }
}

/// Where an arm geom may touch something, in a body's frame: within `reach_m` of its centre and
/// within the box `low..high` (its oriented box, grown by the same allowance, as seen along the
/// body's axes). A long link's sphere is far larger than the link.
struct Region {
    point: DVec3,
    reach_m: f64,
    low: DVec3,
    high: DVec3,
}

impl Region {
    /// The region of arm geom `a`, `allowance_m` around it, in the frame whose origin is at `origin`
    /// and whose axes are the columns of `axes`.
    fn of(a: &Bound, allowance_m: f64, origin: DVec3, axes: DMat3) -> Self {
        let to_body = axes.transpose();
        let box_center = to_body * (a.box_center - origin);
        let box_axes = to_body * a.axes;
        let extent = DVec3::new(
            box_axes.row(0).abs().dot(a.half),
            box_axes.row(1).abs().dot(a.half),
            box_axes.row(2).abs().dot(a.half),
        ) + DVec3::splat(allowance_m);
        Self {
            point: to_body * (a.center - origin),
            reach_m: a.radius_m + allowance_m,
            low: box_center - extent,
            high: box_center + extent,
        }
    }

    fn meets_box(&self, low: DVec3, high: DVec3) -> bool {
        let outside = (low - self.point).max(self.point - high).max(DVec3::ZERO);
        low.cmple(self.high).all()
            && high.cmpge(self.low).all()
            && outside.length_squared() <= self.reach_m * self.reach_m
    }

    fn meets_sphere(&self, center: DVec3, radius_m: f64) -> bool {
        let outside = (self.low - center).max(center - self.high).max(DVec3::ZERO);
        let reach_m = radius_m + self.reach_m;
        outside.length_squared() <= radius_m * radius_m
            && (center - self.point).length_squared() <= reach_m * reach_m
    }
}

impl ContactScreen {
    /// The screen of the arm whose bodies `owns_body` names, or `None` when the model's contacts
    /// are not what the screen models (see the module documentation).
    pub fn new(model: &MjModel, owns_body: impl Fn(usize) -> bool) -> Option<Self> {
        let opt = model.opt();
        let enabled = |bit: MjtEnableBit| opt.enableflags & bit as i32 != 0;
        let disabled = |bit: MjtDisableBit| opt.disableflags & bit as i32 != 0;
        if model.ffi().npair > 0
            || model.ffi().nflex > 0
            || enabled(MjtEnableBit::mjENBL_OVERRIDE)
            || enabled(MjtEnableBit::mjENBL_SLEEP)
            || disabled(MjtDisableBit::mjDSBL_NATIVECCD)
            || opt.ccd_tolerance.is_nan()
            || opt.ccd_tolerance > MAX_CCD_TOLERANCE
        {
            return None;
        }
        let filter_parent = opt.disableflags & MjtDisableBit::mjDSBL_FILTERPARENT as i32 == 0;
        let ngeom = model.ffi().ngeom as usize;
        let arm: Vec<usize> = (0..ngeom)
            .filter(|&g| owns_body(model.geom_bodyid()[g] as usize))
            .collect();
        // A geom the screen cannot bound (a plane, a height field) would leave every sample
        // undecided: such a world is not screened at all.
        let boundable = arm.iter().all(|&a| {
            Bound::boundable(model, a)
                && (0..ngeom).all(|g| !may_touch(model, a, g, filter_parent) || Bound::boundable(model, g))
        });
        if !boundable {
            return None;
        }
        let mut pairs = 0;
        let arm_geoms: Vec<ArmGeom> = arm
            .into_iter()
            .map(|a| {
                let mut by_body: Vec<(usize, Vec<(usize, usize)>)> = Vec::new();
                for g in (0..ngeom).filter(|&g| may_touch(model, a, g, filter_parent)) {
                    let body = model.geom_bodyid()[g] as usize;
                    let slot = (g, pairs);
                    pairs += 1;
                    match by_body.iter_mut().find(|(b, _)| *b == body) {
                        Some((_, geoms)) => geoms.push(slot),
                        None => by_body.push((body, vec![slot])),
                    }
                }
                let neighbours = by_body
                    .into_iter()
                    .map(|(body, slots)| neighbour(model, body, owns_body(body), slots))
                    .collect();
                ArmGeom { geom: a, neighbours }
            })
            .collect();
        let margin_m = 2.0
            * model
                .geom_margin()
                .iter()
                .zip(model.geom_gap())
                .fold(0.0_f64, |m, (margin, gap)| m.max(margin + gap));
        Some(Self {
            settled: vec![None; arm_geoms.len()],
            arm_geoms,
            margin_m,
            measured: vec![None; pairs],
        })
    }

    /// Whether the current kinematics (`geom_xpos`, `geom_xmat`, `xpos`, `xmat`) leave every geom
    /// of the arm clear of everything it may touch. Measures the nearest pairs with
    /// `mj_geomDistance`, which uses `data` as scratch only.
    pub fn screen<M: ModelType>(&mut self, model: &MjModel, data: &mut MjData<M>) -> Screened {
        let clear_m = self.margin_m + CLEARANCE_M + ROUNDING_M;
        for (index, arm_geom) in self.arm_geoms.iter().enumerate() {
            let a = Bound::of(model, data, arm_geom.geom);
            let arm_xmat = data.geom_xmat()[arm_geom.geom];
            let outside_settled = self.settled[index].as_ref().is_some_and(|settled| {
                arm_geom.outside_bodies_in_place(data, &settled.bodies)
                    && settled.gap_m - travel_m(settled.arm_center, &settled.arm_xmat, &a, &arm_xmat)
                        > clear_m
            });
            if !outside_settled {
                // Everything outside the arm within `SETTLE_REACH_M` (beyond the margin) is bounded.
                let reach_m = self.margin_m + SETTLE_REACH_M;
                let Some(gap_m) = arm_geom.bounds_clear(model, data, &a, false, reach_m, &mut self.measured)
                else {
                    self.settled[index] = None;
                    return Screened::Undecided;
                };
                self.settled[index] = Some(Settled {
                    gap_m,
                    arm_center: a.center,
                    arm_xmat,
                    bodies: arm_geom.outside_bodies(data),
                });
            }
            if arm_geom
                .bounds_clear(model, data, &a, true, clear_m, &mut self.measured)
                .is_none()
            {
                return Screened::Undecided;
            }
        }
        Screened::Clear
    }
}

/// How far beyond the contact margin an arm geom's clearance from everything outside the arm is
/// bounded, metres: while the geom has moved less than its clearance since (and nothing outside
/// the arm has moved), it is clear without looking at a single pair. Settling the sensor moves the
/// pad by fractions of a millimetre, a few millimetres from the surface.
const SETTLE_REACH_M: f64 = 5e-3;

impl ArmGeom {
    /// The smallest lower bound of the distance from this geom (at `a`) to the geoms of its neighbours on
    /// the arm (`on_arm`) or outside it, `reach_m` for those farther than that (`reach_m` at
    /// least the margin plus the clearance); `None` when a pair within reach is not clear.
    fn bounds_clear<M: ModelType>(
        &self,
        model: &MjModel,
        data: &mut MjData<M>,
        a: &Bound,
        on_arm: bool,
        reach_m: f64,
        measured: &mut [Option<Measured>],
    ) -> Option<f64> {
        let mut gap_m = reach_m;
        for n in self.neighbours.iter().filter(|n| n.on_arm == on_arm) {
            // The arm geom in the body's frame, where the tree is.
            let origin = DVec3::from_array(data.xpos()[n.body]);
            let region = Region::of(a, reach_m + ROUNDING_M, origin, mat3(&data.xmat()[n.body]));
            let all_clear = n.tree.all_near(&region, |i| {
                let (g, slot) = n.geoms[i];
                let apart_m = pair_margin(model, a.geom, g) + CLEARANCE_M;
                match lower_bound_m(model, data, a, g, apart_m, &mut measured[slot]) {
                    Some(bound_m) if bound_m >= apart_m => {
                        gap_m = gap_m.min(bound_m);
                        true
                    }
                    _ => false,
                }
            });
            if !all_clear {
                return None;
            }
        }
        Some(gap_m)
    }

    /// The position and orientation of each body outside the arm that holds geoms this may touch.
    fn outside_bodies<M: ModelType>(&self, data: &MjData<M>) -> Vec<([f64; 3], [f64; 9])> {
        self.neighbours
            .iter()
            .filter(|n| !n.on_arm)
            .map(|n| (data.xpos()[n.body], data.xmat()[n.body]))
            .collect()
    }

    /// Whether every body outside the arm is where `bodies` has it, to the bit.
    fn outside_bodies_in_place<M: ModelType>(
        &self,
        data: &MjData<M>,
        bodies: &[([f64; 3], [f64; 9])],
    ) -> bool {
        self.neighbours
            .iter()
            .filter(|n| !n.on_arm)
            .zip(bodies)
            .all(|(n, (xpos, xmat))| data.xpos()[n.body] == *xpos && data.xmat()[n.body] == *xmat)
    }
}

/// Whether MuJoCo's filters let geoms `a` (of the arm) and `g` make a contact.
fn may_touch(model: &MjModel, a: usize, g: usize, filter_parent: bool) -> bool {
    let (ba, bg) = (model.geom_bodyid()[a] as usize, model.geom_bodyid()[g] as usize);
    if ba == bg {
        return false;
    }
    let (ta, ca) = (model.geom_contype()[a], model.geom_conaffinity()[a]);
    let (tg, cg) = (model.geom_contype()[g], model.geom_conaffinity()[g]);
    if ta & cg == 0 && tg & ca == 0 {
        return false;
    }
    let weld = |b: usize| model.body_weldid()[b] as usize;
    let (wa, wg) = (weld(ba), weld(bg));
    if wa == wg || (model.body_dofnum()[wa] == 0 && model.body_dofnum()[wg] == 0) {
        return false;
    }
    let weld_parent = |w: usize| weld(model.body_parentid()[w] as usize);
    if filter_parent && wa != 0 && wg != 0 && (wa == weld_parent(wg) || wg == weld_parent(wa)) {
        return false;
    }
    let (b1, b2) = (ba.min(bg), ba.max(bg));
    let signature = ((b1 as i32) << 16) + b2 as i32;
    !model.exclude_signature().contains(&signature)
}

/// The geoms `slots` of `body` an arm geom may touch: their bounding spheres about their origins
/// (`geom_pos` in the body's frame, `geom_rbound`) in a tree.
fn neighbour(model: &MjModel, body: usize, on_arm: bool, slots: Vec<(usize, usize)>) -> Neighbour {
    let spheres: Vec<(DVec3, f64)> = slots
        .iter()
        .map(|&(g, _)| (DVec3::from_array(model.geom_pos()[g]), model.geom_rbound()[g]))
        .collect();
    let (tree, order) = SphereTree::new(&spheres);
    Neighbour {
        body,
        on_arm,
        geoms: order.iter().map(|&i| slots[i]).collect(),
        tree,
    }
}

/// A lower bound of the distance between arm geom `a` and geom `g`, `None` where none can be
/// had (a failed measurement). The cheapest bound that clears `apart_m`
/// first: the distance kept in `measured` from an earlier sample less how far `a` can have moved
/// since (`g` not moved); their bounding spheres; their oriented boxes; MuJoCo's distance now. A
/// fresh bound is kept in `measured`.
fn lower_bound_m<M: ModelType>(
    model: &MjModel,
    data: &mut MjData<M>,
    a: &Bound,
    g: usize,
    apart_m: f64,
    measured: &mut Option<Measured>,
) -> Option<f64> {
    let (other_xpos, other_xmat) = (data.geom_xpos()[g], data.geom_xmat()[g]);
    let arm_xmat = data.geom_xmat()[a.geom];
    if let Some(m) = measured.as_ref()
        && m.other_xpos == other_xpos
        && m.other_xmat == other_xmat
    {
        let bound_m = m.distance_m - travel_m(m.arm_center, &m.arm_xmat, a, &arm_xmat) - ROUNDING_M;
        if bound_m >= apart_m {
            return Some(bound_m);
        }
    }
    let b = Bound::of(model, data, g);
    let sphere_gap_m = (b.center - a.center).length() - a.radius_m - b.radius_m - ROUNDING_M;
    let distance_m = if sphere_gap_m >= apart_m {
        sphere_gap_m
    } else if let Some(gap_m) = box_gap_m(a, &b, apart_m + ROUNDING_M) {
        gap_m - ROUNDING_M
    } else {
        // `mj_geomDistance` gives its `dist_max` when the pair is farther apart than that; a pair
        // beyond the clearance is measured up to a few centimetres, so that the measurement lasts.
        data.try_geom_distance(a.geom, g, apart_m + MEASURED_UP_TO_M, None)
            .ok()?
    };
    *measured = Some(Measured {
        distance_m,
        arm_center: a.center,
        arm_xmat,
        other_xpos,
        other_xmat,
    });
    Some(distance_m)
}

/// How far beyond the clearance a pair's distance is measured, metres: what the measurement can
/// clear of later samples (a motion's samples are under a millimetre apart).
const MEASURED_UP_TO_M: f64 = 0.02;

/// An upper bound of how much nearer arm geom `a` can have come to anything since it was at
/// `center` turned by `xmat`: how far any point of it has moved, its centre's travel plus the
/// change of its orientation matrix (Frobenius norm, which bounds the rotation of any vector by at
/// most that fraction of its length) times its bounding radius. A capsule is the points within its
/// radius of a segment, so the segment's travel is enough: the centre's plus the change of the
/// segment's direction (the z axis) times its half length.
fn travel_m(center: DVec3, xmat: &[f64; 9], a: &Bound, now_xmat: &[f64; 9]) -> f64 {
    let moved_m = (a.center - center).length();
    let squared = |indices: &[usize]| {
        indices
            .iter()
            .map(|&i| (xmat[i] - now_xmat[i]).powi(2))
            .sum::<f64>()
    };
    match a.segment_half_m {
        Some(half_m) => moved_m + squared(&[2, 5, 8]).sqrt() * half_m,
        None => moved_m + squared(&[0, 1, 2, 3, 4, 5, 6, 7, 8]).sqrt() * a.radius_m,
    }
}

/// MuJoCo's margin plus gap of a geom pair (each the sum of the two geoms', as MuJoCo has summed them
/// since 3.5): contacts are made below it, the gap's among them.
fn pair_margin(model: &MjModel, a: usize, g: usize) -> f64 {
    let (margin, gap) = (model.geom_margin(), model.geom_gap());
    margin[a] + margin[g] + gap[a] + gap[g]
}

/// A geom's bounding sphere and oriented box (MuJoCo's `geom_rbound` and `geom_aabb`) in the world.
struct Bound {
    geom: usize,
    /// The sphere's centre, the geom's origin.
    center: DVec3,
    radius_m: f64,
    /// The box's centre, axes (columns) and half sizes.
    box_center: DVec3,
    axes: DMat3,
    half: DVec3,
    /// The half length of the segment a capsule (or a sphere: 0) is the points within its radius
    /// of, along the geom's z axis; `None` for other shapes.
    segment_half_m: Option<f64>,
}

impl Bound {
    /// The shapes whose `geom_aabb` holds the whole solid MuJoCo collides (meshes: their convex hull).
    const SHAPES: [MjtGeomBase; 6] = [
        MjtGeomBase::mjGEOM_SPHERE,
        MjtGeomBase::mjGEOM_CAPSULE,
        MjtGeomBase::mjGEOM_ELLIPSOID,
        MjtGeomBase::mjGEOM_CYLINDER,
        MjtGeomBase::mjGEOM_BOX,
        MjtGeomBase::mjGEOM_MESH,
    ];

    /// Whether geom `g` has the bounds (not a plane, a height field or a signed distance field).
    fn boundable(model: &MjModel, g: usize) -> bool {
        model.geom_rbound()[g] > 0.0 && Self::SHAPES.contains(&model.geom_type()[g])
    }

    /// The bounds of geom `g` (one [`boundable`](Self::boundable)) at the current kinematics.
    fn of<M: ModelType>(model: &MjModel, data: &MjData<M>, g: usize) -> Self {
        let radius_m = model.geom_rbound()[g];
        let center = DVec3::from_array(data.geom_xpos()[g]);
        let axes = mat3(&data.geom_xmat()[g]);
        let [cx, cy, cz, hx, hy, hz] = model.geom_aabb()[g];
        Self {
            geom: g,
            center,
            radius_m,
            box_center: center + axes * DVec3::new(cx, cy, cz),
            axes,
            half: DVec3::new(hx, hy, hz),
            segment_half_m: match model.geom_type()[g] {
                MjtGeomBase::mjGEOM_CAPSULE => Some(model.geom_size()[g][1]),
                MjtGeomBase::mjGEOM_SPHERE => Some(0.0),
                _ => None,
            },
        }
    }
}

/// A row-major 3x3 matrix (MuJoCo's `xmat`) whose columns are the frame's axes in the world.
fn mat3(m: &[f64; 9]) -> DMat3 {
    DMat3::from_cols_array(m).transpose()
}

/// How far apart two oriented boxes are along the first of the fifteen separating axes of the
/// separating-axis theorem (the other geom's three face normals, the arm geom's, then their nine
/// cross products) that parts them by more than `apart_m`: a lower bound of their distance. `None`
/// when no axis does.
fn box_gap_m(a: &Bound, b: &Bound, apart_m: f64) -> Option<f64> {
    let t = b.box_center - a.box_center;
    let a_axes = [a.axes.x_axis, a.axes.y_axis, a.axes.z_axis];
    let b_axes = [b.axes.x_axis, b.axes.y_axis, b.axes.z_axis];
    let reach = |axes: &[DVec3; 3], half: DVec3, l: DVec3| {
        half.x * axes[0].dot(l).abs() + half.y * axes[1].dot(l).abs() + half.z * axes[2].dot(l).abs()
    };
    let gap_along = |l: DVec3| {
        let length = l.length();
        if length < 1e-9 {
            return None;
        }
        let gap = (t.dot(l).abs() - reach(&a_axes, a.half, l) - reach(&b_axes, b.half, l)) / length;
        (gap > apart_m).then_some(gap)
    };
    b_axes
        .iter()
        .chain(&a_axes)
        .find_map(|&l| gap_along(l))
        .or_else(|| {
            a_axes
                .iter()
                .find_map(|&u| b_axes.iter().find_map(|&v| gap_along(u.cross(v))))
        })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn bound(center: DVec3, axes: DMat3, half: DVec3) -> Bound {
        Bound {
            geom: 0,
            center,
            radius_m: half.length(),
            box_center: center,
            axes,
            half,
            segment_half_m: None,
        }
    }

    #[test]
    fn boxes_are_apart_only_beyond_their_gap() {
        let unit = DVec3::splat(0.5);
        let a = bound(DVec3::ZERO, DMat3::IDENTITY, unit);
        // Side by side along x with a gap of 1 mm: apart by 0.5 mm, not by 2 mm.
        let b = bound(DVec3::new(1.001, 0.3, -0.2), DMat3::IDENTITY, unit);
        assert!(box_gap_m(&a, &b, 0.5e-3).is_some());
        assert!(box_gap_m(&a, &b, 2e-3).is_none());
        // Turned 45 degrees about z, a corner points at `a`: the corner reaches x = 0.5 + 0.5 * sqrt(2)
        // - 0.5 = 0.207 short of the centre distance, so apart at 1.2 only when the corner is clear.
        let turned = DMat3::from_rotation_z(std::f64::consts::FRAC_PI_4);
        let corner = 0.5 * std::f64::consts::SQRT_2;
        let c = bound(DVec3::new(0.5 + corner + 1e-3, 0.0, 0.0), turned, unit);
        assert!(box_gap_m(&a, &c, 0.5e-3).is_some());
        let d = bound(DVec3::new(0.5 + corner - 1e-3, 0.0, 0.0), turned, unit);
        assert!(box_gap_m(&a, &d, 0.0).is_none());
        // Two thin boxes crossing at right angles above each other, separated only along the cross
        // product of their long axes (the z axis here).
        let long_x = DVec3::new(1.0, 0.01, 0.01);
        let long_y = DVec3::new(0.01, 1.0, 0.01);
        let e = bound(DVec3::ZERO, DMat3::IDENTITY, long_x);
        let tilted = DMat3::from_rotation_x(0.3);
        let f = bound(DVec3::new(0.2, 0.0, 0.05), tilted, long_y);
        assert!(box_gap_m(&e, &f, 0.0).is_some());
        let g = bound(DVec3::new(0.2, 0.0, 0.015), tilted, long_y);
        assert!(box_gap_m(&e, &g, 0.0).is_none());
    }
}
