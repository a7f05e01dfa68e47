//! Tactile image descriptors (Sec. IV-B): each turns a [`TactileImage`] into one or more feature
//! vectors, ideally invariant to rotation about the pad normal, which the controllers leave free.

use serde::{Deserialize, Serialize};

use crate::tactile::TactileImage;

/// One feature vector.
pub type Feature = Vec<f64>;

/// A tactile image descriptor `d(I)` of Sec. IV-A. Most return one feature per image; MR-8 returns
/// one per image subsection.
pub trait Descriptor: Send + Sync {
    /// Which descriptor this is.
    fn kind(&self) -> DescriptorKind;
    /// The features of `image`; every value finite, for every input including all-zero and
    /// saturated images.
    fn describe(&self, image: &TactileImage) -> Vec<Feature>;
}

/// The six descriptors of Sec. IV-B, by name.
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
}

impl DescriptorKind {
    pub const ALL: [DescriptorKind; 6] = [
        Self::Vectorize,
        Self::Sift,
        Self::Mr8,
        Self::MomentNormalized,
        Self::PolarFourier,
        Self::Mnti,
    ];

    /// The command-line name (`vectorize`, `sift`, `mr8`, `moment-normalized`, `polar-fourier`, `mnti`).
    pub fn name(self) -> &'static str {
        match self {
            Self::Vectorize => "vectorize",
            Self::Sift => "sift",
            Self::Mr8 => "mr8",
            Self::MomentNormalized => "moment-normalized",
            Self::PolarFourier => "polar-fourier",
            Self::Mnti => "mnti",
        }
    }

    /// Parses [`name`](Self::name).
    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|k| k.name() == name)
    }
}
