//! A compiled MuJoCo world and its state: the one place that owns `MjModel` and `MjData`.

use std::sync::{Arc, OnceLock};

use glam::DVec3;
use mujoco_rs::prelude::*;

use crate::bodies::OBJECT_BODY;
use crate::mesh::TriMesh;
use crate::pose::Pose;
use crate::sim::SimError;
use crate::sim::arm::Arm;
use crate::sim::contact_screen::{ContactScreen, Screened};
use crate::sim::mjcf::{ARM_XML, Document, Section, TABLE_XML, as_read_f32, sensed_surface_names};
use crate::sim::object::{MeshAsset, OBJECT_MESH, ObjectMount, ObjectSpec, ObjectSurfaces};
use crate::sim::twin::ArmTwin;

/// What goes into a scene. The arm and table come from `mjcf/`; the object and any extra parts (a
/// sensor plugin, a free-floating pad) are added by the caller.
#[derive(Debug, Clone, Default)]
pub struct SceneBuilder {
    arm: bool,
    table: bool,
    object: Option<ObjectSpec>,
    /// File the object's mesh asset refers to, instead of inline vertices.
    object_mesh_file: Option<String>,
    extra: Vec<(Section, String)>,
    timestep_s: Option<f64>,
    /// The object without its collision shell: a world where nothing collides with it.
    without_collision_shell: bool,
}

impl SceneBuilder {
    /// An empty world.
    pub fn new() -> Self {
        Self::default()
    }

    /// The world of Sec. V-A1: arm and table.
    pub fn with_arm_and_table() -> Self {
        Self {
            arm: true,
            table: true,
            ..Self::default()
        }
    }

    pub fn table(mut self, yes: bool) -> Self {
        self.table = yes;
        self
    }

    pub fn object(mut self, object: ObjectSpec) -> Self {
        self.object = Some(object);
        self
    }

    /// How the scene's object is held, when it has one.
    pub fn object_mount(&self) -> Option<ObjectMount> {
        self.object.as_ref().map(|o| o.mount)
    }

    /// Leaves out the object's collision shell (`collision_shell.rs`): for a world where nothing
    /// can collide with the object (the free-floating pad's: its plate takes part in no contact,
    /// and there is neither arm nor table), where the shell's 40-200 convex pieces would only be
    /// compiled by MuJoCo and placed again at every kinematics call. The sensor never reads the
    /// shell, and the object's body has an explicit inertia, so its readings are the same.
    pub fn without_collision_shell(mut self) -> Self {
        self.without_collision_shell = true;
        self
    }

    /// Makes the object's mesh asset refer to `file` (relative to where the MJCF is written; the
    /// caller writes the mesh there) instead of holding its vertices inline: for a scene written
    /// out for MuJoCo's own tools. [`to_xml`](Self::to_xml) alone uses it: [`build`](Self::build)
    /// hands MuJoCo the mesh in memory.
    pub fn object_mesh_file(mut self, file: impl Into<String>) -> Self {
        self.object_mesh_file = Some(file.into());
        self
    }

    /// Extra MJCF elements for a section (e.g. a sensor plugin instance).
    pub fn add(mut self, section: Section, xml: impl Into<String>) -> Self {
        self.extra.push((section, xml.into()));
        self
    }

    /// Overrides the simulation timestep, seconds.
    pub fn timestep_s(mut self, dt: f64) -> Self {
        self.timestep_s = Some(dt);
        self
    }

    /// The MJCF document of this builder's scene, complete, with the object's whole mesh inline or
    /// in the [`object_mesh_file`](Self::object_mesh_file). It compiles to the model
    /// [`build`](Self::build) makes, bit for bit, unless the mesh is large: `build` then gives
    /// MuJoCo a coarse copy and the sensor the exact surface ([`ObjectSurfaces`]), which MJCF text
    /// cannot carry, and the two read the same images to `f32` rounding.
    pub fn to_xml(&self) -> Result<String, SimError> {
        self.document(match &self.object_mesh_file {
            Some(file) => MeshAsset::File(file),
            None => MeshAsset::Inline,
        })
    }

    /// The MJCF document with the object's mesh asset from `asset`.
    fn document(&self, asset: MeshAsset) -> Result<String, SimError> {
        let mut doc = Document::default();
        if self.arm {
            doc.include(ARM_XML, "mjcf/arm.xml")?;
        } else {
            doc.include(
                "<mujoco><compiler angle=\"degree\" autolimits=\"true\"/></mujoco>",
                "compiler",
            )?;
        }
        if let Some(dt) = self.timestep_s {
            doc.include(&format!("<mujoco><option timestep=\"{dt}\"/></mujoco>"), "option")?;
        }
        if self.table {
            doc.include(TABLE_XML, "mjcf/table.xml")?;
        }
        if self.object_mount() == Some(ObjectMount::Free) {
            doc.include(FREE_OBJECT_OPTIONS, "free object options")?;
        }
        if let Some(object) = &self.object {
            object.add_to(&mut doc, asset, !self.without_collision_shell)?;
        }
        for (section, xml) in &self.extra {
            doc.add(*section, xml.clone());
        }
        Ok(doc.to_xml("taction scene"))
    }

    /// Compiles the scene and runs `mj_forward` once, the object's mesh handed to MuJoCo as numbers
    /// rather than text (a scanned mesh's millions of them, issue 39); a large mesh as
    /// [`ObjectSurfaces`] says.
    pub fn build(&self) -> Result<Scene, SimError> {
        let surfaces = self.object.as_ref().map(ObjectSpec::surfaces);
        let xml = self.document(surfaces.as_ref().map_or(MeshAsset::Inline, MeshAsset::Spec))?;
        let model = compile(&xml, surfaces.as_ref()).map_err(|message| SimError::Mjcf {
            origin: "assembled scene".into(),
            message,
        })?;
        Scene::new(model, self.object.as_ref())
    }
}

/// The solver options of a world with a free object: MuJoCo's contacts are soft, and a sustained
/// sideways force, however far inside the friction cone, makes an object creep (0.2 mm a touch on
/// four-legged shapes under no press at all, 3-6 mm under a 1 kPa covering's); elliptic friction
/// cones with `impratio` 10 make friction as hard as the normal force, and the no-slip pass
/// removes what slip is left, as MuJoCo's documentation advises for objects that must stay put
/// under a finger. With them the shapes move a few micrometres a touch under the default covering
/// (docs/measurements.md). The paper's mocap worlds keep MuJoCo's defaults.
const FREE_OBJECT_OPTIONS: &str =
    "<mujoco><option cone=\"elliptic\" impratio=\"10\" noslip_iterations=\"10\"/></mujoco>";

/// The start of the message MuJoCo gives when `errno` is set after it parsed a numeric array
/// attribute without finding a fault (`ReadAttrVec` in `xml_util.cc`).
const STRAY_ERRNO_MESSAGE: &str = "XML Error: unknown error in attribute";

/// Compiles the assembled scene: at most this many attempts when MuJoCo reports a stray `errno`.
const COMPILE_ATTEMPTS: usize = 4;

/// Parses `xml`, sets the object's surfaces on the specification when there is one
/// ([`MeshAsset::Spec`]), and compiles; tried again when the failure is MuJoCo's stray-`errno` report.
///
/// MuJoCo 3.17 reads an array attribute (a mesh's `vertex` and `face`) with `StringToVector`,
/// which zeroes `errno`, reserves, parses and shrinks the vector; its caller then takes any
/// non-zero `errno` as a parse fault, and one it does not know as "unknown error in attribute".
/// The reserve and the shrink allocate, and an allocation may leave `errno` set although it
/// succeeds, so a valid attribute occasionally fails: once in a `reproduce --scale 0.02`
/// (a planner's mesh of the 3D set, 2 worker threads), never again in six repeats of the same
/// collections. The XML is the same on the next attempt and compiles; a real fault (a malformed
/// number gives "bad format", a huge one "number is too large") is reported at once.
///
/// Seen again on a fresh heap, all three attempts failing (the parity test's second object,
/// one run in three): the allocations repeat exactly, and so does the stray `errno`. glibc's
/// `free` gives the top of the heap back to the system (`sbrk` with a negative size) and keeps
/// the call's `errno` when the sandbox refuses it, so heap trimming is switched off once
/// (memory stays with the process, as it would after the first large scene anyway), and each
/// retry holds a ballast allocation that moves the heap's top.
///
/// Seen a third time late in a whole `reproduce --scale 0.02` (twice in two runs, every attempt
/// failing): on a heap grown large, the main arena's `sbrk` is refused, glibc falls back to
/// `mmap` and the allocation succeeds with `errno` left at `ENOMEM`, however the top moves. A
/// thread other than the main one allocates from its own `mmap`ed arena and never calls `sbrk`,
/// so each retry compiles on a fresh thread.
fn compile(xml: &str, surfaces: Option<&ObjectSurfaces>) -> Result<MjModel, String> {
    keep_heap_top();
    let mut attempt = 1;
    let mut ballast: Vec<Vec<u8>> = Vec::new();
    let mut result = compile_once(xml, surfaces);
    while attempt < COMPILE_ATTEMPTS && matches!(&result, Err(m) if m.starts_with(STRAY_ERRNO_MESSAGE)) {
        ballast.push(vec![1u8; 4096 << attempt]);
        attempt += 1;
        result = std::thread::scope(|s| {
            s.spawn(|| compile_once(xml, surfaces))
                .join()
                .unwrap_or_else(|_| Err("MuJoCo's compiler panicked".into()))
        });
    }
    result
}

/// One attempt of [`compile`].
fn compile_once(xml: &str, surfaces: Option<&ObjectSurfaces>) -> Result<MjModel, String> {
    if xml.contains('\0') {
        return Err("the MJCF text holds a NUL character".into());
    }
    let mut spec = MjSpec::from_xml_string(xml).map_err(|e| edit_message(&e))?;
    if let Some(surfaces) = surfaces {
        set_object_surfaces(&mut spec, surfaces)?;
    }
    spec.compile().map_err(|e| edit_message(&e))
}

/// Sets the object's mesh asset and, for a large mesh, its exact surface's `<numeric>` fields on
/// the parsed specification ([`MeshAsset::Spec`]).
fn set_object_surfaces(spec: &mut MjSpec, surfaces: &ObjectSurfaces) -> Result<(), String> {
    let too_many = || format!("the object's mesh has more than {} vertices", i32::MAX);
    let asset = spec
        .mesh_mut(OBJECT_MESH)
        .ok_or_else(|| format!("no mesh asset '{OBJECT_MESH}' for the object"))?;
    let drawn = &surfaces.drawn;
    asset.set_uservert(
        &drawn
            .vertices
            .iter()
            .flat_map(|v| v.to_array())
            .map(as_read_f32)
            .collect::<Vec<_>>(),
    );
    let face = drawn
        .triangles
        .iter()
        .flatten()
        .map(|&i| i32::try_from(i))
        .collect::<Result<Vec<_>, _>>()
        .map_err(|_| too_many())?;
    asset.set_userface(&face);
    if let Some(sensed) = surfaces.sensed {
        let (vertex_name, face_name) = sensed_surface_names(OBJECT_MESH);
        let vertex: Vec<f64> = sensed.vertices.iter().flat_map(|v| v.to_array()).collect();
        let face: Vec<f64> = sensed.triangles.iter().flatten().map(|&i| f64::from(i)).collect();
        for (name, data) in [(vertex_name, vertex), (face_name, face)] {
            let size = i32::try_from(data.len()).map_err(|_| too_many())?;
            let numeric = spec.add_numeric();
            numeric.set_name(&name).map_err(|e| edit_message(&e))?;
            numeric.set_data(&data);
            numeric.set_size(size).map_err(|e| edit_message(&e))?;
        }
    }
    Ok(())
}

/// The text of a MuJoCo parse or compile error.
fn edit_message(e: &MjEditError) -> String {
    match e {
        MjEditError::ParseFailed(m) | MjEditError::CompileFailed(m) => m.clone(),
        other => format!("{other:?}"),
    }
}

/// Switches glibc's heap trimming off, once per process (see [`compile`]).
fn keep_heap_top() {
    #[cfg(all(target_os = "linux", target_env = "gnu"))]
    {
        static ONCE: std::sync::Once = std::sync::Once::new();
        // SAFETY: `mallopt` only sets an allocator parameter; any value is valid for
        // M_TRIM_THRESHOLD.
        ONCE.call_once(|| unsafe {
            libc::mallopt(libc::M_TRIM_THRESHOLD, i32::MAX);
        });
    }
}

/// Gives the heap's freed memory back to the system, where no MuJoCo XML is being parsed.
///
/// Heap trimming is off for the process (`keep_heap_top`, for the compiler's sake), so nothing
/// freed is ever returned on its own, and a long run that builds and drops scenes (an environment
/// resetting episode after episode, its Python objects' allocations interleaved with the
/// library's) grows its resident memory with freed, fragmented heap: 269 -> 299 MiB over 30,000
/// steps of one `taction/ActiveTouch-v1` environment, 106-111 MiB throughout with a trim at every
/// reset (docs/measurements.md, "Touches that land"). A trim may leave `errno` set, as a refused
/// `sbrk` does; that is harmless outside a parse (MuJoCo's parser zeroes `errno` before each
/// attribute it reads, and `errno` is the calling thread's own), so it runs between episodes.
pub fn give_back_freed_memory() {
    #[cfg(all(target_os = "linux", target_env = "gnu"))]
    // SAFETY: `malloc_trim` only walks glibc's own heap under its locks; any argument is valid.
    unsafe {
        libc::malloc_trim(0);
    }
}

/// Stops MuJoCo from appending its messages to `MUJOCO_LOG.TXT` in the working directory; it
/// still prints them on stderr. A run reports the faults those warnings announce itself
/// ([`Scene::fault`]; `physics_fault` among a dataset's causes), so the file only left a stray
/// log in the user's folder. For a program that owns its process (the `taction` command): the log
/// configuration is MuJoCo's, global, so a library call would change a host program's log.
///
/// # Safety
/// No other thread may use MuJoCo while this runs: call it at the start of the program.
pub unsafe fn keep_mujoco_log_off_disk() {
    let config = mujoco_rs::wrappers::mj_logging::log_config().with_logto_file(false);
    // SAFETY: the caller holds every thread that could read MuJoCo's log configuration.
    unsafe { mujoco_rs::wrappers::mj_logging::set_log_config(config) };
}

/// MuJoCo's warnings of a state gone bad, and what each says.
const FAULT_WARNINGS: [(MjtWarning, &str); 3] = [
    (
        MjtWarning::mjWARN_BADQPOS,
        "bad position (NaN, Inf or beyond 1e10)",
    ),
    (
        MjtWarning::mjWARN_BADQVEL,
        "bad velocity (NaN, Inf or beyond 1e10)",
    ),
    (
        MjtWarning::mjWARN_BADQACC,
        "bad acceleration (NaN, Inf or beyond 1e10)",
    ),
];

/// The largest state value MuJoCo accepts (`mjMAXVAL`, its bound in `mj_checkPos` and
/// `mj_checkVel`).
const MAX_STATE_VALUE: f64 = 1e10;

/// What a [`SceneState`] holds: MuJoCo's integration state without the plugins' (see
/// [`Scene::restore`]).
const CHECKPOINT_SPEC: u32 = MjtState::mjSTATE_INTEGRATION as u32 & !(MjtState::mjSTATE_PLUGIN as u32);
const PLUGIN_SPEC: u32 = MjtState::mjSTATE_PLUGIN as u32;

/// A saved state of a scene's world, from [`Scene::checkpoint`] (for the same scene only).
#[derive(Debug, Clone, PartialEq)]
pub struct SceneState {
    values: Box<[f64]>,
}

/// The object slot of a compiled scene.
#[derive(Debug, Clone)]
pub struct SceneObject {
    pub name: String,
    pub body: usize,
    pub mount: ObjectMount,
    /// Address of the free joint's 7 qpos values (free mount).
    qpos_adr: Option<usize>,
    /// Index into mocap arrays (mocap mount).
    mocap: Option<usize>,
    /// The mesh in the body frame, for resting it on the table after a perturbation.
    pub mesh: TriMesh,
}

/// `mjcf/arm.xml` compiled alone (the arm's [`ArmTwin`]), once per process; `None` if it did not
/// compile (scenes then place the whole world for the arm's kinematics, only slower).
fn arm_alone() -> Option<Arc<MjModel>> {
    static MODEL: OnceLock<Option<Arc<MjModel>>> = OnceLock::new();
    MODEL
        .get_or_init(|| {
            let builder = SceneBuilder {
                arm: true,
                ..SceneBuilder::default()
            };
            let xml = builder.document(MeshAsset::Inline).ok()?;
            compile(&xml, None).ok().map(Arc::new)
        })
        .clone()
}

/// A compiled world and its simulation state.
pub struct Scene {
    model: Arc<MjModel>,
    data: MjData<Arc<MjModel>>,
    object: Option<SceneObject>,
    arm: Option<Arm>,
    /// The arm compiled alone, where it is bit for bit the scene's: the pad's pose at a
    /// configuration without placing the rest of the world.
    twin: Option<ArmTwin>,
    /// Clears the samples of the arm's kinematic motions that are far from any contact without
    /// `mj_collision`; `None` without an arm, for contacts it does not model, or when switched off.
    contact_screen: Option<ContactScreen>,
}

impl Scene {
    /// Wraps a compiled model (any model: the arm and object slot are found by name if present).
    pub fn new(model: MjModel, object: Option<&ObjectSpec>) -> Result<Self, SimError> {
        let model = Arc::new(model);
        let data = MjData::try_new(model.clone()).map_err(|e| SimError::Physics {
            message: format!("{e:?}"),
        })?;
        let object = match (object, model.name_to_id(MjtObjBase::mjOBJ_BODY, OBJECT_BODY)) {
            (Some(spec), Some(body)) => {
                let mocap_id = model.body_mocapid()[body];
                let jnt = model.body_jntadr()[body];
                Some(SceneObject {
                    name: spec.name.clone(),
                    body,
                    mount: spec.mount,
                    qpos_adr: (jnt >= 0).then(|| model.jnt_qposadr()[jnt as usize] as usize),
                    mocap: (mocap_id >= 0).then_some(mocap_id as usize),
                    mesh: spec.mesh.clone(),
                })
            }
            _ => None,
        };
        let arm = Arm::find(&model)?;
        let twin = arm
            .as_ref()
            .and_then(|arm| ArmTwin::of(arm_alone()?, &model, arm));
        let contact_screen = arm
            .as_ref()
            .and_then(|arm| ContactScreen::new(&model, |b| arm.owns_body(&model, b)));
        let mut scene = Self {
            model,
            data,
            object,
            arm,
            twin,
            contact_screen,
        };
        scene.data.forward();
        Ok(scene)
    }

    pub fn model(&self) -> &MjModel {
        &self.model
    }

    /// The shared model, for a second `MjData` (e.g. scratch data for inverse kinematics).
    pub fn model_arc(&self) -> Arc<MjModel> {
        self.model.clone()
    }

    pub fn data(&self) -> &MjData<Arc<MjModel>> {
        &self.data
    }

    pub fn data_mut(&mut self) -> &mut MjData<Arc<MjModel>> {
        &mut self.data
    }

    pub fn arm(&self) -> Option<&Arm> {
        self.arm.as_ref()
    }

    pub fn object(&self) -> Option<&SceneObject> {
        self.object.as_ref()
    }

    /// The arm compiled alone ([`ArmTwin`]), when the scene's arm is `mjcf/arm.xml`'s.
    pub fn arm_twin(&self) -> Option<&ArmTwin> {
        self.twin.as_ref()
    }

    /// The pad's pose with `arm` (the scene's) at `q`, the rest of the world where it is: from the
    /// arm's twin when the scene has one, leaving the scene's state alone; otherwise by the scene's
    /// own kinematics, left at `q`.
    pub fn pad_pose_at(&mut self, arm: &Arm, q: &[f64]) -> Pose {
        match self.twin.as_mut() {
            Some(twin) => twin.pad_pose(q),
            None => {
                arm.set_q(&mut self.data, q);
                self.data.kinematics();
                arm.site_pose(&self.data)
            }
        }
    }

    /// Moves `arm` (the scene's) to `q` with the scene's kinematics current, where only the arm
    /// moved since the scene's last `mj_kinematics` (a kinematic motion): the arm's frames from its
    /// twin, the rest of the world's as they are, the bits `mj_kinematics` would give without
    /// placing the object's collision shell again. Without a twin, [`pad_pose_at`](Self::pad_pose_at)
    /// of the same `q` already computed them.
    pub(crate) fn arm_moved_to(&mut self, arm: &Arm, q: &[f64]) {
        if let Some(twin) = self.twin.as_mut() {
            arm.set_q(&mut self.data, q);
            twin.write_arm_kinematics(q, &mut self.data);
        }
    }

    /// Recomputes everything derived from the state (kinematics, contacts, sensors) without advancing time.
    pub fn forward(&mut self) {
        self.data.forward();
    }

    /// One physics step; a state gone bad (see [`fault`](Self::fault)) is a
    /// [`SimError::PhysicsFault`] naming the time.
    pub fn step(&mut self) -> Result<(), SimError> {
        self.data.step();
        self.check_state()
    }

    /// One physics step like [`step`](Self::step), but without the sensor stages: `mj_step` with
    /// `mj_forwardSkip(.., skipsensor = 1)` in place of `mj_forward`, then the model's integrator.
    ///
    /// The tactile plugin computes at the sensor stage, so a plain `mj_step` raycasts the covering on
    /// every physics step although a motion reads it once per control interval at most; this step
    /// leaves `sensordata` stale, and whoever reads a sensor runs `mj_forward` (or
    /// [`compute_sensors`](Self::compute_sensors)) first. Positions, velocities and contacts evolve
    /// exactly as with `mj_step`.
    pub fn step_without_sensors(&mut self) -> Result<(), SimError> {
        let integrator = self.model.opt().integrator;
        if integrator == MjtIntegrator::mjINT_RK4 as i32 {
            // RK4 re-evaluates the dynamics itself; keep MuJoCo's own step.
            return self.step();
        }
        self.data.check_pos();
        self.data.check_vel();
        self.data.forward_skip(MjtStage::mjSTAGE_NONE, true);
        self.data.check_acc();
        if integrator == MjtIntegrator::mjINT_EULER as i32 {
            self.data.euler();
        } else {
            self.data.implicit();
        }
        self.check_state()
    }

    /// What is wrong with the state, if it went bad: MuJoCo warned that positions, velocities or
    /// accelerations were not finite or beyond its bound (`mjWARN_BADQPOS`, `mjWARN_BADQVEL`,
    /// `mjWARN_BADQACC`, since the last [`restore`](Self::restore)), or a position, velocity or
    /// mocap pose is so now.
    ///
    /// The warnings matter as much as the values: on such a warning `mj_step` resets the whole
    /// state to the model's initial one and goes on, so after it every value is finite again,
    /// and the arm and the object have silently jumped to where they were at the start.
    pub fn fault(&self) -> Option<String> {
        let warnings = self.data.warning();
        for (warning, what) in FAULT_WARNINGS {
            let stat = &warnings[warning as usize];
            if stat.number > 0 {
                return Some(format!(
                    "MuJoCo warned of a {what} at degree of freedom {} ({} times); it reset the state",
                    stat.lastinfo, stat.number
                ));
            }
        }
        let bad = |values: &[f64]| {
            values
                .iter()
                .position(|v| v.is_nan() || v.abs() > MAX_STATE_VALUE)
        };
        let mocap_pos = self.data.mocap_pos().as_flattened();
        let mocap_quat = self.data.mocap_quat().as_flattened();
        [
            ("qpos", self.data.qpos()),
            ("qvel", self.data.qvel()),
            ("mocap_pos", mocap_pos),
            ("mocap_quat", mocap_quat),
        ]
        .into_iter()
        .find_map(|(name, values)| {
            bad(values).map(|i| format!("{name}[{i}] = {} is not a finite state value", values[i]))
        })
    }

    /// `Ok` while the state is sound, else the [`fault`](Self::fault) as a
    /// [`SimError::PhysicsFault`].
    pub fn check_state(&self) -> Result<(), SimError> {
        match self.fault() {
            None => Ok(()),
            Some(what) => Err(SimError::PhysicsFault {
                time_s: self.data.time(),
                what,
            }),
        }
    }

    /// The state to go back to after a physics fault: MuJoCo's integration state (time, positions,
    /// velocities, controls, mocap poses, warm start, ...) but for the plugins'. A bad state is
    /// refused: it could only be restored into the same fault.
    pub fn checkpoint(&self) -> Result<SceneState, SimError> {
        self.check_state()?;
        Ok(SceneState {
            values: self.data.state(CHECKPOINT_SPEC),
        })
    }

    /// Puts the world back at `state` and clears MuJoCo's warnings, then runs `mj_forward`. The
    /// plugins keep their own state: the covering sensor's reading counter runs on, so no noise
    /// stream is read twice.
    pub fn restore(&mut self, state: &SceneState) -> Result<(), SimError> {
        let plugins = self.data.state(PLUGIN_SPEC);
        self.data.reset();
        let physics = |e| SimError::Physics {
            message: format!("restoring a checkpoint: {e:?}"),
        };
        self.data
            .set_state(&state.values, CHECKPOINT_SPEC)
            .map_err(physics)?;
        self.data.set_state(&plugins, PLUGIN_SPEC).map_err(physics)?;
        self.data.forward();
        Ok(())
    }

    /// Kinematics and MuJoCo's collision detection for the current `qpos` (no dynamics, no sensors):
    /// what a sampling-based motion planner evaluates at each configuration of an edge. Contacts are
    /// then in [`contact_bodies`](Self::contact_bodies).
    pub fn kinematics_and_collision(&mut self) {
        self.data.kinematics();
        self.data.collision();
    }

    /// Whether the current kinematics leave the arm clear of any contact without MuJoCo's collision
    /// detection (`sim/contact_screen.rs`); [`Screened::Undecided`] when the scene has no screen.
    pub fn screen_contacts(&mut self) -> Screened {
        match self.contact_screen.as_mut() {
            Some(screen) => screen.screen(&self.model, &mut self.data),
            None => Screened::Undecided,
        }
    }

    /// Switches the contact screen off: every sample of a kinematic motion then goes through
    /// `mj_collision` (the reference the screen is tested and measured against).
    pub fn without_contact_screen(mut self) -> Self {
        self.contact_screen = None;
        self
    }

    /// Kinematics and the position-stage sensors for the current `qpos` (and mocap poses): all that
    /// a sensor depending only on poses needs, such as the tactile plugin, which reads site and geom
    /// frames. Contacts and the velocity and acceleration stages are left as they were (the next
    /// `mj_step`/`mj_forward` recomputes them), so a sensor that needs those needs `forward`.
    ///
    /// Every reading of every carrier passes here, so this is where a state gone bad is caught
    /// before a sensor reads it: a [`SimError::PhysicsFault`], the sensors not computed.
    pub fn compute_sensors(&mut self) -> Result<(), SimError> {
        self.check_state()?;
        self.data.kinematics();
        self.data.sensor_pos();
        Ok(())
    }

    /// Signed distance between geoms `a` and `b` (MuJoCo's `mj_geomDistance`, convex hulls for
    /// meshes), or `dist_max_m` when they are farther apart than that. Needs current kinematics.
    pub fn geom_distance_m(&mut self, a: usize, b: usize, dist_max_m: f64) -> Result<f64, SimError> {
        self.data
            .try_geom_distance(a, b, dist_max_m, None)
            .map_err(|e| SimError::Physics {
                message: format!("distance between geoms {a} and {b}: {e:?}"),
            })
    }

    /// Name of body `id` (or `body <id>` when unnamed).
    pub fn body_name(&self, id: usize) -> String {
        self.model
            .id_to_name(MjtObjBase::mjOBJ_BODY, id)
            .map(str::to_string)
            .unwrap_or_else(|| {
                if id == 0 {
                    "world".into()
                } else {
                    format!("body {id}")
                }
            })
    }

    /// Contacts currently detected, as body pairs (after `forward` or `step`).
    pub fn contact_bodies(&self) -> Vec<(usize, usize)> {
        let geom_body = self.model.geom_bodyid();
        self.data
            .contact()
            .iter()
            .map(|c| {
                (
                    geom_body[c.geom1 as usize] as usize,
                    geom_body[c.geom2 as usize] as usize,
                )
            })
            .collect()
    }

    /// The object's current pose (its mesh frame in the world).
    pub fn object_pose(&self) -> Option<Pose> {
        let object = self.object.as_ref()?;
        let b = object.body;
        Some(Pose::from_mujoco(self.data.xpos()[b], self.data.xquat()[b]))
    }

    /// Puts the object at `pose` (mesh frame in the world), at rest, and runs `mj_forward`.
    pub fn set_object_pose(&mut self, pose: Pose) -> Result<(), SimError> {
        let object = self.object.as_ref().ok_or(SimError::NoObject)?;
        let pos = pose.position_m.to_array();
        let quat = pose.mujoco_quat();
        match (object.qpos_adr, object.mocap) {
            (Some(adr), _) => {
                let qpos = self.data.qpos_mut();
                qpos[adr..adr + 3].copy_from_slice(&pos);
                qpos[adr + 3..adr + 7].copy_from_slice(&quat);
                let dof = self.model.jnt_dofadr()[self.model.body_jntadr()[object.body] as usize] as usize;
                self.data.qvel_mut()[dof..dof + 6].fill(0.0);
            }
            (None, Some(m)) => {
                self.data.mocap_pos_mut()[m] = pos;
                self.data.mocap_quat_mut()[m] = quat;
            }
            (None, None) => return Err(SimError::NoObject),
        }
        self.data.forward();
        Ok(())
    }

    /// Lowest world z of the object's mesh at `pose`.
    pub fn object_lowest_z(&self, pose: &Pose) -> Option<f64> {
        self.object.as_ref()?.mesh.lowest_z_at(pose)
    }

    /// Centre of the object's bounding box in the world, at its current pose.
    pub fn object_center(&self) -> Option<DVec3> {
        Some(self.object_pose()?.transform_point(self.object_center_local()?))
    }

    /// Centre of the object's bounding box in its own frame.
    pub fn object_center_local(&self) -> Option<DVec3> {
        self.object.as_ref()?.mesh.bounding_box_centre()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The library's unit tests provoke MuJoCo's warnings on purpose (a NaN velocity, an absurd
    /// force): they leave no `MUJOCO_LOG.TXT` in the checkout. Before `main`, while no thread runs
    /// MuJoCo, as [`keep_mujoco_log_off_disk`] requires.
    #[ctor::ctor(unsafe)]
    fn log_off_disk() {
        // SAFETY: constructors run before `main`, on the one thread there is, and after those of
        // libmujoco.so, a shared library the executable links (its globals are set up).
        unsafe { keep_mujoco_log_off_disk() };
    }

    fn mesh_xml(vertex: &str) -> String {
        format!(
            "<mujoco><asset><mesh name=\"m\" vertex=\"{vertex}\"/></asset>\
             <worldbody><geom type=\"mesh\" mesh=\"m\"/></worldbody></mujoco>"
        )
    }

    /// A ball on a free joint, 1 m above the origin, nothing to fall onto.
    fn ball() -> Scene {
        let xml = "<mujoco><worldbody><body pos=\"0 0 1\"><freejoint/><geom size=\"0.1\"/></body>\
                   </worldbody></mujoco>";
        Scene::new(compile(xml, None).unwrap(), None).unwrap()
    }

    #[test]
    fn a_state_gone_bad_is_a_fault_even_after_mujoco_reset_it_and_a_checkpoint_restores_the_world() {
        let mut scene = ball();
        scene.data_mut().qpos_mut()[0] = 0.3;
        scene.forward();
        scene.step().unwrap();
        let checkpoint = scene.checkpoint().unwrap();
        let time_s = scene.data().time();
        let qvel = scene.data().qvel().to_vec();

        // A velocity gone bad: mj_step warns and resets the whole state, so every value is finite
        // again and the ball is back at its start (x = 0); only the warning tells.
        scene.data_mut().qvel_mut()[2] = f64::NAN;
        let e = scene.step().unwrap_err();
        assert!(e.is_physics_fault(), "{e}");
        assert!(e.to_string().contains("bad velocity"), "{e}");
        assert!(scene.data().qpos().iter().all(|v| v.is_finite()));
        assert_eq!(scene.data().qpos()[0], 0.0);
        assert!(scene.checkpoint().unwrap_err().is_physics_fault());
        scene.restore(&checkpoint).unwrap();
        assert_eq!(scene.fault(), None);
        assert_eq!((scene.data().qpos()[0], scene.data().time()), (0.3, time_s));
        assert_eq!(scene.data().qvel(), qvel.as_slice());

        // An absurd force: the acceleration is out of bounds.
        scene.data_mut().qfrc_applied_mut()[0] = 1e300;
        let e = scene.step().unwrap_err();
        assert!(e.to_string().contains("bad acceleration"), "{e}");
        scene.restore(&checkpoint).unwrap();
        scene.data_mut().qfrc_applied_mut()[0] = 0.0;
        scene.step().unwrap();

        // A position corrupted outside a step is caught before the sensors read it.
        scene.data_mut().qpos_mut()[1] = f64::INFINITY;
        let e = scene.compute_sensors().unwrap_err();
        assert!(e.to_string().contains("qpos[1] = inf"), "{e}");
    }

    #[test]
    fn a_real_fault_in_an_array_attribute_is_reported_not_retried_away() {
        let valid = "0 0 0  1 0 0  0 1 0  0 0 1";
        assert!(compile(&mesh_xml(valid), None).is_ok());
        let message = compile(&mesh_xml("0 0 0  1 0 x  0 1 0  0 0 1"), None).unwrap_err();
        assert!(message.contains("bad format in attribute 'vertex'"), "{message}");
        assert!(!message.starts_with(STRAY_ERRNO_MESSAGE), "{message}");
    }
}
