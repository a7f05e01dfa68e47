//! A descriptor together with its parameters, as one serialisable value: what a trained model stores
//! so that test images are described exactly as the training images were.

use serde::{Deserialize, Serialize};

use super::mnti::{Mnti, MntiParams};
use super::moment_normalized::{MomentNormalized, MomentNormalizedParams};
use super::mr8::{Mr8, Mr8Params};
use super::polar_fourier::{PolarFourier, PolarFourierParams};
use super::shape_index::{ShapeIndex, ShapeIndexParams};
use super::sift::{Sift, SiftParams};
use super::vectorize::Vectorize;
use super::{Descriptor, DescriptorKind};
use crate::valid::Valid;

/// A descriptor kind with its parameters. In JSON: `{"descriptor": "mr8", "sigma_floor_px": 0.5, ...}`;
/// omitted parameters take their defaults.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(tag = "descriptor", rename_all = "kebab-case")]
pub enum DescriptorParams {
    Vectorize,
    Sift(SiftParams),
    Mr8(Mr8Params),
    MomentNormalized(MomentNormalizedParams),
    PolarFourier(PolarFourierParams),
    Mnti(MntiParams),
    ShapeIndex(ShapeIndexParams),
}

/// Parameters that cannot describe anything; names the field and what it accepts. The error of the
/// descriptors' [`Check`](crate::valid::Check) impls ([`SiftParams`], [`Mr8Params`], [`MntiParams`]).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ParamsError {
    #[error("descriptor parameter {field} = {value}: expected {expected}")]
    OutOfRange {
        field: &'static str,
        value: f64,
        expected: &'static str,
    },
}

impl DescriptorParams {
    /// The default parameters of `kind` (the ones each descriptor's docs state).
    pub fn default_for(kind: DescriptorKind) -> Self {
        match kind {
            DescriptorKind::Vectorize => Self::Vectorize,
            DescriptorKind::Sift => Self::Sift(SiftParams::default()),
            DescriptorKind::Mr8 => Self::Mr8(Mr8Params::default()),
            DescriptorKind::MomentNormalized => Self::MomentNormalized(MomentNormalizedParams::default()),
            DescriptorKind::PolarFourier => Self::PolarFourier(PolarFourierParams::default()),
            DescriptorKind::Mnti => Self::Mnti(MntiParams::default()),
            DescriptorKind::ShapeIndex => Self::ShapeIndex(ShapeIndexParams::default()),
        }
    }

    pub fn kind(&self) -> DescriptorKind {
        match self {
            Self::Vectorize => DescriptorKind::Vectorize,
            Self::Sift(_) => DescriptorKind::Sift,
            Self::Mr8(_) => DescriptorKind::Mr8,
            Self::MomentNormalized(_) => DescriptorKind::MomentNormalized,
            Self::PolarFourier(_) => DescriptorKind::PolarFourier,
            Self::Mnti(_) => DescriptorKind::Mnti,
            Self::ShapeIndex(_) => DescriptorKind::ShapeIndex,
        }
    }

    /// The descriptor these parameters define, after checking them.
    pub fn build(&self) -> Result<Box<dyn Descriptor>, ParamsError> {
        Ok(match *self {
            Self::Vectorize => Box::new(Vectorize),
            Self::Sift(p) => Box::new(Sift::new(Valid::new(p)?)),
            Self::Mr8(p) => Box::new(Mr8::new(Valid::new(p)?)),
            Self::MomentNormalized(p) => Box::new(MomentNormalized::new(p)),
            Self::PolarFourier(p) => Box::new(PolarFourier::new(p)),
            Self::Mnti(p) => Box::new(Mnti::new(Valid::new(p)?)),
            Self::ShapeIndex(p) => Box::new(ShapeIndex::new(Valid::new(p)?)),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn json_round_trip_and_defaults_for_omitted_fields() {
        for kind in DescriptorKind::ALL {
            let params = DescriptorParams::default_for(kind);
            let json = serde_json::to_string(&params).unwrap();
            assert!(
                json.contains(&format!("\"descriptor\":\"{}\"", kind.name())),
                "{json}"
            );
            let back: DescriptorParams = serde_json::from_str(&json).unwrap();
            assert_eq!(back, params);
            let built = params.build().unwrap();
            assert_eq!(built.kind(), kind);
            assert_eq!(built.params(), params);
        }
        let partial: DescriptorParams =
            serde_json::from_str(r#"{"descriptor":"mr8","stride_px":2}"#).unwrap();
        assert_eq!(
            partial,
            DescriptorParams::Mr8(Mr8Params {
                stride_px: 2,
                ..Default::default()
            })
        );
    }

    #[test]
    fn unknown_fields_and_bad_values_are_rejected_by_name() {
        let e = serde_json::from_str::<DescriptorParams>(r#"{"descriptor":"sift","clip":0.3}"#).unwrap_err();
        assert!(e.to_string().contains("clip"), "{e}");
        let bad = DescriptorParams::Mnti(MntiParams {
            padded_size_ratio: f64::NAN,
            ..Default::default()
        });
        let e = bad.build().err().unwrap();
        assert!(e.to_string().contains("mnti.padded_size_ratio"), "{e}");
    }
}
