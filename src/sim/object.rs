//! The object under exploration as MJCF: a mesh asset and a body in the object slot.
//!
//! The body is named `object`, its geom `object`, as in `mjcf/example_object.xml`. The body frame is
//! the mesh's own frame (vertices are written as given, metres), so the object's pose in MuJoCo is
//! the pose that maps mesh coordinates to the world, and perturbations (Sec. V-B4) act on it.

use std::borrow::Cow;

use crate::mesh::{BuildOptions, MeshError, Object, ObjectSet, SolidMoments, TriMesh, cluster_vertices};
use crate::pose::Pose;
use crate::sim::SimError;
use crate::sim::collision_shell::{ShellOptions, collision_shell};
use crate::sim::mjcf::{COLLISION_GROUP, Document, Section, comment, escape_attr, numbers, space_separated};

use crate::bodies::{FreeBody, OBJECT_BODY};

/// Geom and joint names of the object slot (its body: [`OBJECT_BODY`]).
pub const OBJECT_GEOM: &str = "object";
pub const OBJECT_JOINT: &str = "object_free";
/// The name of the mesh asset of the object's exact surface.
pub const OBJECT_MESH: &str = "object";

/// How the object is held in the world.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum ObjectMount {
    /// A mocap body: it stays exactly where it is put (contacts do not move it); perturbations
    /// teleport it. The default for exploration, since the paper's object is "relatively stable while
    /// taking a sensor measurement" (Sec. I).
    #[default]
    Mocap,
    /// A free joint: gravity, contacts and the covering's push (`tactile::press_back`) act on
    /// it; it rests on the table. Its mass and inertia are its mesh's as a uniform solid of the
    /// [`FreeBody`]'s density.
    Free,
}

/// The torsional friction of a free object's contacts, metres (MuJoCo's `condim="6"` second
/// coefficient: the torque resisting a spin about the contact normal per newton of normal force,
/// about the radius of a contact patch): set so that a press off the object's centre does not spin
/// it in place, which MuJoCo's default `condim="3"` would let it do freely about a single contact.
pub const TORSIONAL_FRICTION_M: f64 = 0.01;
/// The rolling friction of a free object's contacts, metres (`condim="6"`'s third coefficient):
/// a hard object on a wooden table, 1 mm, so a sphere pressed from the side rolls, as one does.
pub const ROLLING_FRICTION_M: f64 = 0.001;

/// Meshes of more triangles than this reach MuJoCo as a coarse copy of at most
/// [`DRAWN_MESH_TRIANGLES`] (`mesh::cluster_vertices`), with the exact surface beside it for the
/// sensor (see [`ObjectSurfaces`]). Every built-in object is below it (the bunny, the largest, has
/// about 70,000).
pub const LARGE_MESH_TRIANGLES: usize = 100_000;
/// The most triangles of the copy MuJoCo compiles and draws of a large mesh.
pub const DRAWN_MESH_TRIANGLES: usize = 20_000;

/// The object's surface as a scene holds it.
///
/// MuJoCo compiles every mesh asset in full (normals, inertia, a BVH of every face), although the
/// object's geom takes part in no contact (its collision shell does) and the sensor reads its own
/// BVH: for a 1.3M-triangle scan that was a 256 MB model, 1.2 GB at the peak of the compile, and
/// most of the time to its first reading (issue 39). A large mesh's asset is therefore a coarse
/// copy, and the model carries the exact surface as two `<numeric>` fields, plain numbers MuJoCo
/// copies without processing, from which the sensor builds its BVH
/// ([`sensed_surface_names`](crate::sim::sensed_surface_names)); the model stays the one source of
/// what the sensor reads.
#[derive(Debug, Clone)]
pub struct ObjectSurfaces<'a> {
    /// The mesh asset MuJoCo compiles: the mesh itself, or a coarse copy of a large one.
    pub drawn: Cow<'a, TriMesh>,
    /// The exact surface, when `drawn` is a copy.
    pub sensed: Option<&'a TriMesh>,
}

/// Where the `<mesh>` asset of the object gets its vertices and faces.
#[derive(Debug, Clone, Copy)]
pub enum MeshAsset<'a> {
    /// The whole mesh as inline attributes: the text compiles alone. A large mesh too: MJCF text
    /// cannot carry its exact surface beside a copy (MuJoCo 3.17 refuses a `<numeric>` of more
    /// than a few hundred values, and crashes on one whose `size` is larger).
    Inline,
    /// The whole mesh in a file, relative to the MJCF file, which the caller writes beside it: a
    /// scene exported for MuJoCo's own tools.
    File(&'a str),
    /// None in the text: the compiler of the scene sets them on the parsed specification, with a
    /// large mesh's exact surface beside its copy ([`ObjectSurfaces`];
    /// [`SceneBuilder::build`](crate::sim::SceneBuilder::build)), sparing a scanned mesh's
    /// millions of numbers their printing and MuJoCo's parsing.
    Spec(&'a ObjectSurfaces<'a>),
}

/// An object to place in the scene.
#[derive(Debug, Clone)]
pub struct ObjectSpec {
    /// Display name (for messages); the MJCF names are fixed.
    pub name: String,
    /// The shape in its own frame, metres.
    pub mesh: TriMesh,
    /// Initial pose of the mesh frame in the world.
    pub pose: Pose,
    pub mount: ObjectMount,
    /// The mass the mocap mount writes (a mocap body's mass moves nothing), kilograms.
    pub mass_kg: f64,
    /// What the object is made of, where it is free ([`ObjectMount::Free`]).
    pub free_body: FreeBody,
    /// Triangles above which MuJoCo is given a coarse copy of the mesh and the sensor the exact
    /// surface beside it ([`ObjectSurfaces`]; [`LARGE_MESH_TRIANGLES`] by default); `usize::MAX`
    /// gives MuJoCo the whole mesh whatever its size.
    pub large_mesh_triangles: usize,
}

/// A checked object, resting at the origin as it was built.
impl From<Object> for ObjectSpec {
    fn from(object: Object) -> Self {
        Self::new(object.name, object.mesh)
    }
}

impl ObjectSpec {
    /// An object resting at the origin as given (its coordinates are already world metres).
    pub fn new(name: impl Into<String>, mesh: TriMesh) -> Self {
        Self {
            name: name.into(),
            mesh,
            pose: Pose::IDENTITY,
            mount: ObjectMount::Mocap,
            mass_kg: 0.2,
            free_body: FreeBody::DEFAULT,
            large_mesh_triangles: LARGE_MESH_TRIANGLES,
        }
    }

    /// Every object of `set`, built (missing CGAL meshes fetched) and resting at the origin as the
    /// set places it, in set order: the objects a collection run puts in its scenes.
    pub fn all_of(set: &ObjectSet) -> Result<Vec<Self>, MeshError> {
        let built = set.build(&BuildOptions {
            fetch: true,
            ..BuildOptions::default()
        })?;
        Ok(built.into_iter().map(Self::from).collect())
    }

    /// This object held free and made of `body`, or, `None`, as it is.
    pub fn mounted(&self, body: Option<FreeBody>) -> ObjectSpec {
        match body {
            None => self.clone(),
            Some(free_body) => ObjectSpec {
                mount: ObjectMount::Free,
                free_body,
                ..self.clone()
            },
        }
    }

    /// The mass a free mount gives it: its mesh as a uniform solid of the [`FreeBody`]'s density;
    /// `None` when the mesh encloses no volume.
    pub fn solid_mass_kg(&self) -> Option<f64> {
        SolidMoments::of(&self.mesh).map(|m| m.volume_m3 * self.free_body.density_kg_m3())
    }

    /// How a scene holds this object's surface: as it is, or, for a mesh of more than
    /// [`large_mesh_triangles`](Self::large_mesh_triangles), a coarse copy for MuJoCo and the exact
    /// surface beside it.
    pub fn surfaces(&self) -> ObjectSurfaces<'_> {
        if self.mesh.triangles.len() > self.large_mesh_triangles {
            ObjectSurfaces {
                drawn: Cow::Owned(cluster_vertices(&self.mesh, DRAWN_MESH_TRIANGLES)),
                sensed: Some(&self.mesh),
            }
        } else {
            ObjectSurfaces {
                drawn: Cow::Borrowed(&self.mesh),
                sensed: None,
            }
        }
    }

    /// Adds the mesh asset (its vertices and faces from `asset`) and the object body to `doc`, with
    /// the collision shell (`collision_shell.rs`) when `with_shell` says so.
    ///
    /// The shell collides with the arm and the table (the tactile sensor raycasts the exact
    /// triangles of the object's own geom, which takes part in no contact). The body gets an
    /// explicit inertia (a solid sphere of the mesh's bounding radius), so that open or thin user
    /// meshes, whose volume MuJoCo cannot compute, still load, and so that the body's frames do not
    /// depend on whether it has a shell.
    pub fn add_to(&self, doc: &mut Document, asset: MeshAsset, with_shell: bool) -> Result<(), SimError> {
        let (lo, hi) = self.mesh.bounds().ok_or_else(|| SimError::Object {
            name: self.name.clone(),
            message: "the mesh has no vertices".into(),
        })?;
        if self.mesh.triangles.is_empty() {
            return Err(SimError::Object {
                name: self.name.clone(),
                message: "the mesh has no triangles".into(),
            });
        }
        doc.add(Section::Asset, mesh_asset(asset, &self.mesh));
        // A large mesh's shell is made from the copy MuJoCo draws: its cells (about 1.4 mm for a
        // 1.3M-triangle sphere 8 cm across) are finer than the shell's own 2 mm tolerance, and the
        // pieces of the whole scan were thinned to 1 mm cells anyway.
        let shell_of = match asset {
            MeshAsset::Spec(surfaces) => surfaces.drawn.as_ref(),
            MeshAsset::Inline | MeshAsset::File(_) => &self.mesh,
        };
        let shell = match with_shell {
            true => add_collision_shell(doc, shell_of, self.shell_contacts()),
            false => String::new(),
        };
        let pos = numbers(self.pose.position_m.to_array());
        let quat = numbers(self.pose.mujoco_quat());
        let (mount_attr, joint, inertial) = match self.mount {
            ObjectMount::Mocap => (" mocap=\"true\"", String::new(), self.sphere_inertial(lo, hi)),
            ObjectMount::Free => (
                "",
                format!("<freejoint name=\"{OBJECT_JOINT}\"/>"),
                self.solid_inertial()?,
            ),
        };
        doc.add(
            Section::Worldbody,
            format!(
                "<body name=\"{OBJECT_BODY}\" pos=\"{pos}\" quat=\"{quat}\"{mount_attr}>\n\
                 {}\n{joint}\n{inertial}\n\
                 <geom name=\"{OBJECT_GEOM}\" type=\"mesh\" mesh=\"{OBJECT_MESH}\" rgba=\"0.8 0.5 0.3 1\" contype=\"0\" conaffinity=\"0\"/>\n\
                 {shell}</body>",
                comment(&self.name),
            ),
        );
        Ok(())
    }

    /// The mocap body's `<inertial>`: a solid sphere of the mesh's bounding radius and
    /// [`mass_kg`](Self::mass_kg), so that open or thin user meshes, whose volume MuJoCo cannot
    /// compute, still load, and so that the body's frames do not depend on whether it has a shell.
    fn sphere_inertial(&self, lo: glam::DVec3, hi: glam::DVec3) -> String {
        let center = (lo + hi) * 0.5;
        let radius = ((hi - lo).length() * 0.5).max(1e-3);
        let inertia = 0.4 * self.mass_kg * radius * radius;
        format!(
            "<inertial pos=\"{}\" mass=\"{}\" diaginertia=\"{inertia} {inertia} {inertia}\"/>",
            numbers(center.to_array()),
            self.mass_kg
        )
    }

    /// The free body's `<inertial>`: the mesh as a uniform solid of the [`FreeBody`]'s density.
    /// A mesh that encloses no volume cannot be a free body: a named error.
    fn solid_inertial(&self) -> Result<String, SimError> {
        let moments = SolidMoments::of(&self.mesh).ok_or_else(|| SimError::Object {
            name: self.name.clone(),
            message: "a free object must be a closed solid, and this mesh encloses no volume".into(),
        })?;
        let density = self.free_body.density_kg_m3();
        let i = moments.inertia_kg_m2(density);
        Ok(format!(
            "<inertial pos=\"{}\" mass=\"{}\" fullinertia=\"{}\"/>",
            numbers(moments.centroid_m.to_array()),
            density * moments.volume_m3,
            numbers([
                i.x_axis.x, i.y_axis.y, i.z_axis.z, i.y_axis.x, i.z_axis.x, i.z_axis.y
            ])
        ))
    }

    /// The contact attributes of the collision shell's pieces: the mocap object's plain friction,
    /// or the free body's friction, torsional and rolling resistance, ruling its contacts
    /// (`priority`: MuJoCo otherwise takes the larger of two geoms' frictions, and a slippery
    /// object on the table would get the table's).
    fn shell_contacts(&self) -> String {
        match self.mount {
            ObjectMount::Mocap => "friction=\"0.6\"".into(),
            // Frictionless contacts are normal forces alone: MuJoCo's cone of a zero sliding
            // friction with torsional and rolling terms beside it is degenerate, and blows up.
            ObjectMount::Free if self.free_body.friction() == 0.0 => {
                "friction=\"0 0 0\" condim=\"1\" priority=\"1\"".into()
            }
            ObjectMount::Free => format!(
                "friction=\"{} {TORSIONAL_FRICTION_M} {ROLLING_FRICTION_M}\" condim=\"6\" priority=\"1\"",
                self.free_body.friction()
            ),
        }
    }
}

/// Adds the convex pieces of the collision shell as assets and returns their geoms for the
/// object's body: contacts go through the shell (see `collision_shell`), the sensor reads the
/// exact mesh.
fn add_collision_shell(doc: &mut Document, mesh: &TriMesh, contacts: String) -> String {
    let mut shell = String::new();
    for (i, piece) in collision_shell(mesh, &ShellOptions::default()).iter().enumerate() {
        let vertex = numbers(piece.iter().flat_map(|v| v.to_array()));
        doc.add(
            Section::Asset,
            format!("<mesh name=\"{OBJECT_GEOM}_shell_{i}\" inertia=\"shell\" vertex=\"{vertex}\"/>"),
        );
        shell.push_str(&format!(
            "<geom name=\"{OBJECT_GEOM}_shell_{i}\" type=\"mesh\" mesh=\"{OBJECT_GEOM}_shell_{i}\" \
             group=\"{COLLISION_GROUP}\" contype=\"2\" conaffinity=\"2\" rgba=\"0.8 0.5 0.3 0.3\" {contacts}/>\n"
        ));
    }
    shell
}

/// The object's `<mesh>` asset (`mesh` the whole mesh).
fn mesh_asset(asset: MeshAsset, mesh: &TriMesh) -> String {
    match asset {
        MeshAsset::File(file) => format!(
            "<mesh name=\"{OBJECT_MESH}\" inertia=\"shell\" file=\"{}\"/>",
            escape_attr(file)
        ),
        MeshAsset::Spec(_) => format!("<mesh name=\"{OBJECT_MESH}\" inertia=\"shell\"/>"),
        MeshAsset::Inline => {
            let vertex = numbers(mesh.vertices.iter().flat_map(|v| v.to_array()));
            let face = indices(mesh.triangles.iter().flatten());
            format!("<mesh name=\"{OBJECT_MESH}\" inertia=\"shell\" vertex=\"{vertex}\" face=\"{face}\"/>")
        }
    }
}

/// Space-separated vertex indices.
fn indices<'a>(values: impl Iterator<Item = &'a u32>) -> String {
    use std::fmt::Write;
    space_separated(values, |text, i| {
        let _ = write!(text, "{i}");
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn face_indices_are_the_space_separated_decimal_indices() {
        let triangles = [[0u32, 1, 2], [3, 40, 5_000_000]];
        assert_eq!(indices(triangles.iter().flatten()), "0 1 2 3 40 5000000");
        assert_eq!(indices([].iter()), "");
    }
}
