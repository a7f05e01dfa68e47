//! Fig. 1 as a picture: the explored object, a patch wherever the local controllers converged and a
//! reading was taken, and the first tactile images beside it, drawn by a small software rasteriser
//! (no GPU, no display), so that `demo` and `reproduce` can show where the arm touched.
//!
//! The view is an orthographic projection along a unit direction `v` (from the camera into the
//! scene) with the world's z up: a point `p` lands at screen `(p . r, p . u)` with depth `p . v`,
//! where `r = normalize(v x z)` and `u = r x v`. Triangles fill a z-buffer; each is shaded
//! Lambertian, `c (a + (1 - a) |n . l|)`, with `|.|` because mesh winding is not trusted. A patch is
//! the pad's square footprint placed on the covering's outer surface, `center + t n` (Sec. II: the
//! object surface lies between the pad and that plane at contact), drawn where it is not more than
//! a small bias behind the object's nearest surface, so patches on the far side stay hidden.

use std::path::Path;

use glam::DVec3;

use crate::dataset::Reading;
use crate::mesh::TriMesh;
use crate::pose::PadPose;
use crate::pose::Pose;
use crate::tactile::image::{CONTACT_SHEET_GUTTER_PX, GrayPicture, contact_sheet, write_rgb_png};
use crate::tactile::{ImageError, SensorConfig, TactileImage};

/// The paper's figure shows the first 50 tactile images of a 100-reading exploration.
pub const PAPER_IMAGES_SHOWN: usize = 50;

/// How the picture is laid out.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ExplorationView {
    /// Camera azimuth about z and elevation above the xy plane, radians.
    pub azimuth_rad: f64,
    pub elevation_rad: f64,
    /// Side of the square object panel, pixels.
    pub panel_px: usize,
    /// Tactile images shown beside the object (the first ones), and their columns.
    pub images_shown: usize,
    pub image_columns: usize,
}

impl Default for ExplorationView {
    fn default() -> Self {
        Self {
            azimuth_rad: 35f64.to_radians(),
            elevation_rad: 25f64.to_radians(),
            panel_px: 720,
            images_shown: PAPER_IMAGES_SHOWN,
            image_columns: 5,
        }
    }
}

/// One converged placement: the pad's pose in the object's frame and its tactile image.
#[derive(Debug, Clone)]
pub struct Placement {
    pub pad_in_object: PadPose,
    pub image: TactileImage,
}

impl Placement {
    /// The converged readings that carry a pad pose, each expressed in the object's frame at the
    /// time of its reading (the object may have been perturbed between readings, Sec. V-A2).
    pub fn from_readings<'a>(readings: impl IntoIterator<Item = &'a Reading>) -> Vec<Placement> {
        readings
            .into_iter()
            .filter(|r| r.is_converged())
            .filter_map(|r| {
                let pad = r.image.pose()?;
                let to_object = r.object_pose.inverse();
                let pad_in_object = PadPose::new(
                    to_object.transform_point(pad.center_m),
                    to_object.transform_vector(pad.normal),
                    to_object.transform_vector(pad.up),
                )?;
                Some(Placement {
                    pad_in_object,
                    image: r.image.clone(),
                })
            })
            .collect()
    }
}

/// An RGB picture, row-major, three bytes a pixel.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct RgbPicture {
    pub width: usize,
    pub height: usize,
    pub pixels: Vec<u8>,
}

impl RgbPicture {
    fn filled(width: usize, height: usize, color: [u8; 3]) -> Self {
        Self {
            width,
            height,
            pixels: color.repeat(width * height),
        }
    }

    pub fn get(&self, x: usize, y: usize) -> [u8; 3] {
        let i = 3 * (y * self.width + x);
        [self.pixels[i], self.pixels[i + 1], self.pixels[i + 2]]
    }

    fn set(&mut self, x: usize, y: usize, color: [u8; 3]) {
        let i = 3 * (y * self.width + x);
        self.pixels[i..i + 3].copy_from_slice(&color);
    }

    pub fn write_png(&self, path: &Path) -> Result<(), ImageError> {
        write_rgb_png(path, self.width, self.height, &self.pixels)
    }
}

const BACKGROUND: [u8; 3] = [255, 255, 255];
const OBJECT: [f64; 3] = [150.0, 165.0, 190.0];
/// The paper's patches are yellow.
const PATCH: [u8; 3] = [245, 200, 30];
const PATCH_EDGE: [u8; 3] = [150, 105, 0];
const AMBIENT: f64 = 0.3;

/// The orthographic camera of the module doc.
struct Camera {
    right: DVec3,
    up: DVec3,
    view: DVec3,
    /// Screen-space offset and pixels per metre that fit the scene into the panel.
    min: (f64, f64),
    px_per_m: f64,
    panel_px: usize,
}

impl Camera {
    fn new(view: &ExplorationView, points: &[DVec3]) -> Self {
        let (ce, se) = (view.elevation_rad.cos(), view.elevation_rad.sin());
        let (ca, sa) = (view.azimuth_rad.cos(), view.azimuth_rad.sin());
        let dir = -DVec3::new(ce * ca, ce * sa, se);
        let right = dir.cross(DVec3::Z).try_normalize().unwrap_or(DVec3::X);
        let up = right.cross(dir);
        let (mut lo, mut hi) = ((f64::MAX, f64::MAX), (f64::MIN, f64::MIN));
        for p in points {
            let (x, y) = (p.dot(right), p.dot(up));
            lo = (lo.0.min(x), lo.1.min(y));
            hi = (hi.0.max(x), hi.1.max(y));
        }
        let span = (hi.0 - lo.0).max(hi.1 - lo.1).max(1e-9);
        let margin = 0.06 * view.panel_px as f64;
        let px_per_m = (view.panel_px as f64 - 2.0 * margin) / span;
        // Centre the scene: the offset puts its bounding box in the middle of the panel.
        let centre = ((lo.0 + hi.0) / 2.0, (lo.1 + hi.1) / 2.0);
        let half = view.panel_px as f64 / 2.0 / px_per_m;
        Self {
            right,
            up,
            view: dir,
            min: (centre.0 - half, centre.1 - half),
            px_per_m,
            panel_px: view.panel_px,
        }
    }

    /// Pixel column, pixel row (down) and depth in metres (larger is farther).
    fn project(&self, p: DVec3) -> DVec3 {
        let x = (p.dot(self.right) - self.min.0) * self.px_per_m;
        let y = self.panel_px as f64 - (p.dot(self.up) - self.min.1) * self.px_per_m;
        DVec3::new(x, y, p.dot(self.view))
    }
}

/// Renders the object at `object_pose` with every placement's patch, and the `contact_sheet` of
/// the first `view.images_shown` tactile images to its right, scaled to the panel's height. Fails
/// only when the images differ in shape.
pub fn render_exploration(
    mesh: &TriMesh,
    object_pose: &Pose,
    placements: &[Placement],
    sensor: &SensorConfig,
    view: &ExplorationView,
) -> Result<RgbPicture, ImageError> {
    let vertices: Vec<DVec3> = mesh
        .vertices
        .iter()
        .map(|&v| object_pose.transform_point(v))
        .collect();
    let patches: Vec<[DVec3; 4]> = placements
        .iter()
        .map(|p| patch_corners(&p.pad_in_object, sensor, object_pose))
        .collect();
    let mut extent = vertices.clone();
    extent.extend(patches.iter().flatten());
    let camera = Camera::new(view, &extent);

    let shown: Vec<TactileImage> = placements
        .iter()
        .take(view.images_shown)
        .map(|p| p.image.clone())
        .collect();
    let sheet = images_beside(&shown, view)?;
    let (sheet_w, sheet_h) = sheet.as_ref().map_or((0, 0), |s| (s.width, s.height));
    let mut picture = RgbPicture::filled(view.panel_px + sheet_w, view.panel_px.max(sheet_h), BACKGROUND);
    let mut depth = vec![f64::INFINITY; view.panel_px * view.panel_px];

    draw_object(&mut picture, &mut depth, &camera, mesh, &vertices);
    draw_patches(&mut picture, &mut depth, &camera, &patches, sensor);
    if let Some(sheet) = sheet {
        for y in 0..sheet.height {
            for x in 0..sheet.width {
                let g = sheet.pixels[y * sheet.width + x];
                picture.set(view.panel_px + x, y, [g, g, g]);
            }
        }
    }
    Ok(picture)
}

/// The object's triangles (at `vertices`, in the world), shaded Lambertian from a light beside the
/// camera, into the z-buffer `depth`.
fn draw_object(
    picture: &mut RgbPicture,
    depth: &mut [f64],
    camera: &Camera,
    mesh: &TriMesh,
    vertices: &[DVec3],
) {
    let light = (-camera.view + 0.6 * camera.up - 0.4 * camera.right).normalize();
    for &[a, b, c] in &mesh.triangles {
        let [a, b, c] = [a, b, c].map(|i| vertices[i as usize]);
        let Some(normal) = (b - a).cross(c - a).try_normalize() else {
            continue;
        };
        let shade = AMBIENT + (1.0 - AMBIENT) * normal.dot(light).abs();
        let color = OBJECT.map(|c| (c * shade).round().clamp(0.0, 255.0) as u8);
        let screen = [a, b, c].map(|p| camera.project(p));
        fill_convex(picture, depth, camera, &screen, DepthTest::Opaque, |_| color);
    }
}

/// Each placement's patch, with an edge, where it is not hidden behind the object.
fn draw_patches(
    picture: &mut RgbPicture,
    depth: &mut [f64],
    camera: &Camera,
    patches: &[[DVec3; 4]],
    sensor: &SensorConfig,
) {
    // A patch shows if it is at most this far behind the nearest object surface: the covering's
    // thickness plus a millimetre for the object's curvature under the pad.
    let overlay = DepthTest::Overlay {
        bias_m: sensor.thickness_m + 1e-3,
    };
    for corners in patches {
        let screen = corners.map(|p| camera.project(p));
        let edge_px = 1.5;
        fill_convex(picture, depth, camera, &screen, overlay, |inset_px| {
            if inset_px < edge_px { PATCH_EDGE } else { PATCH }
        });
    }
}

/// The contact sheet of `images` in `view.image_columns` columns, its taxels as large as lets the
/// sheet be no taller than the object panel; `None` without images.
fn images_beside(images: &[TactileImage], view: &ExplorationView) -> Result<Option<GrayPicture>, ImageError> {
    let Some(first) = images.first() else {
        return Ok(None);
    };
    let columns = view.image_columns.clamp(1, images.len());
    let rows = images.len().div_ceil(columns);
    let free_px = view.panel_px.saturating_sub(CONTACT_SHEET_GUTTER_PX * (rows + 1));
    let taxel_px = (free_px / (rows * first.rows())).max(1);
    contact_sheet(images, columns, taxel_px).map(Some)
}

/// How a polygon meets the z-buffer.
#[derive(Debug, Clone, Copy)]
enum DepthTest {
    /// A surface of the object: drawn where nearest, and it becomes the nearest.
    Opaque,
    /// A mark on the surface (a patch): drawn where at most `bias_m` behind the nearest surface,
    /// leaving the z-buffer as it is.
    Overlay { bias_m: f64 },
}

/// The pad's footprint on the covering's outer surface, in the world at the displayed pose.
fn patch_corners(pad: &PadPose, sensor: &SensorConfig, object_pose: &Pose) -> [DVec3; 4] {
    let side = pad.right();
    let centre = pad.center_m + pad.normal * sensor.thickness_m;
    let (h, w) = (
        pad.up * sensor.pad_height_m / 2.0,
        side * sensor.pad_width_m / 2.0,
    );
    [centre + h + w, centre + h - w, centre - h - w, centre - h + w].map(|p| object_pose.transform_point(p))
}

/// Fills the convex polygon `screen` (pixel x, pixel y, depth m) where `test` passes;
/// `color` gets the pixel's distance in pixels to the polygon's nearest edge.
/// Depth is interpolated on the plane of the first three corners (the polygons are planar).
fn fill_convex(
    picture: &mut RgbPicture,
    depth: &mut [f64],
    camera: &Camera,
    screen: &[DVec3],
    test: DepthTest,
    color: impl Fn(f64) -> [u8; 3],
) {
    let n = screen.len();
    let (a, b, c) = (screen[0], screen[1], screen[2]);
    let area = (b.x - a.x) * (c.y - a.y) - (c.x - a.x) * (b.y - a.y);
    if area.abs() < 1e-12 {
        return;
    }
    // Orientation of the polygon on screen: edges are tested so that inside is positive.
    let sign = area.signum();
    let (mut x0, mut y0, mut x1, mut y1) = (f64::MAX, f64::MAX, f64::MIN, f64::MIN);
    for p in screen {
        (x0, y0, x1, y1) = (x0.min(p.x), y0.min(p.y), x1.max(p.x), y1.max(p.y));
    }
    let limit = camera.panel_px as f64 - 1.0;
    let (x0, x1) = (x0.floor().max(0.0), x1.ceil().min(limit));
    let (y0, y1) = (y0.floor().max(0.0), y1.ceil().min(limit));
    if x0 > x1 || y0 > y1 {
        return;
    }
    for y in y0 as usize..=y1 as usize {
        for x in x0 as usize..=x1 as usize {
            let (px, py) = (x as f64 + 0.5, y as f64 + 0.5);
            let mut inset = f64::MAX;
            for k in 0..n {
                let (p, q) = (screen[k], screen[(k + 1) % n]);
                let (ex, ey) = (q.x - p.x, q.y - p.y);
                let len = (ex * ex + ey * ey).sqrt().max(1e-12);
                inset = inset.min(sign * (ex * (py - p.y) - ey * (px - p.x)) / len);
            }
            if inset < 0.0 {
                continue;
            }
            // Barycentric weights of (px, py) in the triangle a, b, c give the plane's depth.
            let wb = ((px - a.x) * (c.y - a.y) - (c.x - a.x) * (py - a.y)) / area;
            let wc = ((b.x - a.x) * (py - a.y) - (px - a.x) * (b.y - a.y)) / area;
            let z = a.z + wb * (b.z - a.z) + wc * (c.z - a.z);
            let slot = &mut depth[y * camera.panel_px + x];
            match test {
                DepthTest::Opaque if z < *slot => *slot = z,
                DepthTest::Overlay { bias_m } if z < *slot + bias_m => {}
                _ => continue,
            }
            picture.set(x, y, color(inset));
        }
    }
}

/// Renders and writes the picture as PNG.
pub fn write_exploration_png(
    path: &Path,
    mesh: &TriMesh,
    object_pose: &Pose,
    placements: &[Placement],
    sensor: &SensorConfig,
) -> Result<(), ImageError> {
    render_exploration(mesh, object_pose, placements, sensor, &ExplorationView::default())?.write_png(path)
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DQuat;

    /// A closed axis-aligned cube of side `s` with a corner at the origin.
    fn cube(s: f64) -> TriMesh {
        let mut mesh = TriMesh::cuboid(DVec3::splat(s / 2.0));
        for v in &mut mesh.vertices {
            *v += s / 2.0;
        }
        mesh
    }

    fn image(value: f64) -> TactileImage {
        TactileImage::new(6, 6, vec![value; 36]).expect("a valid image")
    }

    /// A pad pressing the cube's face through `point` with outward normal `outward`: the pad's
    /// back sits the covering's thickness outside the face, its normal pointing in.
    fn placement(point: DVec3, outward: DVec3, sensor: &SensorConfig, value: f64) -> Placement {
        let pad = PadPose::new(
            point + outward * sensor.thickness_m,
            -outward,
            DVec3::Z + DVec3::X * 0.1,
        )
        .expect("a valid pad pose");
        Placement {
            pad_in_object: pad,
            image: image(value),
        }
    }

    fn view() -> ExplorationView {
        ExplorationView {
            panel_px: 200,
            images_shown: 2,
            image_columns: 2,
            ..ExplorationView::default()
        }
    }

    #[test]
    fn a_patch_on_a_visible_face_is_drawn_and_one_on_the_far_face_is_hidden() {
        let sensor = SensorConfig::square(6, 6, 0.012, 0.0012);
        let s = 0.05;
        let mesh = cube(s);
        // The default camera looks from +x, +y, +z: the faces x = s and y = s are visible, the
        // faces x = 0 and y = 0 are not.
        let near = placement(DVec3::new(s, s / 2.0, s / 2.0), DVec3::X, &sensor, 1.0);
        let far = placement(DVec3::new(0.0, s / 2.0, s / 2.0), -DVec3::X, &sensor, 0.0);
        let view = view();
        let picture = render_exploration(
            &mesh,
            &Pose::IDENTITY,
            &[near.clone(), far.clone()],
            &sensor,
            &view,
        )
        .expect("one shape of image");
        let camera = Camera::new(&view, &{
            let mut extent = mesh.vertices.clone();
            for p in [&near, &far] {
                extent.extend(patch_corners(&p.pad_in_object, &sensor, &Pose::IDENTITY));
            }
            extent
        });
        let at = |p: DVec3| {
            let q = camera.project(p);
            picture.get(q.x as usize, q.y as usize)
        };
        assert_eq!(at(DVec3::new(s, s / 2.0, s / 2.0)), PATCH);
        let hidden = at(DVec3::new(0.0, s / 2.0, s / 2.0));
        assert_ne!(hidden, PATCH);
        assert_ne!(hidden, PATCH_EDGE);
        assert_ne!(
            hidden, BACKGROUND,
            "the far patch's pixel shows the object in front of it"
        );
        // A corner of the panel shows the background.
        assert_eq!(picture.get(0, 0), BACKGROUND);
    }

    #[test]
    fn the_object_moves_with_its_pose_and_the_images_are_drawn_in_gray_beside_it() {
        let sensor = SensorConfig::square(6, 6, 0.012, 0.0012);
        let mesh = cube(0.05);
        let placements = [
            placement(DVec3::new(0.05, 0.025, 0.025), DVec3::X, &sensor, 1.0),
            placement(DVec3::new(0.025, 0.025, 0.05), DVec3::Z, &sensor, 0.5),
        ];
        let view = view();
        let fixed = render_exploration(&mesh, &Pose::IDENTITY, &placements, &sensor, &view)
            .expect("one shape of image");
        // The picture fits the scene: a translated object gives the same picture, up to rounding.
        let moved = Pose::new(DVec3::new(0.3, -0.2, 0.1), DQuat::IDENTITY);
        let shifted =
            render_exploration(&mesh, &moved, &placements, &sensor, &view).expect("one shape of image");
        let differing = (0..fixed.pixels.len())
            .step_by(3)
            .filter(|&i| fixed.pixels[i..i + 3] != shifted.pixels[i..i + 3])
            .count();
        // Rounding may move an edge pixel, nothing more.
        assert!(
            differing * 200 < fixed.width * fixed.height,
            "{differing} pixels differ"
        );
        // A quarter turn about z shows other faces: the picture changes.
        let turned = Pose::new(DVec3::ZERO, DQuat::from_rotation_z(0.7));
        assert_ne!(
            fixed,
            render_exploration(&mesh, &turned, &placements, &sensor, &view).expect("one shape of image")
        );
        // The contact sheet: two 6x6 images to the right of the panel, the first white, the second
        // mid-gray.
        assert!(fixed.width > view.panel_px);
        let gutter = CONTACT_SHEET_GUTTER_PX;
        let first = fixed.get(view.panel_px + gutter + 1, gutter + 1);
        assert_eq!(first, [255, 255, 255]);
        let cell_px = (fixed.width - view.panel_px - gutter) / 2;
        let second = fixed.get(view.panel_px + gutter + cell_px + 1, gutter + 1);
        assert_eq!(second, [128, 128, 128]);
    }
}
