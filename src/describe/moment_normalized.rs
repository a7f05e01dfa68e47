//! Moment-Normalized (Sec. IV-B4): the image turned so that its principal axis points along +x.
//!
//! 1. Mask to the inscribed disc ([`InscribedDisc`]).
//! 2. Divide by the mean intensity in the disc, so `I -> k I` gives the same descriptor (the paper
//!    says MN "should be invariant to intensity changes"; this is our explicit normalisation, on
//!    by default, see [`MomentNormalizedParams::normalize_intensity`]).
//! 3. Moments about the image centre give the orientation `phi`: the major-axis angle, turned by a
//!    half turn when the third-order moment along the axis is negative ([`CentredMoments`], Hu [50]).
//! 4. Rotate by `-phi` with bilinear interpolation, `out(p) = in(R(phi) p)`, so the axis lies on +x;
//!    mask to the disc again (the corners of the turned image come from outside it).
//! 5. Vectorize (columns concatenated), `rows * cols` values.
//!
//! Rotating the input by `alpha` turns `phi` into `phi + alpha` and step 4 undoes it, so the output is
//! rotation-invariant up to resampling error (and up to the paper's caveat: shapes with a symmetry
//! have no defined axis or skew). Outputs at the extremes: an all-zero image gives all zeros; a
//! saturated square image gives the disc itself (1 inside, 0 outside; its moments are isotropic,
//! `phi = 0`).

use serde::{Deserialize, Serialize};

use super::disc::InscribedDisc;
use super::moments::CentredMoments;
use super::plane::Plane;
use super::vectorize::columns_concatenated;
use super::{Descriptor, DescriptorKind, DescriptorParams, Feature};
use crate::tactile::TactileImage;

/// Parameters of [`MomentNormalized`].
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct MomentNormalizedParams {
    /// Divide the masked image by its mean in the disc (step 2). Default true.
    pub normalize_intensity: bool,
}

impl Default for MomentNormalizedParams {
    fn default() -> Self {
        Self {
            normalize_intensity: true,
        }
    }
}

/// Sec. IV-B4 (module docs).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct MomentNormalized {
    params: MomentNormalizedParams,
}

impl MomentNormalized {
    pub fn new(params: MomentNormalizedParams) -> Self {
        Self { params }
    }

    pub fn parameters(&self) -> MomentNormalizedParams {
        self.params
    }

    /// Steps 1-4: the masked, normalised image turned to its principal axis, before vectorising
    /// (also the input of MNTI, Sec. IV-B6).
    pub fn normalized_plane(&self, image: &TactileImage) -> Plane {
        let mut plane = Plane::from_image(image);
        let disc = InscribedDisc::of(&plane);
        disc.mask(&mut plane);
        if self.params.normalize_intensity {
            disc.normalize_mean(&mut plane);
        }
        let phi = CentredMoments::of(&plane).orientation_rad();
        let mut turned = plane.rotated(-phi);
        disc.mask(&mut turned);
        turned
    }
}

impl Descriptor for MomentNormalized {
    fn kind(&self) -> DescriptorKind {
        DescriptorKind::MomentNormalized
    }

    fn params(&self) -> DescriptorParams {
        DescriptorParams::MomentNormalized(self.params)
    }

    fn describe(&self, image: &TactileImage) -> Vec<Feature> {
        let plane = self.normalized_plane(image);
        vec![columns_concatenated(plane.rows(), plane.cols(), plane.values())]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A 7x7 image with a bright blob at centred (x, y) and a dimmer one opposite at half distance.
    fn lopsided_bar(x: i32, y: i32) -> TactileImage {
        let mut values = vec![0.0; 49];
        let mut put = |x: i32, y: i32, v: f64| values[((3 - y) * 7 + (x + 3)) as usize] = v;
        put(x, y, 1.0);
        put(-x / 2, -y / 2, 0.5);
        put(0, 0, 0.7);
        TactileImage::new(7, 7, values).unwrap()
    }

    #[test]
    fn quarter_turns_give_the_same_descriptor_with_the_heavy_end_on_plus_x() {
        let mn = MomentNormalized::default();
        let reference = mn.normalized_plane(&lopsided_bar(2, 0));
        // Heavy end on +x already: nothing turns. The blob at centred (2, 0) is row 3, col 5.
        assert!(reference.get(3, 5) > reference.get(3, 1));
        for (x, y) in [(0, 2), (-2, 0), (0, -2)] {
            let turned = mn.normalized_plane(&lopsided_bar(x, y));
            for (a, b) in reference.values().iter().zip(turned.values()) {
                assert!((a - b).abs() < 1e-9, "blob at ({x}, {y})");
            }
        }
    }

    #[test]
    fn extremes_are_documented_outputs() {
        let mn = MomentNormalized::default();
        let zero = mn.describe(&TactileImage::zeros(6, 6).unwrap());
        assert_eq!(zero, vec![vec![0.0; 36]]);
        let full = mn.describe(&TactileImage::new(6, 6, vec![1.0; 36]).unwrap());
        let mut disc = Plane::from_values(6, 6, vec![1.0; 36]).unwrap();
        InscribedDisc::of(&disc).mask(&mut disc);
        assert_eq!(full, vec![columns_concatenated(6, 6, disc.values())]);
    }
}
