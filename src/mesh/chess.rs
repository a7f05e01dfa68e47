//! Chess pieces as surfaces of revolution: the paper's 3D set had a chess piece (Fig. 1, Fig. 5);
//! we generate a pawn and a rook from profile curves instead of downloading one.
//!
//! Proportions follow a Staunton set (pawn 38.5 mm tall on a 28 mm base, rook 42 mm on a 30 mm
//! base); the object sets rescale them like every other object. The rook's crenellated top is not
//! rotationally symmetric, so it is modelled as a turret with a hollow cup in its top, which keeps
//! the concave rim that distinguishes it by touch.

use std::f64::consts::{FRAC_PI_2, TAU};

use serde::{Deserialize, Serialize};

use super::TriMesh;
use super::error::MeshError;
use super::revolution::Profile;

/// Segments around the axis: 96 keeps the inscribed-polygon volume loss at 0.07 % and the facets
/// about 2 mm wide at the base after scaling to a 12 cm diagonal, the size of one taxel.
pub const REVOLUTION_SEGMENTS: usize = 96;
/// Largest angle of an arc piece of the profile.
pub const ARC_STEP_RAD: f64 = TAU / 96.0;

/// The generated chess pieces.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum ChessPiece {
    Pawn,
    Rook,
}

impl ChessPiece {
    pub const ALL: [ChessPiece; 2] = [ChessPiece::Pawn, ChessPiece::Rook];

    pub fn name(self) -> &'static str {
        match self {
            ChessPiece::Pawn => "pawn",
            ChessPiece::Rook => "rook",
        }
    }

    /// The piece's profile in metres, base on z = 0 (checked by [`ProfileBuilder::finish`]).
    ///
    /// [`ProfileBuilder::finish`]: super::revolution::ProfileBuilder::finish
    pub fn profile(self) -> Result<Profile, MeshError> {
        let mm: f64 = 1e-3;
        let profile = match self {
            // Base disc with a rounded molding, a tapering shaft, a collar, and a ball head of radius
            // 7.5 mm centred 31 mm up, met by a 5 mm neck.
            ChessPiece::Pawn => {
                let head_z = 31.0 * mm;
                let head_r = 7.5 * mm;
                let neck_r = 5.0 * mm;
                let neck_top = head_z - (head_r * head_r - neck_r * neck_r).sqrt();
                Profile::builder(0.0)
                    .line_to(14.0 * mm, 0.0)
                    .line_to(14.0 * mm, 2.0 * mm)
                    .arc_to(12.0 * mm, 2.0 * mm, FRAC_PI_2)
                    .line_to(10.0 * mm, 5.0 * mm)
                    .line_to(6.0 * mm, 20.0 * mm)
                    .line_to(9.0 * mm, 21.0 * mm)
                    .line_to(9.0 * mm, 23.0 * mm)
                    .line_to(neck_r, 24.0 * mm)
                    .line_to(neck_r, neck_top)
                    .arc_to(0.0, head_z, FRAC_PI_2)
            }
            // Base with molding, a shaft widening to a collar, a turret, and a cup 4 mm deep in the
            // top: the profile runs back down inside the rim before returning to the axis.
            ChessPiece::Rook => Profile::builder(0.0)
                .line_to(15.0 * mm, 0.0)
                .line_to(15.0 * mm, 3.0 * mm)
                .arc_to(13.0 * mm, 3.0 * mm, FRAC_PI_2)
                .line_to(11.0 * mm, 6.0 * mm)
                .line_to(9.0 * mm, 30.0 * mm)
                .line_to(12.0 * mm, 31.0 * mm)
                .line_to(12.0 * mm, 33.0 * mm)
                .line_to(11.0 * mm, 34.0 * mm)
                .line_to(11.0 * mm, 42.0 * mm)
                .line_to(8.0 * mm, 42.0 * mm)
                .line_to(8.0 * mm, 38.0 * mm)
                .line_to(0.0, 38.0 * mm),
        };
        profile.finish()
    }

    /// The piece as a closed, outward-oriented mesh (metres, base on z = 0, axis along z).
    pub fn mesh(self) -> Result<TriMesh, MeshError> {
        self.profile()?.revolve(REVOLUTION_SEGMENTS, ARC_STEP_RAD)
    }
}
