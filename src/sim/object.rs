//! The object under exploration as MJCF: a mesh asset and a body in the object slot.
//!
//! The body is named `object`, its geom `object`, as in `mjcf/example_object.xml`. The body frame is
//! the mesh's own frame (vertices are written as given, metres), so the object's pose in MuJoCo is
//! the pose that maps mesh coordinates to the world, and perturbations (Sec. V-B4) act on it.

use crate::mesh::{BuildOptions, MeshError, Object, ObjectSet, TriMesh};
use crate::pose::Pose;
use crate::sim::SimError;
use crate::sim::collision_shell::{ShellOptions, collision_shell};
use crate::sim::mjcf::{COLLISION_GROUP, Document, Section, comment, escape_attr, numbers, space_separated};

use crate::bodies::OBJECT_BODY;

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
    /// A free joint: gravity and contacts act on it; it rests on the table.
    Free,
}

/// Where the `<mesh>` asset of the object's exact surface (the one the sensor reads) gets its
/// vertices and faces.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum MeshData<'a> {
    /// Inline `vertex` and `face` attributes: the text compiles alone.
    Inline,
    /// A file, relative to the MJCF file, which the caller writes beside it: a scene exported for
    /// MuJoCo's own tools.
    File(&'a str),
    /// None in the text: the compiler of the scene sets them on the parsed specification
    /// ([`SceneBuilder::build`](crate::sim::SceneBuilder::build)), sparing a scanned mesh's
    /// millions of numbers their printing and MuJoCo's parsing (issue 39, large meshes).
    Spec,
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
    /// Mass of the object (free mount only), kilograms.
    pub mass_kg: f64,
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

    /// Adds the mesh asset (its vertices and faces from `mesh_data`) and the object body to `doc`.
    ///
    /// The geom collides with the arm and the table (MuJoCo uses the mesh's convex hull for these
    /// contacts; the tactile sensor raycasts the exact triangles). The body gets an explicit inertia (a
    /// solid sphere of the mesh's bounding radius), so that open or thin user meshes, whose volume
    /// MuJoCo cannot compute, still load.
    pub fn add_to(&self, doc: &mut Document, mesh_data: MeshData) -> Result<(), SimError> {
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
        doc.add(Section::Asset, self.mesh_asset(mesh_data));
        let shell = self.add_collision_shell(doc);

        let center = (lo + hi) * 0.5;
        let radius = ((hi - lo).length() * 0.5).max(1e-3);
        let inertia = 0.4 * self.mass_kg * radius * radius;
        let pos = numbers(self.pose.position_m.to_array());
        let quat = numbers(self.pose.mujoco_quat());
        let (mount_attr, joint) = match self.mount {
            ObjectMount::Mocap => (" mocap=\"true\"", String::new()),
            ObjectMount::Free => ("", format!("<freejoint name=\"{OBJECT_JOINT}\"/>")),
        };
        doc.add(
            Section::Worldbody,
            format!(
                "<body name=\"{OBJECT_BODY}\" pos=\"{pos}\" quat=\"{quat}\"{mount_attr}>\n\
                 {}\n{joint}\n\
                 <inertial pos=\"{}\" mass=\"{}\" diaginertia=\"{inertia} {inertia} {inertia}\"/>\n\
                 <geom name=\"{OBJECT_GEOM}\" type=\"mesh\" mesh=\"{OBJECT_MESH}\" rgba=\"0.8 0.5 0.3 1\" contype=\"0\" conaffinity=\"0\"/>\n\
                 {shell}</body>",
                comment(&self.name),
                numbers(center.to_array()),
                self.mass_kg
            ),
        );
        Ok(())
    }

    /// The `<mesh>` asset of the exact surface the sensor reads.
    fn mesh_asset(&self, mesh_data: MeshData) -> String {
        match mesh_data {
            MeshData::File(file) => format!(
                "<mesh name=\"{OBJECT_MESH}\" inertia=\"shell\" file=\"{}\"/>",
                escape_attr(file)
            ),
            MeshData::Spec => format!("<mesh name=\"{OBJECT_MESH}\" inertia=\"shell\"/>"),
            MeshData::Inline => {
                let vertex = numbers(self.mesh.vertices.iter().flat_map(|v| v.to_array()));
                let face = indices(self.mesh.triangles.iter().flatten());
                format!(
                    "<mesh name=\"{OBJECT_MESH}\" inertia=\"shell\" vertex=\"{vertex}\" face=\"{face}\"/>"
                )
            }
        }
    }

    /// Adds the convex pieces of the collision shell as assets and returns their geoms for the
    /// object's body: contacts go through the shell (see `collision_shell`), the sensor reads the
    /// exact mesh.
    fn add_collision_shell(&self, doc: &mut Document) -> String {
        let mut shell = String::new();
        for (i, piece) in collision_shell(&self.mesh, &ShellOptions::default())
            .iter()
            .enumerate()
        {
            let vertex = numbers(piece.iter().flat_map(|v| v.to_array()));
            doc.add(
                Section::Asset,
                format!("<mesh name=\"{OBJECT_GEOM}_shell_{i}\" inertia=\"shell\" vertex=\"{vertex}\"/>"),
            );
            shell.push_str(&format!(
                "<geom name=\"{OBJECT_GEOM}_shell_{i}\" type=\"mesh\" mesh=\"{OBJECT_GEOM}_shell_{i}\" \
                 group=\"{COLLISION_GROUP}\" contype=\"2\" conaffinity=\"2\" rgba=\"0.8 0.5 0.3 0.3\" friction=\"0.6\"/>\n"
            ));
        }
        shell
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
