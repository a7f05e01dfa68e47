//! Read-only views of the compiled model and of the state arrays the sensor needs, taken from
//! MuJoCo's raw `mjModel` / `mjData` (the plugin callbacks receive only raw pointers).

use std::ffi::{CStr, c_char};

use mujoco_rs::mujoco_c::{mjData, mjModel, mjtObj};

/// `len` elements at `ptr`, or an empty slice when MuJoCo left the array unallocated.
///
/// # Safety
/// `ptr` must point to `len` initialised elements that stay valid and unaliased by writes for `'a`.
unsafe fn slice<'a, T>(ptr: *const T, len: i64) -> &'a [T] {
    if ptr.is_null() || len <= 0 {
        &[]
    } else {
        // SAFETY: guaranteed by the caller.
        unsafe { std::slice::from_raw_parts(ptr, len as usize) }
    }
}

/// The model arrays the covering sensor reads.
#[derive(Debug, Clone, Copy)]
pub struct ModelView<'a> {
    pub geom_type: &'a [i32],
    pub geom_bodyid: &'a [i32],
    pub geom_group: &'a [i32],
    pub geom_dataid: &'a [i32],
    /// 3 per geom.
    pub geom_size: &'a [f64],
    pub geom_rbound: &'a [f64],
    pub body_rootid: &'a [i32],
    pub site_bodyid: &'a [i32],
    pub mesh_vertadr: &'a [i32],
    pub mesh_vertnum: &'a [i32],
    pub mesh_faceadr: &'a [i32],
    pub mesh_facenum: &'a [i32],
    /// 3 per vertex.
    pub mesh_vert: &'a [f32],
    /// 3 per face.
    pub mesh_face: &'a [i32],
    /// 3 per mesh: the translation MuJoCo took off the asset's vertices (its centre of mass).
    pub mesh_pos: &'a [f64],
    /// 4 per mesh (w, x, y, z): the rotation MuJoCo took off them (its principal axes), so that a
    /// vertex `v` of the asset is `mesh_quat^-1 (v - mesh_pos)` in the geom frame.
    pub mesh_quat: &'a [f64],
    pub numeric_adr: &'a [i32],
    pub numeric_size: &'a [i32],
    pub numeric_data: &'a [f64],
    pub sensor_type: &'a [i32],
    pub sensor_objtype: &'a [i32],
    pub sensor_objid: &'a [i32],
    pub sensor_adr: &'a [i32],
    pub sensor_dim: &'a [i32],
    pub sensor_plugin: &'a [i32],
    names: *const c_char,
    nnames: i64,
    raw: &'a mjModel,
}

impl<'a> ModelView<'a> {
    /// Views the arrays of a compiled model.
    ///
    /// # Safety
    /// `m` must be a model compiled by MuJoCo (all its arrays allocated with their documented sizes).
    pub unsafe fn new(m: &'a mjModel) -> Self {
        // SAFETY: MuJoCo allocates each array with the size named beside it.
        unsafe {
            Self {
                geom_type: slice(m.geom_type, m.ngeom),
                geom_bodyid: slice(m.geom_bodyid, m.ngeom),
                geom_group: slice(m.geom_group, m.ngeom),
                geom_dataid: slice(m.geom_dataid, m.ngeom),
                geom_size: slice(m.geom_size, 3 * m.ngeom),
                geom_rbound: slice(m.geom_rbound, m.ngeom),
                body_rootid: slice(m.body_rootid, m.nbody),
                site_bodyid: slice(m.site_bodyid, m.nsite),
                mesh_vertadr: slice(m.mesh_vertadr, m.nmesh),
                mesh_vertnum: slice(m.mesh_vertnum, m.nmesh),
                mesh_faceadr: slice(m.mesh_faceadr, m.nmesh),
                mesh_facenum: slice(m.mesh_facenum, m.nmesh),
                mesh_vert: slice(m.mesh_vert, 3 * m.nmeshvert),
                mesh_face: slice(m.mesh_face, 3 * m.nmeshface),
                mesh_pos: slice(m.mesh_pos, 3 * m.nmesh),
                mesh_quat: slice(m.mesh_quat, 4 * m.nmesh),
                numeric_adr: slice(m.numeric_adr, m.nnumeric),
                numeric_size: slice(m.numeric_size, m.nnumeric),
                numeric_data: slice(m.numeric_data, m.nnumericdata),
                sensor_type: slice(m.sensor_type, m.nsensor),
                sensor_objtype: slice(m.sensor_objtype, m.nsensor),
                sensor_objid: slice(m.sensor_objid, m.nsensor),
                sensor_adr: slice(m.sensor_adr, m.nsensor),
                sensor_dim: slice(m.sensor_dim, m.nsensor),
                sensor_plugin: slice(m.sensor_plugin, m.nsensor),
                names: m.names,
                nnames: m.nnames,
                raw: m,
            }
        }
    }

    pub fn ngeom(&self) -> usize {
        self.geom_type.len()
    }

    /// The name of object `id` of type `obj`, or `"<kind> <id>"` when it has none.
    pub fn name(&self, obj: mjtObj, id: usize) -> String {
        let m = self.raw;
        let (adr, kind, count) = match obj {
            mjtObj::mjOBJ_GEOM => (m.name_geomadr, "geom", m.ngeom),
            mjtObj::mjOBJ_SITE => (m.name_siteadr, "site", m.nsite),
            mjtObj::mjOBJ_SENSOR => (m.name_sensoradr, "sensor", m.nsensor),
            mjtObj::mjOBJ_MESH => (m.name_meshadr, "mesh", m.nmesh),
            mjtObj::mjOBJ_PLUGIN => (m.name_pluginadr, "plugin", m.nplugin),
            mjtObj::mjOBJ_NUMERIC => (m.name_numericadr, "numeric", m.nnumeric),
            _ => return format!("object {id}"),
        };
        // SAFETY: the name address arrays have one entry per object; names holds nnames bytes of
        // NUL-terminated strings.
        let name = unsafe {
            let adrs = slice(adr, count);
            adrs.get(id)
                .filter(|&&a| a >= 0 && (a as i64) < self.nnames)
                .map(|&a| CStr::from_ptr(self.names.add(a as usize)))
        };
        match name.map(|n| n.to_string_lossy().into_owned()) {
            Some(n) if !n.is_empty() => n,
            _ => format!("{kind} {id}"),
        }
    }

    /// The values of the `<numeric>` field named `name`, if the model has one (its whole `size`;
    /// none when MuJoCo's arrays disagree with its addresses).
    pub fn numeric(&self, name: &str) -> Option<&[f64]> {
        let id = (0..self.numeric_adr.len()).find(|&id| self.name(mjtObj::mjOBJ_NUMERIC, id) == name)?;
        let adr = usize::try_from(self.numeric_adr[id]).ok()?;
        let size = usize::try_from(self.numeric_size[id]).ok()?;
        self.numeric_data.get(adr..adr.checked_add(size)?)
    }
}

/// The state arrays the covering sensor reads at compute time (after position kinematics).
#[derive(Debug, Clone, Copy)]
pub struct PoseView<'a> {
    /// 3 per geom.
    pub geom_xpos: &'a [f64],
    /// 9 per geom, row-major.
    pub geom_xmat: &'a [f64],
    /// 3 per site.
    pub site_xpos: &'a [f64],
    /// 9 per site, row-major.
    pub site_xmat: &'a [f64],
}

impl<'a> PoseView<'a> {
    /// Views the pose arrays of `d`.
    ///
    /// # Safety
    /// `d` must be data made by MuJoCo for `m`.
    pub unsafe fn new(m: &mjModel, d: &'a mjData) -> Self {
        // SAFETY: MuJoCo sizes these arrays by ngeom and nsite.
        unsafe {
            Self {
                geom_xpos: slice(d.geom_xpos, 3 * m.ngeom),
                geom_xmat: slice(d.geom_xmat, 9 * m.ngeom),
                site_xpos: slice(d.site_xpos, 3 * m.nsite),
                site_xmat: slice(d.site_xmat, 9 * m.nsite),
            }
        }
    }
}
