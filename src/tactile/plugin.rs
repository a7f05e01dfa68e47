//! Registration of the `taction.covering` sensor plugin with MuJoCo, and its callbacks.
//!
//! MJCF:
//!
//! ```xml
//! <extension><plugin plugin="taction.covering"/></extension>
//! <sensor>
//!   <plugin name="tactile" plugin="taction.covering" objtype="site" objname="pad">
//!     <config key="rows" value="6"/> ...   (keys: see ConfigKey)
//!   </plugin>
//! </sensor>
//! ```
//!
//! The sensor writes `rows * cols` values in [0, 1] (row-major, row 0 = the pad's `+up` edge) at
//! the position stage, so any MuJoCo user reads the image from `sensordata`. Each instance keeps a
//! reading counter in its `plugin_state` (one number): it numbers the noise streams, is copied
//! by `mj_copyData` and zeroed by `mj_resetData`, so a copied or reset `mjData` continues or restarts
//! the same noise sequence. Everything else (BVHs, buffers) lives in a [`Covering`] behind
//! `plugin_data`, built in `init` and freed in `destroy`.
//!
//! The `visualize` callback draws each sensor's taxel grid as small boxes in the covering, in front
//! of the pad, coloured by the taxel values of the last reading, so MuJoCo's viewer
//! (`python -m mujoco.viewer`) shows the tactile image live on the arm.
//!
//! A bad config value fails compilation: `init` raises `mju_error` with a message naming the key
//! and its allowed range, which MuJoCo's compiler turns into the load error (as MuJoCo's own
//! plugins do).

use std::ffi::{CStr, c_char, c_int, c_void};
use std::sync::Once;

use glam::{DMat3, DVec3};
use mujoco_rs::mujoco_c::{
    mj_applyFT, mj_getPluginConfig, mj_objectVelocity, mjData, mjModel, mjp_defaultPlugin, mjp_getPlugin,
    mjp_getPluginAtSlot, mjp_registerPlugin, mjpPlugin, mjtCatBit, mjtGeom, mjtNum, mjtObj,
    mjtPluginCapabilityBit, mjtSensor, mjtStage, mju_error, mju_warning, mjv_initGeom, mjvOption, mjvScene,
};

use crate::pose::rotation_from_xmat;
use crate::tactile::config::{ConfigKey, SensorConfig};
use crate::tactile::covering::Covering;
use crate::tactile::model_view::{ModelView, PoseView};
use crate::tactile::press_back::{CoveringModulus, CoveringModulusError};
use crate::valid::Valid;

/// The plugin's registered name.
pub const PLUGIN_NAME: &str = "taction.covering";
const PLUGIN_NAME_C: &CStr = c"taction.covering";

/// The config keys as C strings, in [`ConfigKey::ALL`] order.
struct Attributes([*const c_char; 10]);
// SAFETY: the pointers refer to 'static string literals, never written.
unsafe impl Sync for Attributes {}

static ATTRIBUTES: Attributes = Attributes([
    c"rows".as_ptr(),
    c"cols".as_ptr(),
    c"pad_width_m".as_ptr(),
    c"pad_height_m".as_ptr(),
    c"thickness_m".as_ptr(),
    c"psf_sigma_m".as_ptr(),
    c"rays_per_taxel".as_ptr(),
    c"noise_fraction".as_ptr(),
    c"noise_seed".as_ptr(),
    MODULUS_KEY.as_ptr(),
]);

/// The config key of the covering's Young's modulus, pascals (`press_back.rs`): absent or 0, the
/// covering pushes nothing, as the paper's. Not a [`ConfigKey`]: it changes no image, only what
/// the covering does to the world.
const MODULUS_KEY: &CStr = c"modulus_pa";
/// [`MODULUS_KEY`] as MJCF writes it.
pub const MODULUS_CONFIG_KEY: &str = "modulus_pa";

static REGISTER: Once = Once::new();

/// Registers the plugin with MuJoCo, once per process (later calls do nothing). Must run before
/// any model using `taction.covering` is compiled; [`ensure_registered`] is the same call under
/// the name scene builders use.
///
/// Two copies of this code can live in one process: the plugin library (`plugin/`, loaded by
/// `mujoco.mj_loadPluginLibrary`) and the Python module, each registering on load. MuJoCo refuses a
/// second plugin of the same name with other callbacks by `mju_error`, which ends the process, so
/// a copy that finds `taction.covering` already registered leaves it: the first copy's callbacks
/// serve every model.
pub fn register() {
    REGISTER.call_once(|| {
        if is_registered() {
            return;
        }
        // SAFETY: mjp_defaultPlugin fills a plain C struct; every pointer stored in it is 'static
        // and every callback has the signature MuJoCo declares. mjp_registerPlugin copies it.
        unsafe {
            let mut plugin: mjpPlugin = std::mem::zeroed();
            mjp_defaultPlugin(&mut plugin);
            plugin.name = PLUGIN_NAME_C.as_ptr();
            plugin.nattribute = ATTRIBUTES.0.len() as c_int;
            plugin.attributes = ATTRIBUTES.0.as_ptr();
            plugin.capabilityflags = mjtPluginCapabilityBit::mjPLUGIN_SENSOR as c_int
                | mjtPluginCapabilityBit::mjPLUGIN_PASSIVE as c_int;
            plugin.needstage = mjtStage::mjSTAGE_POS as c_int;
            plugin.nstate = Some(nstate);
            plugin.nsensordata = Some(nsensordata);
            plugin.init = Some(init);
            plugin.destroy = Some(destroy);
            plugin.reset = Some(reset);
            plugin.compute = Some(compute);
            plugin.visualize = Some(visualize);
            mjp_registerPlugin(&plugin);
        }
    });
}

/// Whether MuJoCo already knows a plugin named `taction.covering` (this copy's or another's).
fn is_registered() -> bool {
    let mut slot: c_int = -1;
    // SAFETY: the name is NUL-terminated; MuJoCo writes the slot and returns null or a pointer into
    // its own table, which is only compared with null here.
    unsafe { !mjp_getPlugin(PLUGIN_NAME_C.as_ptr(), &mut slot).is_null() }
}

/// Makes sure the plugin is registered before compiling a model that uses it.
pub fn ensure_registered() {
    register();
}

/// Whether plugin instance `instance` of `m` is a `taction.covering` instance.
pub fn is_covering_instance(m: &mjModel, instance: usize) -> bool {
    if instance as i64 >= m.nplugin || m.plugin.is_null() {
        return false;
    }
    // SAFETY: m.plugin has nplugin slots; mjp_getPluginAtSlot returns null or a registered plugin.
    unsafe {
        let slot = *m.plugin.add(instance);
        let plugin = mjp_getPluginAtSlot(slot);
        !plugin.is_null() && !(*plugin).name.is_null() && CStr::from_ptr((*plugin).name) == PLUGIN_NAME_C
    }
}

/// Whether covering instance `instance` of `m` runs this copy's callbacks (see [`instance_state`]).
fn made_by_this_copy(m: &mjModel, instance: usize) -> bool {
    // SAFETY: `instance` is a covering instance of `m` (checked by the caller), so its slot holds a
    // registered plugin.
    unsafe {
        let plugin = mjp_getPluginAtSlot(*m.plugin.add(instance));
        !plugin.is_null()
            && (*plugin)
                .init
                .is_some_and(|registered| std::ptr::fn_addr_eq(registered, init as InitCallback))
    }
}

/// The signature of a plugin's `init` callback.
type InitCallback = unsafe extern "C" fn(*const mjModel, *mut mjData, c_int) -> c_int;

/// The config of plugin instance `instance`, parsed and validated.
pub fn instance_config(
    m: &mjModel,
    instance: usize,
) -> Result<Valid<SensorConfig>, crate::tactile::ConfigError> {
    let values: Vec<Option<String>> = ConfigKey::ALL
        .iter()
        .zip(ATTRIBUTES.0.iter())
        .map(|(_, &attr)| {
            // SAFETY: m is a compiled (or compiling) model and attr a NUL-terminated key; MuJoCo
            // returns null or a NUL-terminated string owned by the model.
            unsafe {
                let value = mj_getPluginConfig(m, instance as c_int, attr);
                (!value.is_null()).then(|| CStr::from_ptr(value).to_string_lossy().into_owned())
            }
        })
        .collect();
    SensorConfig::from_key_values(|key| {
        let i = ConfigKey::ALL.iter().position(|k| *k == key)?;
        values[i].as_deref()
    })
}

/// The sensors of `m` that use plugin instance `instance`.
pub fn instance_sensors(model: &ModelView, instance: usize) -> Vec<usize> {
    (0..model.sensor_type.len())
        .filter(|&s| {
            model.sensor_type[s] == mjtSensor::mjSENS_PLUGIN as i32
                && model.sensor_plugin[s] == instance as i32
        })
        .collect()
}

/// Copies `message` into a fixed buffer as a NUL-terminated string, truncated if needed.
fn c_message(message: &str) -> [u8; 1024] {
    let mut buffer = [0u8; 1024];
    let bytes = message.as_bytes();
    let n = bytes.len().min(buffer.len() - 1);
    buffer[..n].copy_from_slice(&bytes[..n]);
    // Interior NULs would cut the message short; replace them.
    for b in &mut buffer[..n] {
        if *b == 0 {
            *b = b' ';
        }
    }
    buffer
}

unsafe extern "C" fn nstate(_m: *const mjModel, _instance: c_int) -> c_int {
    1
}

/// Sets up the instance; on failure returns the message. The callers turn it into plain bytes and
/// drop it before raising `mju_error` (which does not return), so that they hold no destructors
/// when MuJoCo's error handler jumps out of them.
fn set_up(m: &mjModel, d: &mut mjData, instance: c_int) -> Result<(), String> {
    let config = instance_config(m, instance as usize).map_err(|e| e.to_string())?;
    // SAFETY: m is the model being compiled or used, with all arrays allocated.
    let model = unsafe { ModelView::new(m) };
    let sensors = instance_sensors(&model, instance as usize);
    let covering = Covering::new(&model, config, &sensors)
        .map_err(|e| e.to_string())?
        .with_modulus(instance_modulus(m, instance as usize)?);
    // SAFETY: plugin_data has nplugin entries; the pointer is reclaimed in `destroy`.
    unsafe { *d.plugin_data.add(instance as usize) = Box::into_raw(Box::new(covering)) as usize };
    Ok(())
}

unsafe extern "C" fn nsensordata(m: *const mjModel, instance: c_int, _sensor_id: c_int) -> c_int {
    // SAFETY: MuJoCo passes the model being compiled.
    let m = unsafe { &*m };
    let message = match instance_config(m, instance as usize) {
        Ok(config) => return config.taxel_count() as c_int,
        Err(e) => c_message(&e.to_string()),
    };
    // SAFETY: the format is a literal and its argument NUL-terminated; no value with a destructor
    // is alive in this frame (mju_error unwinds by longjmp to the compiler).
    unsafe { mju_error(c"%s".as_ptr(), message.as_ptr()) };
    0
}

unsafe extern "C" fn init(m: *const mjModel, d: *mut mjData, instance: c_int) -> c_int {
    // SAFETY: MuJoCo passes valid model and data pointers.
    let (m, d) = unsafe { (&*m, &mut *d) };
    let message = match std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| set_up(m, d, instance))) {
        Ok(Ok(())) => return 0,
        Ok(Err(message)) => c_message(&message),
        Err(_) => c_message("taction.covering: internal error while setting up the sensor"),
    };
    // SAFETY: as in `nsensordata`: only plain bytes are alive here.
    unsafe { mju_error(c"%s".as_ptr(), message.as_ptr()) };
    -1
}

unsafe extern "C" fn destroy(d: *mut mjData, instance: c_int) {
    // SAFETY: plugin_data[instance] is 0 or the pointer `set_up` leaked from a Box<Covering>.
    unsafe {
        let slot = (*d).plugin_data.add(instance as usize);
        if *slot != 0 {
            drop(Box::from_raw(*slot as *mut Covering));
            *slot = 0;
        }
    }
}

unsafe extern "C" fn reset(
    _m: *const mjModel,
    plugin_state: *mut mjtNum,
    _plugin_data: *mut c_void,
    _instance: c_int,
) {
    // SAFETY: MuJoCo passes this instance's state, of the size `nstate` returned.
    unsafe { *plugin_state = 0.0 };
}

/// The covering modulus of instance `instance` ([`MODULUS_KEY`]); absent or empty, none.
fn instance_modulus(m: &mjModel, instance: usize) -> Result<CoveringModulus, String> {
    // SAFETY: as in `instance_config`.
    let text = unsafe {
        let value = mj_getPluginConfig(m, instance as c_int, MODULUS_KEY.as_ptr());
        (!value.is_null()).then(|| CStr::from_ptr(value).to_string_lossy().into_owned())
    };
    match text.as_deref().map(str::trim).filter(|t| !t.is_empty()) {
        None => Ok(CoveringModulus::NONE),
        Some(text) => text
            .parse()
            .map_err(|e: CoveringModulusError| format!("taction.covering: {MODULUS_CONFIG_KEY}: {e}")),
    }
}

unsafe extern "C" fn compute(m: *const mjModel, d: *mut mjData, instance: c_int, capability: c_int) {
    // SAFETY: MuJoCo passes valid pointers; plugin_data[instance] is our Covering (set in init).
    unsafe {
        let (m, d) = (&*m, &mut *d);
        let covering = *d.plugin_data.add(instance as usize) as *mut Covering;
        if covering.is_null() {
            return;
        }
        if capability == mjtPluginCapabilityBit::mjPLUGIN_PASSIVE as c_int {
            press_back(m, d, &mut *covering);
        } else {
            read_covering(m, d, instance, &mut *covering);
        }
    }
}

/// The sensor stage: the image into `sensordata`, the reading counter advanced.
///
/// # Safety
/// As [`compute`]'s arguments: `covering` is instance `instance`'s.
unsafe fn read_covering(m: &mjModel, d: &mut mjData, instance: c_int, covering: &mut Covering) {
    // SAFETY: the state address comes from the model; sensordata has nsensordata entries.
    unsafe {
        let state = d
            .plugin_state
            .add(*m.plugin_stateadr.add(instance as usize) as usize);
        let reading = *state as u64;
        let poses = PoseView::new(m, d);
        let sensordata = std::slice::from_raw_parts_mut(d.sensordata, m.nsensordata as usize);
        let computed = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
            covering.compute(&poses, reading, sensordata)
        }));
        if computed.is_err() {
            mju_warning(
                c"%s".as_ptr(),
                c"taction.covering: internal error while computing a reading".as_ptr(),
            );
        }
        *state = (reading + 1) as mjtNum;
    }
}

/// The passive stage: the covering's push (`press_back.rs`) added to `qfrc_passive`, on each body
/// it touches at the pad's origin and, reversed, on the body carrying the pad, so MuJoCo's step
/// integrates it. Nothing when the covering has no modulus.
///
/// # Safety
/// As [`compute`]'s arguments.
unsafe fn press_back(m: &mjModel, d: &mut mjData, covering: &mut Covering) {
    if covering.modulus().is_none() {
        return;
    }
    // SAFETY: positions and velocities are current in the passive stage; mj_objectVelocity reads
    // them; mj_applyFT adds to qfrc_passive, nv long.
    unsafe {
        let velocity = |body: usize, point: DVec3| point_velocity(m, d, body, point);
        let poses = PoseView::new(m, d);
        let pressed =
            std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| covering.press(&poses, &velocity)));
        let Ok(pressed) = pressed else {
            mju_warning(
                c"%s".as_ptr(),
                c"taction.covering: internal error while pressing back".as_ptr(),
            );
            return;
        };
        for (pad_body, press) in pressed {
            let origin = press.about_m.to_array();
            for (body, sign) in [(press.body, 1.0), (pad_body, -1.0)] {
                let force = (press.force_n * sign).to_array();
                let torque = (press.torque_nm * sign).to_array();
                mj_applyFT(m, d, &force, &torque, &origin, body as c_int, d.qfrc_passive);
            }
        }
    }
}

/// The world velocity of `body`'s point `point`.
///
/// # Safety
/// `d` holds current positions and velocities of `m`.
unsafe fn point_velocity(m: &mjModel, d: &mjData, body: usize, point: DVec3) -> DVec3 {
    let mut spatial = [0.0; 6];
    // SAFETY: `body` is a body of `m`; the result has 6 values (rotation, then translation of the
    // body frame's origin, world axes).
    unsafe { mj_objectVelocity(m, d, mjtObj::mjOBJ_BODY as c_int, body as c_int, &mut spatial, 0) };
    let angular = DVec3::from_slice(&spatial[..3]);
    let linear = DVec3::from_slice(&spatial[3..]);
    let origin = unsafe { DVec3::from_slice(std::slice::from_raw_parts(d.xpos.add(3 * body), 3)) };
    linear + angular.cross(point - origin)
}

/// The instance state behind plugin instance `instance` of `d`, when it is a covering instance
/// made by this copy of the plugin's code. When another copy registered `taction.covering` first
/// ([`register`]: the plugin library loaded before the Python module), its instances hold that
/// copy's `Covering`, whose layout this copy cannot vouch for: `None`, as for any other plugin
/// (the readings in `sensordata` are the same either way).
///
/// # Safety
/// `d` must be data made for `m` by MuJoCo, with plugins initialised.
pub unsafe fn instance_state<'d>(m: &mjModel, d: &'d mjData, instance: usize) -> Option<&'d Covering> {
    if !is_covering_instance(m, instance) || !made_by_this_copy(m, instance) || d.plugin_data.is_null() {
        return None;
    }
    // SAFETY: plugin_data[instance] of a covering instance is null or a live Covering.
    unsafe {
        let ptr = *d.plugin_data.add(instance) as *const Covering;
        ptr.as_ref()
    }
}

/// One drawn taxel: a box in the covering in front of the pad, in world coordinates.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TaxelTile {
    /// Box centre, world metres.
    pub center_m: DVec3,
    /// Half extents along the pad's x, up and normal axes, metres.
    pub half_size_m: [f64; 3],
    /// Box orientation: the pad site's frame (columns x, up, normal), world.
    pub frame: DMat3,
    pub rgba: [f32; 4],
}

/// Fraction of the taxel pitch a drawn tile covers, so the grid lines between taxels stay visible.
const TILE_FILL: f64 = 0.9;

/// The colour of a taxel value in [0, 1]: dark blue for no contact through orange to pale yellow
/// at full compression, so that the image reads in the viewer as it does in `taction sense` PNGs
/// (brighter = deeper).
pub fn taxel_rgba(value: f64) -> [f32; 4] {
    let v = if value.is_finite() {
        value.clamp(0.0, 1.0)
    } else {
        0.0
    } as f32;
    let dark = [0.10, 0.12, 0.35];
    let bright = [1.0, 0.85, 0.25];
    [
        dark[0] + (bright[0] - dark[0]) * v,
        dark[1] + (bright[1] - dark[1]) * v,
        dark[2] + (bright[2] - dark[2]) * v,
        0.85,
    ]
}

/// The tiles of one sensor's image (row-major `values`, row 0 the pad's up edge, column 0 its left
/// edge seen from behind the pad, as in `sensordata`), for a pad site at `site_pos_m` with
/// world-from-site rotation `site_frame` (columns: site x, up, normal). Each tile fills the
/// covering's depth (Sec. V-A2: the viewing volume) over its taxel.
pub fn taxel_tiles(
    config: &SensorConfig,
    site_pos_m: DVec3,
    site_frame: DMat3,
    values: &[f64],
) -> Vec<TaxelTile> {
    let pitch_x = config.pad_width_m / config.cols as f64;
    let pitch_y = config.pad_height_m / config.rows as f64;
    let half_size_m = [
        0.5 * TILE_FILL * pitch_x,
        0.5 * TILE_FILL * pitch_y,
        0.5 * config.thickness_m,
    ];
    let mut tiles = Vec::with_capacity(config.taxel_count());
    for row in 0..config.rows {
        for col in 0..config.cols {
            // Columns run along the pad's right = normal x up = -site x.
            let local = DVec3::new(
                0.5 * config.pad_width_m - (col as f64 + 0.5) * pitch_x,
                0.5 * config.pad_height_m - (row as f64 + 0.5) * pitch_y,
                0.5 * config.thickness_m,
            );
            let value = values.get(row * config.cols + col).copied().unwrap_or(0.0);
            tiles.push(TaxelTile {
                center_m: site_pos_m + site_frame * local,
                half_size_m,
                frame: site_frame,
                rgba: taxel_rgba(value),
            });
        }
    }
    tiles
}

unsafe extern "C" fn visualize(
    m: *const mjModel,
    d: *mut mjData,
    _opt: *const mjvOption,
    scn: *mut mjvScene,
    instance: c_int,
) {
    // SAFETY: MuJoCo passes valid model, data and scene pointers; plugin_data[instance] is our
    // Covering or null; the site and sensor arrays have the sizes ModelView/PoseView assume; the
    // scene's geoms array has maxgeom slots, of which ngeom are used.
    unsafe {
        let (m, d, scn) = (&*m, &mut *d, &mut *scn);
        let covering = *d.plugin_data.add(instance as usize) as *const Covering;
        let Some(covering) = covering.as_ref() else {
            return;
        };
        let config = *covering.config();
        let model = ModelView::new(m);
        let poses = PoseView::new(m, d);
        let sensordata = std::slice::from_raw_parts(d.sensordata, m.nsensordata.max(0) as usize);
        for sensor in instance_sensors(&model, instance as usize) {
            let site = model.sensor_objid[sensor].max(0) as usize;
            let adr = model.sensor_adr[sensor].max(0) as usize;
            let values = sensordata.get(adr..adr + config.taxel_count()).unwrap_or(&[]);
            let p = &poses.site_xpos[3 * site..3 * site + 3];
            let r = &poses.site_xmat[9 * site..9 * site + 9];
            let frame = rotation_from_xmat(r);
            for tile in taxel_tiles(&config, DVec3::new(p[0], p[1], p[2]), frame, values) {
                if scn.ngeom >= scn.maxgeom {
                    if scn.status == 0 {
                        mju_warning(
                            c"%s".as_ptr(),
                            c"taction.covering: the scene's geom buffer is full; some taxels are not drawn (raise maxgeom)"
                                .as_ptr(),
                        );
                        scn.status = 1;
                    }
                    return;
                }
                let mat = tile.frame.transpose().to_cols_array();
                let geom = scn.geoms.add(scn.ngeom as usize);
                mjv_initGeom(
                    geom,
                    mjtGeom::mjGEOM_BOX as c_int,
                    &tile.half_size_m,
                    &tile.center_m.to_array(),
                    &mat,
                    &tile.rgba,
                );
                (*geom).objtype = mjtObj::mjOBJ_UNKNOWN as c_int;
                (*geom).objid = sensor as c_int;
                (*geom).category = mjtCatBit::mjCAT_DECOR as c_int;
                (*geom).segid = scn.ngeom;
                scn.ngeom += 1;
            }
        }
    }
}
