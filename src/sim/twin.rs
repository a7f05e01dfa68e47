//! The arm alone: where the pad would be, without placing the rest of the world.
//!
//! `mj_kinematics` places every body, geom and site of a model. In the arm's scene most geoms are
//! the object's collision shell (40-200 convex pieces, `collision_shell.rs`), so placing them was
//! most of a kinematics call (a fifth of a planner run's time, issue 39), while two of the callers
//! only read the pad's site frame and the arm's Jacobian: a kinematic motion's search for its next
//! sample (`Arm::next_sample`, which shrinks a step until the pad travels little enough) and the
//! inverse kinematics' descent (`ik.rs`). The twin is `mjcf/arm.xml` compiled alone: the same
//! bodies, joints, inertias and site, so MuJoCo's same operations give the same frames and the same
//! Jacobian bit for bit, with a handful of geoms to place. [`ArmTwin::of`] checks the twin's
//! numbers against the scene's arm and gives none where any differs (a world whose arm is not
//! `mjcf/arm.xml`'s), and the callers then use the scene itself.

use std::sync::Arc;

use mujoco_rs::prelude::*;

use crate::pose::Pose;
use crate::sim::arm::Arm;

/// The arm of a scene compiled without the rest of its world, with its own `MjData`.
pub struct ArmTwin {
    model: Arc<MjModel>,
    data: MjData<Arc<MjModel>>,
    arm: Arm,
    /// The arm's elements: (the twin's id, the scene's id) of each.
    elements: ArmElements,
    /// The configuration the twin's kinematics are at (none yet: empty).
    q: Vec<f64>,
}

/// The arm's bodies, joints, geoms and sites in two models: pairs (one model's id, the other's).
struct ArmElements {
    bodies: Vec<(usize, usize)>,
    joints: Vec<(usize, usize)>,
    geoms: Vec<(usize, usize)>,
    sites: Vec<(usize, usize)>,
}

impl ArmTwin {
    /// The twin of `arm` in `scene_model` on `model`, the arm compiled alone, if that has, bit for
    /// bit, the numbers the arm's kinematics and Jacobian read (its bodies, joints, geoms and
    /// sites; see `same_arm`).
    pub fn of(model: Arc<MjModel>, scene_model: &MjModel, arm: &Arm) -> Option<Self> {
        let twin_arm = Arm::find(&model).ok().flatten()?;
        let elements = same_arm(&model, &twin_arm, scene_model, arm)?;
        let data = MjData::try_new(Arc::clone(&model)).ok()?;
        Some(Self {
            model,
            data,
            arm: twin_arm,
            elements,
            q: Vec::new(),
        })
    }

    /// The twin's model: for a second `MjData` of the arm alone (the inverse kinematics' scratch).
    pub fn model_arc(&self) -> Arc<MjModel> {
        Arc::clone(&self.model)
    }

    /// The arm as the twin's model numbers it (its `qpos` and `dof` addresses).
    pub fn arm(&self) -> &Arm {
        &self.arm
    }

    /// The pad's site frame with the arm at `q`: the scene's kinematics would give these bits.
    pub fn pad_pose(&mut self, q: &[f64]) -> Pose {
        self.arm.set_q(&mut self.data, q);
        self.data.kinematics();
        self.q.clear();
        self.q.extend_from_slice(q);
        self.arm.site_pose(&self.data)
    }

    /// Writes the arm's kinematics at `q` (its bodies', joints', geoms' and sites' frames) into
    /// `scene`, the data of the scene this is the twin of: what `mj_kinematics` would write there
    /// for them, bit for bit. The rest of `scene`'s kinematics stay as they are, so they must be
    /// those of the world as it is: only the arm moved since the scene's last `mj_kinematics`.
    pub(crate) fn write_arm_kinematics(&mut self, q: &[f64], scene: &mut MjData<Arc<MjModel>>) {
        if self.q != q {
            self.pad_pose(q);
        }
        let twin = &self.data;
        let ArmElements {
            bodies,
            joints,
            geoms,
            sites,
        } = &self.elements;
        for &(t, s) in bodies {
            scene.xpos_mut()[s] = twin.xpos()[t];
            scene.xquat_mut()[s] = twin.xquat()[t];
            scene.xmat_mut()[s] = twin.xmat()[t];
            scene.xipos_mut()[s] = twin.xipos()[t];
            scene.ximat_mut()[s] = twin.ximat()[t];
        }
        for &(t, s) in joints {
            scene.xanchor_mut()[s] = twin.xanchor()[t];
            scene.xaxis_mut()[s] = twin.xaxis()[t];
        }
        for &(t, s) in geoms {
            scene.geom_xpos_mut()[s] = twin.geom_xpos()[t];
            scene.geom_xmat_mut()[s] = twin.geom_xmat()[t];
        }
        for &(t, s) in sites {
            scene.site_xpos_mut()[s] = twin.site_xpos()[t];
            scene.site_xmat_mut()[s] = twin.site_xmat()[t];
        }
    }
}

/// The pairs of the arm `a`'s elements in model `ma` and the arm `b`'s in `mb` if they have, bit
/// for bit, the numbers that `mj_kinematics`, `mj_comPos` and `mj_jacSite` read: the same bodies
/// in the same order (by name, each with its parent's name), their frames, inertias and masses (the
/// arm's subtree centre of mass sums over them, so no body may be missing or extra), their joints
/// (type, axis, anchor, reference position, and the limits the inverse kinematics clamps to), their
/// geoms' and sites' frames, and the same pad site.
fn same_arm(ma: &MjModel, a: &Arm, mb: &MjModel, b: &Arm) -> Option<ArmElements> {
    let (bodies_a, bodies_b) = (arm_bodies(ma, a), arm_bodies(mb, b));
    let pairs = |x: Vec<usize>, y: Vec<usize>, same: &dyn Fn(usize, usize) -> bool| {
        (x.len() == y.len() && x.iter().zip(&y).all(|(&i, &j)| same(i, j)))
            .then(|| x.into_iter().zip(y).collect::<Vec<_>>())
    };
    let on = |n: i64, body_of: &[i32], bodies: &[usize]| {
        (0..n as usize)
            .filter(|&e| bodies.contains(&(body_of[e] as usize)))
            .collect::<Vec<_>>()
    };
    let joints_a = on(ma.ffi().njnt, ma.jnt_bodyid(), &bodies_a);
    let joints_b = on(mb.ffi().njnt, mb.jnt_bodyid(), &bodies_b);
    let geoms_a = on(ma.ffi().ngeom, ma.geom_bodyid(), &bodies_a);
    let geoms_b = on(mb.ffi().ngeom, mb.geom_bodyid(), &bodies_b);
    let sites_a = on(ma.ffi().nsite, ma.site_bodyid(), &bodies_a);
    let sites_b = on(mb.ffi().nsite, mb.site_bodyid(), &bodies_b);
    if site_numbers(ma, a.site()) != site_numbers(mb, b.site()) {
        return None;
    }
    Some(ArmElements {
        bodies: pairs(bodies_a, bodies_b, &|i, j| {
            body_numbers(ma, i) == body_numbers(mb, j)
        })?,
        joints: pairs(joints_a, joints_b, &|i, j| {
            joint_numbers(ma, i) == joint_numbers(mb, j)
        })?,
        geoms: pairs(geoms_a, geoms_b, &|i, j| {
            geom_numbers(ma, i) == geom_numbers(mb, j)
        })?,
        sites: pairs(sites_a, sites_b, &|i, j| {
            site_numbers(ma, i) == site_numbers(mb, j)
        })?,
    })
}

/// The bodies of `arm`'s kinematic tree, in model order.
fn arm_bodies(m: &MjModel, arm: &Arm) -> Vec<usize> {
    (0..m.ffi().nbody as usize)
        .filter(|&i| arm.owns_body(m, i))
        .collect()
}

/// A name of model `m`, owned (`None` for an unnamed element).
fn name_of(m: &MjModel, kind: MjtObjBase, id: usize) -> Option<String> {
    m.id_to_name(kind, id).map(str::to_owned)
}

/// The bits of `values`: `f64` equality would take -0 for 0.
fn bits(values: &[f64]) -> Vec<u64> {
    values.iter().map(|v| v.to_bits()).collect()
}

/// What kinematics and the centre of mass read of body `i`: its name and its parent's, its frame
/// and inertial frame, inertia, mass and subtree mass, and how many joints and dofs it has.
fn body_numbers(m: &MjModel, i: usize) -> (Option<String>, Option<String>, Vec<u64>, [i32; 3]) {
    let parent = m.body_parentid()[i] as usize;
    let numbers = [
        &m.body_pos()[i][..],
        &m.body_quat()[i],
        &m.body_ipos()[i],
        &m.body_iquat()[i],
        &m.body_inertia()[i],
        &[m.body_mass()[i], m.body_subtreemass()[i]],
    ]
    .concat();
    (
        name_of(m, MjtObjBase::mjOBJ_BODY, i),
        name_of(m, MjtObjBase::mjOBJ_BODY, parent),
        bits(&numbers),
        [
            m.body_sameframe()[i] as i32,
            m.body_jntnum()[i],
            m.body_dofnum()[i],
        ],
    )
}

/// What kinematics read of joint `j` (its name and type, axis, anchor and reference position), and
/// its limits, which the inverse kinematics clamps to.
fn joint_numbers(m: &MjModel, j: usize) -> (Option<String>, i32, Vec<u64>) {
    let reference = m.qpos0()[m.jnt_qposadr()[j] as usize];
    let numbers = [
        &m.jnt_axis()[j][..],
        &m.jnt_pos()[j],
        &[reference],
        &m.jnt_range()[j],
    ]
    .concat();
    (
        name_of(m, MjtObjBase::mjOBJ_JOINT, j),
        m.jnt_type()[j] as i32,
        bits(&numbers),
    )
}

/// Geom `g`'s name, its body's name and its frame on that body.
fn geom_numbers(m: &MjModel, g: usize) -> (Option<String>, Option<String>, Vec<u64>, i32) {
    let body = m.geom_bodyid()[g] as usize;
    let numbers = [&m.geom_pos()[g][..], &m.geom_quat()[g]].concat();
    (
        name_of(m, MjtObjBase::mjOBJ_GEOM, g),
        name_of(m, MjtObjBase::mjOBJ_BODY, body),
        bits(&numbers),
        m.geom_sameframe()[g] as i32,
    )
}

/// Site `s`'s name, its body's name and its frame on that body.
fn site_numbers(m: &MjModel, s: usize) -> (Option<String>, Option<String>, Vec<u64>, i32) {
    let body = m.site_bodyid()[s] as usize;
    let numbers = [&m.site_pos()[s][..], &m.site_quat()[s]].concat();
    (
        name_of(m, MjtObjBase::mjOBJ_SITE, s),
        name_of(m, MjtObjBase::mjOBJ_BODY, body),
        bits(&numbers),
        m.site_sameframe()[s] as i32,
    )
}

#[cfg(test)]
mod tests {
    use glam::DVec3;
    use rand::RngExt;

    use crate::mesh::TriMesh;
    use crate::sim::{ObjectSpec, Scene, SceneBuilder};

    /// Every kinematics array `mj_kinematics` writes, as bits.
    fn kinematics(scene: &Scene) -> Vec<u64> {
        let d = scene.data();
        let rows: Vec<&[f64]> = d
            .xpos()
            .iter()
            .map(|r| &r[..])
            .chain(d.xquat().iter().map(|r| &r[..]))
            .chain(d.xmat().iter().map(|r| &r[..]))
            .chain(d.xipos().iter().map(|r| &r[..]))
            .chain(d.ximat().iter().map(|r| &r[..]))
            .chain(d.xanchor().iter().map(|r| &r[..]))
            .chain(d.xaxis().iter().map(|r| &r[..]))
            .chain(d.geom_xpos().iter().map(|r| &r[..]))
            .chain(d.geom_xmat().iter().map(|r| &r[..]))
            .chain(d.site_xpos().iter().map(|r| &r[..]))
            .chain(d.site_xmat().iter().map(|r| &r[..]))
            .chain(std::iter::once(d.qpos()))
            .collect();
        rows.concat().iter().map(|v| v.to_bits()).collect()
    }

    /// Along 200 seeded moves of a kinematic motion, the arm's frames written from its twin leave
    /// every kinematics array of the scene (object, table and arm) as `mj_kinematics` writes it.
    #[test]
    fn the_arm_moved_by_its_twin_leaves_the_scenes_kinematics_bit_for_bit() {
        let object = ObjectSpec::new("box", TriMesh::cuboid(DVec3::new(0.06, 0.05, 0.08)));
        let mut scene = SceneBuilder::with_arm_and_table().object(object).build().unwrap();
        assert!(scene.arm_twin().is_some());
        let arm = scene.arm().unwrap().clone();
        let mut r = crate::rng::rng(11);
        scene.data_mut().kinematics();
        for _ in 0..200 {
            let q: Vec<f64> = arm
                .joints()
                .iter()
                .map(|j| r.random_range(j.range_rad[0]..=j.range_rad[1]))
                .collect();
            scene.pad_pose_at(&arm, &q);
            scene.arm_moved_to(&arm, &q);
            let written = kinematics(&scene);
            scene.data_mut().kinematics();
            assert!(written == kinematics(&scene), "kinematics at {q:?}");
        }
    }
}
