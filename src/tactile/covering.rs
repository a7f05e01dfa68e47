//! The covering sensor's computation for one plugin instance: what it senses, the BVHs it built at
//! init, and the per-reading pass from geom poses to the taxel image (Sec. V-A2).
//!
//! The computation runs in the pad site's frame (x, y, z) = (site x, up, normal), right-handed.
//! The image's columns run the other way, along `PadPose::right() = normal x up = -site x` (column
//! 0 is the left edge seen from behind the pad, looking along the normal), so the finished
//! per-sample map is mirrored left-right before image formation; the grid is exactly symmetric, so
//! this is a relabelling of samples.
//!
//! For each sample `s` of the pad grid, the ray is the line through the sample along the pad
//! normal. With `z(s)` the pad-frame depth of the nearest surface of any sensed solid in front of
//! the pad (`-inf` when the pad point is inside a solid, `+inf` when nothing is hit), the
//! penetration is `p(s) = clamp(t - z(s), 0, t)`: an object that pushed through the covering, or
//! through the pad itself, reads full penetration, never NaN.
//!
//! Sensed: every geom except those of the kinematic tree the pad is mounted on (same
//! `body_rootid` as the pad site's body; when that root is the world body, only the geoms of the
//! site's own body are skipped). Meshes are rasterised from the faces of their BVH leaves over the
//! sample rays ([`query_region`]), and a second, small query checks the pad's rigid back; each
//! mesh's own bounding radius skips meshes out of reach and keeps both queries off empty space.
//! Primitives are cut analytically ([`crate::tactile::primitive`]). A mesh asset that is a coarse
//! copy of a large scan comes with the exact surface as two `<numeric>` fields
//! (`sim::sensed_surface_names`); its BVH is built from those.

use std::sync::Arc;

use glam::{DMat3, DVec3};
use mujoco_rs::mujoco_c::{mjtGeom, mjtObj};

use crate::pose::rotation_from_xmat;
use crate::sim::mjcf::{COLLISION_GROUP, sensed_surface_names};
use crate::tactile::SensorConfig;
use crate::tactile::back_contact::triangle_overlaps_box;
use crate::tactile::config::ConfigError;
use crate::tactile::formation::ImageFormation;
use crate::tactile::grid::SampleGrid;
use crate::tactile::mesh_bvh::{CheckedMesh, Leaf, MeshBvh, MeshBvhError, OrientedBox};
use crate::tactile::model_view::{ModelView, PoseView};
use crate::tactile::press_back::{BodyPress, CoveringModulus, column_pressure_pa};
use crate::tactile::primitive::{GeomShape, Solid};
use crate::tactile::raster::DepthBuffer;
use crate::tactile::shared_bvh::SHARED_BVHS;
use crate::valid::Valid;

/// Why a plugin instance cannot be set up; each names the offending part of the model, briefly
/// (MuJoCo keeps about 80 characters of a plugin's compile error).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum CoveringError {
    #[error(transparent)]
    Config(#[from] ConfigError),
    #[error("taction.covering: sensor '{sensor}' must be on a site (objtype=\"site\")")]
    NotASite { sensor: String, objtype: i32 },
    #[error("taction.covering: sensor '{sensor}' has dim {got}, not rows*cols = {expected}")]
    Dimension {
        sensor: String,
        got: i32,
        expected: usize,
    },
    #[error("taction.covering: cannot sense geom '{geom}', a {kind}")]
    UnsupportedGeom { geom: String, kind: &'static str },
    #[error("taction.covering: mesh '{mesh}': {source}")]
    Mesh { mesh: String, source: MeshBvhError },
    #[error("taction.covering: mesh '{mesh}': sensed surface: {what}")]
    SensedSurface { mesh: String, what: String },
}

/// How one sensed geom is cut by the rays.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Shape {
    /// Index into `Covering::meshes`.
    Mesh(usize),
    Solid(Solid),
}

#[derive(Debug, Clone, Copy, PartialEq)]
struct SensedGeom {
    geom: usize,
    /// The body the geom is on: the one the covering pushes ([`Covering::press`]).
    body: usize,
    shape: Shape,
    /// Bounding-sphere radius about the geom origin; 0 for unbounded (planes).
    rbound_m: f64,
}

/// One `<sensor><plugin>` element using the instance.
#[derive(Debug, Clone)]
struct PadSensor {
    adr: usize,
    site: usize,
    /// The body carrying the pad: it feels the covering's push reversed.
    pad_body: usize,
    /// Noise stream seed of this sensor.
    noise_seed: u64,
    sensed: Vec<SensedGeom>,
}

/// Counters for diagnostics and tests.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct CoveringStats {
    /// BVHs built by this instance (all at init; compute never builds one).
    pub bvh_builds: usize,
    /// BVHs taken, at init, from another instance that read the same mesh
    /// (`tactile::shared_bvh`).
    pub bvh_shared: usize,
    /// Triangles over all BVHs.
    pub bvh_triangles: usize,
    /// Readings computed since init.
    pub readings: u64,
    /// Mesh faces rasterised in the last reading (those of the BVH leaves over the sample rays).
    pub last_faces: usize,
    /// Samples of the last reading at full penetration: there the object reached the pad's rigid
    /// back (the covering is fully compressed), which the image, blurred by the point-spread and
    /// averaged over taxels, may show well below 1 (a sliver of an edge, a thin blade).
    pub last_full_samples: usize,
    /// Whether, in the last reading, a mesh triangle lay in the pad's rigid back (the pad's
    /// rectangle swept `RIGID_BACK_DEPTH_M` behind the pad plane): the object at the back even
    /// between the samples, or a blade that one turn of the pad swept past the covering
    /// (`triangle_overlaps_box`).
    pub last_back_touched: bool,
}

/// Depth of the pad's rigid back behind the pad plane, metres: the `sensor_back` box of
/// `mjcf/arm.xml` (8 mm).
pub const RIGID_BACK_DEPTH_M: f64 = 0.008;

/// A plugin instance's state (stored behind MuJoCo's `plugin_data`).
#[derive(Debug)]
pub struct Covering {
    config: SensorConfig,
    grid: SampleGrid,
    formation: ImageFormation,
    sensors: Vec<PadSensor>,
    meshes: Vec<Arc<MeshBvh>>,
    // Scratch space, reused by every reading.
    depth: DepthBuffer,
    leaves: Vec<Leaf>,
    stack: Vec<usize>,
    /// Per sample, which sensed geom (index into the sensor's list) is nearest, and the depths
    /// before a geom was drawn: kept only while [`press`](Covering::press) works.
    owner: Vec<usize>,
    before_m: Vec<f64>,
    stats: CoveringStats,
    /// How hard the covering pushes back; [`CoveringModulus::NONE`] unless the scene asked.
    modulus: CoveringModulus,
    /// What the last [`press`](Covering::press) applied, per pressed body.
    last_press: Vec<BodyPress>,
}

/// The box, in a mesh's geom frame, that holds every face that can change a reading's depths:
/// the mesh placed in the pad frame by `x -> placement.0 x + placement.1`, within `rbound_m` of
/// `placement.1` (0: no bound known), under a covering `thickness_m` thick.
///
/// Across the pad it spans the sample rays (which pierce the pad plane half a sample inside its
/// edges: a face elsewhere covers no sample); along the normal `[z_lo, t]` with
/// `z_lo = min(o_z - r, 0)`: beyond `t` nothing is sensed, and behind the pad plane every crossing
/// down to the mesh's far side counts for the inside test. A relative 1e-6 of margin keeps
/// rounding from dropping a face on its boundary.
pub fn query_region(
    grid: &SampleGrid,
    placement: (&DMat3, DVec3),
    rbound_m: f64,
    thickness_m: f64,
) -> OrientedBox {
    let (o, t) = (placement.1, thickness_m);
    let z_lo = (o.z - rbound_m).min(0.0);
    let (hx, hy) = grid.ray_half_extent_m();
    pad_box(
        placement,
        DVec3::new(0.0, 0.0, 0.5 * (z_lo + t)),
        DVec3::new(hx, hy, 0.5 * (t - z_lo)),
    )
}

/// The pad-frame box of centre `centre_pad` and half-sizes `half_pad`, widened by a relative
/// 1e-6, in the geom frame of a mesh placed by `x -> placement.0 x + placement.1`.
fn pad_box(placement: (&DMat3, DVec3), centre_pad: DVec3, half_pad: DVec3) -> OrientedBox {
    let (m, o) = placement;
    let to_geom = m.transpose();
    OrientedBox {
        centre: to_geom * (centre_pad - o),
        axes: [to_geom.x_axis, to_geom.y_axis, to_geom.z_axis],
        half: half_pad + 1e-6 * half_pad.element_sum(),
    }
}

/// The pad's rigid back in the pad frame, as a box's centre and half-sizes: the whole pad
/// rectangle swept [`RIGID_BACK_DEPTH_M`] behind the pad plane.
fn rigid_back(grid: &SampleGrid) -> (DVec3, DVec3) {
    (
        DVec3::new(0.0, 0.0, -0.5 * RIGID_BACK_DEPTH_M),
        DVec3::new(grid.half_width_m, grid.half_height_m, 0.5 * RIGID_BACK_DEPTH_M),
    )
}

/// Whether a face of `mesh` (placed as in [`query_region`]) lies in the pad's [`rigid_back`],
/// where the object is felt even between the samples (`triangle_overlaps_box`, touching counts). Its own BVH query,
/// since the depths need only the faces over the sample rays; none when the mesh lies wholly in
/// front of the pad plane.
fn rigid_back_touched(
    grid: &SampleGrid,
    mesh: &MeshBvh,
    placement: (&DMat3, DVec3),
    rbound_m: f64,
    (stack, leaves): (&mut Vec<usize>, &mut Vec<Leaf>),
) -> bool {
    let (m, o) = placement;
    if rbound_m > 0.0 && o.z - rbound_m > 0.0 {
        return false;
    }
    let (centre, half) = rigid_back(grid);
    leaves.clear();
    mesh.leaves_near(&pad_box(placement, centre, half), stack, leaves);
    leaves
        .iter()
        .flat_map(|&leaf| mesh.leaf_faces(leaf))
        .any(|(face, _)| {
            let corners = mesh.corners(face, m, o);
            corners.iter().any(|p| p.z <= 0.0) && triangle_overlaps_box(corners, centre, half)
        })
}

/// One BVH per mesh the sensed geoms use, built at init (a reading never builds one) or taken from
/// an instance that read the same mesh, shared by every geom and sensor that uses the mesh.
struct MeshCache {
    meshes: Vec<Arc<MeshBvh>>,
    /// The index into `meshes` of each model mesh, once built.
    slot: Vec<Option<usize>>,
    stats: CoveringStats,
}

impl MeshCache {
    fn new(model: &ModelView) -> Self {
        Self {
            meshes: Vec::new(),
            slot: vec![None; model.mesh_vertadr.len()],
            stats: CoveringStats::default(),
        }
    }

    /// The slot of model mesh `mesh`, finding or building its BVH the first time.
    fn slot(&mut self, model: &ModelView, mesh: usize) -> Result<usize, CoveringError> {
        if let Some(slot) = self.slot[mesh] {
            return Ok(slot);
        }
        let name = model.name(mjtObj::mjOBJ_MESH, mesh);
        let checked = match sensed_surface(model, mesh, &name)? {
            Some((vertex_xyz, face)) => CheckedMesh::new(&vertex_xyz, &face),
            None => {
                let (va, vn) = (
                    model.mesh_vertadr[mesh] as usize,
                    model.mesh_vertnum[mesh] as usize,
                );
                let (fa, fnum) = (
                    model.mesh_faceadr[mesh] as usize,
                    model.mesh_facenum[mesh] as usize,
                );
                CheckedMesh::new(
                    &model.mesh_vert[3 * va..3 * (va + vn)],
                    &model.mesh_face[3 * fa..3 * (fa + fnum)],
                )
            }
        }
        .map_err(|source| CoveringError::Mesh { mesh: name, source })?;
        let (bvh, built) = SHARED_BVHS.find_or_build(checked);
        if built {
            self.stats.bvh_builds += 1;
        } else {
            self.stats.bvh_shared += 1;
        }
        self.stats.bvh_triangles += bvh.triangle_count();
        self.meshes.push(bvh);
        self.slot[mesh] = Some(self.meshes.len() - 1);
        Ok(self.meshes.len() - 1)
    }
}

/// A surface as [`CheckedMesh::new`] takes it: flat `xyz` vertex coordinates and vertex-index triples.
type FlatMesh = (Vec<f32>, Vec<i32>);

/// The exact surface of model mesh `mesh` (named `name`) when the model carries it beside a coarse
/// asset (`sim::ObjectSurfaces`, issue 39): its vertices in the geom frame, as MuJoCo placed the
/// asset's (`mesh_quat^-1 (v - mesh_pos)`), and its faces; none when the mesh has no such fields.
fn sensed_surface(model: &ModelView, mesh: usize, name: &str) -> Result<Option<FlatMesh>, CoveringError> {
    let (vertex_name, face_name) = sensed_surface_names(name);
    let fault = |what: String| CoveringError::SensedSurface {
        mesh: name.to_string(),
        what,
    };
    let (vertex, face) = match (model.numeric(&vertex_name), model.numeric(&face_name)) {
        (None, None) => return Ok(None),
        (Some(vertex), Some(face)) => (vertex, face),
        (Some(_), None) => return Err(fault(format!("'{vertex_name}' without '{face_name}'"))),
        (None, Some(_)) => return Err(fault(format!("'{face_name}' without '{vertex_name}'"))),
    };
    if vertex.len() % 3 != 0 || face.len() % 3 != 0 {
        return Err(fault("a field's size is not a multiple of 3".into()));
    }
    let face = face
        .iter()
        .map(|&i| {
            (i.fract() == 0.0 && (0.0..=f64::from(i32::MAX)).contains(&i))
                .then_some(i as i32)
                .ok_or_else(|| fault(format!("face index {i} is not a vertex index")))
        })
        .collect::<Result<Vec<i32>, _>>()?;
    let offset = DVec3::from_slice(&model.mesh_pos[3 * mesh..3 * mesh + 3]);
    let [w, x, y, z] = [0, 1, 2, 3].map(|k| model.mesh_quat[4 * mesh + k]);
    let to_geom = glam::DQuat::from_xyzw(x, y, z, w).normalize().inverse();
    let vertex_xyz = vertex
        .chunks_exact(3)
        .flat_map(|v| (to_geom * (DVec3::from_slice(v) - offset)).as_vec3().to_array())
        .collect();
    Ok(Some((vertex_xyz, face)))
}

/// Checks that `sensor` is on a site and has one value per taxel; returns its site.
fn sensor_site(model: &ModelView, config: &SensorConfig, sensor: usize) -> Result<usize, CoveringError> {
    let sensor_name = || model.name(mjtObj::mjOBJ_SENSOR, sensor);
    let objtype = model.sensor_objtype[sensor];
    if objtype != mjtObj::mjOBJ_SITE as i32 {
        return Err(CoveringError::NotASite {
            sensor: sensor_name(),
            objtype,
        });
    }
    if model.sensor_dim[sensor] as i64 != config.taxel_count() as i64 {
        return Err(CoveringError::Dimension {
            sensor: sensor_name(),
            got: model.sensor_dim[sensor],
            expected: config.taxel_count(),
        });
    }
    Ok(model.sensor_objid[sensor] as usize)
}

/// The geoms the sensor on `site` senses (see the module docs): all but those of the kinematic
/// tree carrying the pad, and but collision-only geoms (an object's collision shell is not the
/// surface the covering presses on).
fn sensed_geoms(
    model: &ModelView,
    site: usize,
    cache: &mut MeshCache,
) -> Result<Vec<SensedGeom>, CoveringError> {
    let body = model.site_bodyid[site] as usize;
    let root = model.body_rootid[body] as usize;
    let own = |geom_body: usize| {
        if root == 0 {
            geom_body == body
        } else {
            model.body_rootid[geom_body] as usize == root
        }
    };
    (0..model.ngeom())
        .filter(|&geom| !own(model.geom_bodyid[geom] as usize) && model.geom_group[geom] != COLLISION_GROUP)
        .map(|geom| sensed_geom(model, geom, cache))
        .collect()
}

/// How the rays cut `geom`, and its bound.
fn sensed_geom(model: &ModelView, geom: usize, cache: &mut MeshCache) -> Result<SensedGeom, CoveringError> {
    let t = model.geom_type[geom];
    let shape = match GeomShape::of_geom(t, &model.geom_size[3 * geom..3 * geom + 3]) {
        GeomShape::Solid(solid) => Shape::Solid(solid),
        GeomShape::Mesh => Shape::Mesh(cache.slot(model, model.geom_dataid[geom] as usize)?),
        GeomShape::Unsupported(kind) => {
            return Err(CoveringError::UnsupportedGeom {
                geom: model.name(mjtObj::mjOBJ_GEOM, geom),
                kind,
            });
        }
    };
    // A mesh's own bound is tight (MuJoCo's `geom_rbound` of a mesh is looser): it skips more
    // geoms out of reach and keeps the queries off empty space.
    let rbound_m = match shape {
        _ if t == mjtGeom::mjGEOM_PLANE as i32 => 0.0,
        Shape::Mesh(slot) => cache.meshes[slot].bounding_radius_m(),
        Shape::Solid(_) => model.geom_rbound[geom],
    };
    Ok(SensedGeom {
        geom,
        body: model.geom_bodyid[geom] as usize,
        shape,
        rbound_m,
    })
}

impl Covering {
    /// Sets up the instance whose sensors are `sensor_ids` (the model's sensors using it): checks
    /// each is on a site with the right dimension, chooses the sensed geoms, and builds one BVH per
    /// mesh they use (or takes it from an instance that read the same mesh).
    pub fn new(
        model: &ModelView,
        config: Valid<SensorConfig>,
        sensor_ids: &[usize],
    ) -> Result<Self, CoveringError> {
        let config = config.into_inner();
        let grid = SampleGrid::new(&config);
        let formation = ImageFormation::new(&config, &grid);
        let mut cache = MeshCache::new(model);
        let mut sensors = Vec::with_capacity(sensor_ids.len());
        for (k, &sensor) in sensor_ids.iter().enumerate() {
            let site = sensor_site(model, &config, sensor)?;
            let sensed = sensed_geoms(model, site, &mut cache)?;
            // The first sensor keeps the configured stream; further ones get substreams.
            let noise_seed = if k == 0 {
                config.noise_seed
            } else {
                crate::rng::substream(config.noise_seed, k as u64)
            };
            sensors.push(PadSensor {
                adr: model.sensor_adr[sensor] as usize,
                site,
                pad_body: model.site_bodyid[site] as usize,
                noise_seed,
                sensed,
            });
        }
        let depth = DepthBuffer::new(&grid);
        Ok(Self {
            config,
            grid,
            formation,
            sensors,
            meshes: cache.meshes,
            depth,
            leaves: Vec::new(),
            stack: Vec::new(),
            owner: Vec::new(),
            before_m: Vec::new(),
            stats: cache.stats,
            modulus: CoveringModulus::NONE,
            last_press: Vec::new(),
        })
    }

    /// The instance with a covering of Young's modulus `modulus` pushing back (`press_back.rs`).
    pub fn with_modulus(mut self, modulus: CoveringModulus) -> Self {
        self.modulus = modulus;
        self
    }

    pub fn modulus(&self) -> CoveringModulus {
        self.modulus
    }

    /// What the last [`press`](Self::press) applied: per pressed body, the force on it and its
    /// moment about the pad's origin (world frame); the pad felt the opposite.
    pub fn last_press(&self) -> &[BodyPress] {
        &self.last_press
    }

    pub fn config(&self) -> &SensorConfig {
        &self.config
    }

    pub fn stats(&self) -> CoveringStats {
        self.stats
    }

    /// Writes the images of all the instance's sensors into `sensordata` at their addresses;
    /// `reading` numbers the reading for the noise streams.
    pub fn compute(&mut self, poses: &PoseView, reading: u64, sensordata: &mut [f64]) {
        self.stats.last_faces = 0;
        self.stats.last_full_samples = 0;
        self.stats.last_back_touched = false;
        for k in 0..self.sensors.len() {
            self.stats.last_full_samples += self.penetration(k, poses);
            let sensor = &self.sensors[k];
            let n = self.config.taxel_count();
            let out = &mut sensordata[sensor.adr..sensor.adr + n];
            self.formation
                .form(&self.depth.nearest_m, sensor.noise_seed, reading, out);
        }
        self.stats.readings += 1;
    }

    /// Fills `nearest_m` with the per-sample penetration (metres) seen by sensor `k`; returns how
    /// many samples are fully penetrated.
    fn penetration(&mut self, k: usize, poses: &PoseView) -> usize {
        self.depths(k, poses, false);
        penetration_from_depths(&mut self.depth.nearest_m, self.grid.cols, self.config.thickness_m)
    }

    /// Fills `nearest_m` with the pad-frame depth of the nearest sensed surface per sample, in the
    /// grid's own order (not yet mirrored, see the module docs), as sensor `k` sees it; with
    /// `track_owner`, `owner` says per sample which sensed geom is the nearest.
    fn depths(&mut self, k: usize, poses: &PoseView, track_owner: bool) {
        let sensor = &self.sensors[k];
        let t = self.config.thickness_m;
        let (pad_origin, pad_rotation) = site_frame(poses, sensor.site);
        let to_pad = pad_rotation.transpose();
        let (hw, hh) = (self.grid.half_width_m, self.grid.half_height_m);
        self.depth.nearest_m.fill(f64::INFINITY);
        if track_owner {
            self.owner.clear();
            self.owner.resize(self.grid.len(), usize::MAX);
        }
        for (index, g) in sensor.sensed.iter().enumerate() {
            let geom_origin = DVec3::from_slice(&poses.geom_xpos[3 * g.geom..3 * g.geom + 3]);
            let geom_rotation = rotation_from_xmat(&poses.geom_xmat[9 * g.geom..9 * g.geom + 9]);
            // Geom frame -> pad frame: p_pad = m p_geom + o.
            let m = to_pad * geom_rotation;
            let o = to_pad * (geom_origin - pad_origin);
            let r = g.rbound_m;
            if r > 0.0 && (o.z - r > t || o.z + r < 0.0 || o.x.abs() - r > hw || o.y.abs() - r > hh) {
                continue;
            }
            if track_owner {
                self.before_m.clone_from(&self.depth.nearest_m);
            }
            match g.shape {
                Shape::Mesh(slot) => {
                    let region = query_region(&self.grid, (&m, o), r, t);
                    let mesh = &self.meshes[slot];
                    self.leaves.clear();
                    mesh.leaves_near(&region, &mut self.stack, &mut self.leaves);
                    self.stats.last_faces += self.leaves.iter().map(Leaf::face_count).sum::<usize>();
                    self.depth.draw_mesh(&self.grid, mesh, &self.leaves, (&m, o), t);
                    if !self.stats.last_back_touched {
                        let scratch = (&mut self.stack, &mut self.leaves);
                        self.stats.last_back_touched =
                            rigid_back_touched(&self.grid, mesh, (&m, o), r, scratch);
                    }
                }
                Shape::Solid(solid) => {
                    draw_solid(&self.grid, &mut self.depth.nearest_m, solid, (&m, o), r);
                }
            }
            if track_owner {
                let nearer = self.depth.nearest_m.iter().zip(&self.before_m);
                for (owner, _) in self
                    .owner
                    .iter_mut()
                    .zip(nearer)
                    .filter(|(_, (now, was))| now < was)
                {
                    *owner = index;
                }
            }
        }
    }

    /// The covering's push on every body it touches, from the poses in `poses` and the velocity
    /// `velocity(body, point)` of a body's point (world frame), per sensor: each sample's column
    /// pressed by the nearest sensed surface ([`column_pressure_pa`]), acting at that surface
    /// along the pad normal. Fills [`last_press`](Self::last_press) (empty when the modulus is
    /// zero) and returns each press with the body carrying its pad, which feels it reversed.
    pub fn press(
        &mut self,
        poses: &PoseView,
        velocity: &dyn Fn(usize, DVec3) -> DVec3,
    ) -> Vec<(usize, BodyPress)> {
        self.last_press.clear();
        let mut applied = Vec::new();
        if self.modulus.is_none() {
            return applied;
        }
        for k in 0..self.sensors.len() {
            self.depths(k, poses, true);
            let pad_body = self.sensors[k].pad_body;
            for press in self.columns_pushing(k, poses, velocity) {
                applied.push((pad_body, press));
                self.last_press.push(press);
            }
        }
        applied
    }

    /// Sensor `k`'s columns summed per pressed body, after [`depths`](Self::depths) tracked
    /// which geom each sample meets.
    fn columns_pushing(
        &self,
        k: usize,
        poses: &PoseView,
        velocity: &dyn Fn(usize, DVec3) -> DVec3,
    ) -> Vec<BodyPress> {
        let sensor = &self.sensors[k];
        let t = self.config.thickness_m;
        let (pad_origin, pad_rotation) = site_frame(poses, sensor.site);
        let normal = pad_rotation.z_axis;
        let area_m2 = self.grid.dx_m() * self.grid.dy_m();
        let pad_body = sensor.pad_body;
        let mut presses: Vec<BodyPress> = Vec::new();
        for i in 0..self.grid.rows {
            for j in 0..self.grid.cols {
                let s = i * self.grid.cols + j;
                let penetration_m = (t - self.depth.nearest_m[s]).clamp(0.0, t);
                let Some(g) = sensor.sensed.get(self.owner[s]).filter(|_| penetration_m > 0.0) else {
                    continue;
                };
                let point =
                    pad_origin + pad_rotation * DVec3::new(self.grid.x(j), self.grid.y(i), t - penetration_m);
                let approach = (velocity(pad_body, point) - velocity(g.body, point)).dot(normal);
                let pressure = column_pressure_pa(self.modulus, t, penetration_m, approach);
                let force = normal * (pressure * area_m2);
                let at = match presses.iter().position(|p| p.body == g.body) {
                    Some(at) => at,
                    None => {
                        presses.push(BodyPress::none(g.body, pad_origin));
                        presses.len() - 1
                    }
                };
                presses[at].add(force, point);
            }
        }
        presses
    }
}

/// The origin and rotation of site `site` in the world.
fn site_frame(poses: &PoseView, site: usize) -> (DVec3, DMat3) {
    (
        DVec3::from_slice(&poses.site_xpos[3 * site..3 * site + 3]),
        rotation_from_xmat(&poses.site_xmat[9 * site..9 * site + 9]),
    )
}

/// Lowers `nearest_m` (pad-frame depths, sample order) to the depth of `solid` placed by
/// `x -> placement.0 x + placement.1` where its ray meets it nearer; within `rbound_m` of its
/// origin only (0: unbounded, every ray). A pad point inside the solid is at depth `-inf`.
fn draw_solid(grid: &SampleGrid, nearest_m: &mut [f64], solid: Solid, (m, o): (&DMat3, DVec3), r: f64) {
    let to_geom = m.transpose();
    let (right, up, dir) = (to_geom.x_axis, to_geom.y_axis, to_geom.z_axis);
    let base = -(to_geom * o);
    let (rows, cols) = if r > 0.0 {
        (grid.row_range(o.y - r, o.y + r), grid.col_range(o.x - r, o.x + r))
    } else {
        (0..grid.rows, 0..grid.cols)
    };
    for i in rows {
        let row_origin = base + up * grid.y(i);
        for j in cols.clone() {
            let origin = row_origin + right * grid.x(j);
            if let Some((s_in, s_out)) = solid.line_interval(origin, dir)
                && s_out >= 0.0
            {
                let z = if s_in <= 0.0 { f64::NEG_INFINITY } else { s_in };
                let s = i * grid.cols + j;
                if z < nearest_m[s] {
                    nearest_m[s] = z;
                }
            }
        }
    }
}

/// Turns the per-sample depths into penetrations `clamp(t - z, 0, t)` in the image's column order
/// (mirrored left-right, see the module docs); returns how many samples are fully penetrated.
fn penetration_from_depths(nearest_m: &mut [f64], cols: usize, t: f64) -> usize {
    let mut full = 0;
    for row in nearest_m.chunks_exact_mut(cols) {
        row.reverse();
        for z in row {
            *z = (t - *z).clamp(0.0, t);
            full += usize::from(*z >= t);
        }
    }
    full
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::tactile::mesh_bvh::{bumpy_ball, random_rotation};

    /// A random placement of a ball of bound `rbound_m` at the pad: any rotation, its bounding
    /// sphere from 4 mm through the pad plane to 1 mm in front of it, the ball's rim often across
    /// the pad's border.
    fn random_press(rng: &mut crate::rng::Rng, rbound_m: f64) -> (DMat3, DVec3) {
        use rand::RngExt;
        let rotation = random_rotation(rng);
        let offset = DVec3::new(
            rng.random_range(-0.012..0.012),
            rng.random_range(-0.012..0.012),
            rbound_m + rng.random_range(-0.004..0.001),
        );
        (rotation, offset)
    }

    #[test]
    fn a_tree_built_in_halves_holds_every_face_once_and_draws_what_the_whole_tree_draws() {
        use crate::tactile::mesh_bvh::bumpy_ball_mesh;
        let (xyz, faces) = bumpy_ball_mesh(0.008);
        let checked = CheckedMesh::new(&xyz, &faces).unwrap();
        let whole = MeshBvh::build_split_above(checked.clone(), usize::MAX);
        let halves = MeshBvh::build_split_above(checked, 0);
        // The shape: one root over two subtrees; each node's box holds its children's; each face
        // in exactly one leaf.
        let nodes = halves.nodes();
        assert_eq!((nodes[0].prim_count, nodes[0].first_index), (0, 1));
        let mut seen = vec![0; halves.triangle_count()];
        let (mut stack, mut every) = (vec![0usize], Vec::new());
        while let Some(i) = stack.pop() {
            let node = &nodes[i];
            if node.prim_count > 0 {
                continue;
            }
            for child in [node.first_index as usize, node.first_index as usize + 1] {
                let (outer, inner) = (node.aabb, nodes[child].aabb);
                assert!(outer.min.cmple(inner.min).all() && outer.max.cmpge(inner.max).all());
                stack.push(child);
            }
        }
        halves.leaves_near(&OrientedBox::cube(1.0), &mut stack, &mut every);
        for leaf in &every {
            for (face, _) in halves.leaf_faces(*leaf) {
                seen[face as usize] += 1;
            }
        }
        assert!(seen.iter().all(|&n| n == 1), "every face once");
        // The readings: the leaves over the rays of either tree give the same depths, bit for bit.
        let g = SampleGrid::new(&SensorConfig::default());
        let t = SensorConfig::default().thickness_m;
        let rbound_m = whole.bounding_radius_m();
        let depths = |mesh: &MeshBvh, placement: (&DMat3, DVec3), stack: &mut Vec<usize>| {
            let mut leaves = Vec::new();
            mesh.leaves_near(&query_region(&g, placement, rbound_m, t), stack, &mut leaves);
            let mut depth = DepthBuffer::new(&g);
            depth.draw_mesh(&g, mesh, &leaves, placement, t);
            depth.nearest_m
        };
        let mut rng = crate::rng::rng(29);
        let mut read = 0;
        for _ in 0..200 {
            let (rotation, offset) = random_press(&mut rng, rbound_m);
            let a = depths(&whole, (&rotation, offset), &mut stack);
            let b = depths(&halves, (&rotation, offset), &mut stack);
            for (s, (a, b)) in a.iter().zip(&b).enumerate() {
                assert_eq!(a.to_bits(), b.to_bits(), "sample {s}: {a} vs {b}");
            }
            read += usize::from(a.iter().any(|z| z.is_finite()));
        }
        assert!(read > 100, "{read} of 200 poses reach the covering");
    }

    #[test]
    fn the_query_regions_keep_every_face_that_changes_a_reading() {
        // Whether the ball lies wholly in front of the pad, touches the covering, or is pushed
        // through the pad plane: the leaves over the sample rays give the same depths, bit for bit,
        // as every leaf of the mesh, and the rigid-back query finds a face in the back exactly when
        // one of all the mesh's faces is there.
        let g = SampleGrid::new(&SensorConfig::default());
        let t = SensorConfig::default().thickness_m;
        let mesh = bumpy_ball(0.008);
        // The bound the covering uses for a mesh.
        let rbound_m = mesh.bounding_radius_m();
        let (mut every, mut stack, mut scratch) = (Vec::new(), Vec::new(), Vec::new());
        mesh.leaves_near(&OrientedBox::cube(1.0), &mut stack, &mut every);
        let (back_centre, back_half) = rigid_back(&g);
        let depths = |leaves: &[Leaf], placement: (&DMat3, DVec3)| {
            let mut depth = DepthBuffer::new(&g);
            depth.draw_mesh(&g, &mesh, leaves, placement, t);
            depth.nearest_m
        };
        let mut rng = crate::rng::rng(23);
        let (mut fewer, mut read, mut inside, mut backs) = (0, 0, 0, 0);
        for _ in 0..300 {
            let (rotation, offset) = random_press(&mut rng, rbound_m);
            let placement = (&rotation, offset);
            let mut near = Vec::new();
            mesh.leaves_near(&query_region(&g, placement, rbound_m, t), &mut stack, &mut near);
            let (all, over_rays) = (depths(&every, placement), depths(&near, placement));
            for (s, (a, b)) in all.iter().zip(&over_rays).enumerate() {
                assert_eq!(a.to_bits(), b.to_bits(), "sample {s}: {a} vs {b}");
            }
            let in_back = (0..mesh.triangle_count() as u32).any(|f| {
                let corners = mesh.corners(f, &rotation, offset);
                corners.iter().any(|p| p.z <= 0.0) && triangle_overlaps_box(corners, back_centre, back_half)
            });
            let found = rigid_back_touched(&g, &mesh, placement, rbound_m, (&mut stack, &mut scratch));
            assert_eq!(found, in_back, "offset {offset}");
            let faces = |leaves: &[Leaf]| leaves.iter().map(Leaf::face_count).sum::<usize>();
            fewer += usize::from(faces(&near) < faces(&every));
            read += usize::from(all.iter().any(|z| z.is_finite()));
            inside += usize::from(all.contains(&f64::NEG_INFINITY));
            backs += usize::from(in_back);
        }
        // Not vacuous: fewer faces drawn, surfaces read in the covering, samples inside the
        // ball, and faces in the rigid back (and poses without).
        assert!(
            fewer > 250 && read > 50 && inside > 20 && backs > 20 && backs < 280,
            "{fewer} with fewer faces, {read} read, {inside} inside, {backs} in the back"
        );
    }
}
