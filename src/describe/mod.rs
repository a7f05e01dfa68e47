//! Tactile image descriptors (Sec. IV-B): each turns a [`TactileImage`] into one or more feature
//! vectors, ideally invariant to rotation about the pad normal, which the controllers leave free.
//!
//! One file per descriptor (`vectorize`, `sift`, `mr8`, `moment_normalized`, `polar_fourier`,
//! `mnti`, and beyond the paper `shape_index`, for the frames of large arrays), and the helpers they share: [`Plane`] (centred coordinates, bilinear sampling),
//! [`InscribedDisc`] (the mask), [`CentredMoments`] and [`FftPlans`] (cached FFT plans). Every
//! descriptor works on images of any size, is deterministic, `Send + Sync`, and returns finite values
//! for every valid image; each module documents its output for all-zero and saturated images.
//! Descriptors that are built once and reused (as [`DescriptorKind::build`] gives them) plan their
//! FFTs and filter banks once per image size.

pub(crate) mod disc;
pub(crate) mod fft;
pub(crate) mod mnti;
pub(crate) mod moment_normalized;
pub(crate) mod moments;
pub(crate) mod mr8;
pub(crate) mod params;
pub(crate) mod plane;
pub(crate) mod polar_fourier;
pub(crate) mod shape_index;
pub(crate) mod sift;
pub(crate) mod vectorize;

use serde::{Deserialize, Serialize};

use crate::tactile::TactileImage;

pub use disc::InscribedDisc;
pub use fft::FftPlans;
pub use mnti::{Mnti, MntiParams};
pub use moment_normalized::{MomentNormalized, MomentNormalizedParams};
pub use moments::CentredMoments;
pub use mr8::{Mr8, Mr8Params};
pub use params::{DescriptorParams, ParamsError};
pub use plane::Plane;
pub use polar_fourier::{PolarFourier, PolarFourierParams};
pub use shape_index::{ShapeIndex, ShapeIndexParams};
pub use sift::{Sift, SiftParams};
pub use vectorize::Vectorize;

/// One feature vector.
pub type Feature = Vec<f64>;

/// A tactile image descriptor `d(I)` of Sec. IV-A. Most return one feature per image; MR-8 returns
/// one per image subsection.
pub trait Descriptor: Send + Sync {
    /// Which descriptor this is.
    fn kind(&self) -> DescriptorKind;
    /// The parameters it was built with: `self.params().build()` describes images identically.
    fn params(&self) -> DescriptorParams;
    /// The features of `image`; every value finite, for every input including all-zero and
    /// saturated images.
    fn describe(&self, image: &TactileImage) -> Vec<Feature>;
}

/// The six descriptors of Sec. IV-B and the shape index, by name.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum DescriptorKind {
    /// Sec. IV-B1: columns concatenated; the negative control.
    Vectorize,
    /// Sec. IV-B2: the SIFT descriptor at the scale of the whole image.
    Sift,
    /// Sec. IV-B3: the Varma-Zisserman maximal-response filter bank.
    Mr8,
    /// Sec. IV-B4: rotated to the principal axis of moments about the image centre.
    MomentNormalized,
    /// Sec. IV-B5: Fourier magnitudes of polar rings (Eq. 5-8).
    PolarFourier,
    /// Sec. IV-B6: Moment-Normalized, then 2-D Fourier magnitudes (translation-invariant).
    Mnti,
    /// Beyond the paper: the local shapes of a large array's frame, pooled (shape index and
    /// curvedness at three scales).
    ShapeIndex,
}

impl DescriptorKind {
    /// Every descriptor: the paper's six, then the shape index.
    pub const ALL: [DescriptorKind; 7] = [
        Self::Vectorize,
        Self::Sift,
        Self::Mr8,
        Self::MomentNormalized,
        Self::PolarFourier,
        Self::Mnti,
        Self::ShapeIndex,
    ];

    /// The six of Sec. IV-B, which the paper's experiments compare: the first six of
    /// [`ALL`](Self::ALL).
    pub const PAPER: &'static [DescriptorKind] = Self::ALL.split_at(6).0;

    /// The command-line name (`vectorize`, `sift`, `mr8`, `moment-normalized`, `polar-fourier`,
    /// `mnti`, `shape-index`).
    pub fn name(self) -> &'static str {
        match self {
            Self::Vectorize => "vectorize",
            Self::Sift => "sift",
            Self::Mr8 => "mr8",
            Self::MomentNormalized => "moment-normalized",
            Self::PolarFourier => "polar-fourier",
            Self::Mnti => "mnti",
            Self::ShapeIndex => "shape-index",
        }
    }

    /// The short name: `mn` and `pf` for the two long names (as the paper abbreviates them), the
    /// name otherwise.
    pub fn short_name(self) -> &'static str {
        match self {
            Self::MomentNormalized => "mn",
            Self::PolarFourier => "pf",
            other => other.name(),
        }
    }

    /// Parses [`name`](Self::name) or [`short_name`](Self::short_name).
    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL
            .into_iter()
            .find(|k| k.name() == name || k.short_name() == name)
    }

    /// Its documented default parameters.
    pub fn default_params(self) -> DescriptorParams {
        DescriptorParams::default_for(self)
    }

    /// The descriptor with its documented default parameters.
    pub fn build(self) -> Box<dyn Descriptor> {
        match self {
            Self::Vectorize => Box::new(Vectorize),
            Self::Sift => Box::new(Sift::default()),
            Self::Mr8 => Box::new(Mr8::default()),
            Self::MomentNormalized => Box::new(MomentNormalized::default()),
            Self::PolarFourier => Box::new(PolarFourier::default()),
            Self::Mnti => Box::new(Mnti::default()),
            Self::ShapeIndex => Box::new(ShapeIndex::default()),
        }
    }

    /// The descriptor `params` define (their kind included), after checking them.
    pub fn build_with(params: &DescriptorParams) -> Result<Box<dyn Descriptor>, ParamsError> {
        params.build()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_round_trip_and_defaults_build_the_named_descriptor() {
        for kind in DescriptorKind::ALL {
            assert_eq!(DescriptorKind::from_name(kind.name()), Some(kind));
            let built = kind.build();
            assert_eq!(built.kind(), kind);
            assert_eq!(built.params(), kind.default_params());
            assert_eq!(
                DescriptorKind::build_with(&kind.default_params()).unwrap().kind(),
                kind
            );
        }
        assert_eq!(DescriptorKind::from_name("hog"), None);
        // The paper's experiments compare the six of Sec. IV-B, never the shape index.
        assert_eq!(DescriptorKind::PAPER.len(), 6);
        assert!(!DescriptorKind::PAPER.contains(&DescriptorKind::ShapeIndex));
    }

    #[test]
    fn descriptors_are_shareable_across_threads() {
        fn shareable<T: Send + Sync + ?Sized>() {}
        shareable::<dyn Descriptor>();
        shareable::<Mr8>();
        shareable::<Mnti>();
        shareable::<PolarFourier>();
    }
}
