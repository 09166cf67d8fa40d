//! All sampling math: warps by inversion with their pdfs (and inverses), discrete and
//! piecewise-constant distributions, orthonormal frames, and the per-pixel sample patterns.
//!
//! Nothing here knows about rendering; every BSDF, light, light selector and integrator calls
//! into this module instead of re-deriving a warp.

pub mod alias;
pub mod chi2;
pub mod distribution1d;
pub mod distribution2d;
pub mod equal_area;
pub mod error;
pub mod f64_lanes;
pub mod frame;
pub mod hash;
pub mod pattern;
pub mod permutation;
pub mod spherical_rectangle;
pub mod spherical_triangle;
pub mod warps;

pub use alias::AliasTable;
pub use distribution1d::Distribution1D;
pub use distribution2d::Distribution2D;
pub use equal_area::{equal_area_sphere_to_square, equal_area_square_to_sphere};
pub use error::SamplingError;
pub use frame::Frame;
pub use pattern::{Pattern, PatternKind, PixelSamples, SamplePattern, make_pattern};
pub use permutation::{Permutation, permute};
pub use spherical_rectangle::SphericalRectangle;
pub use spherical_triangle::{SolidAngleDraw, SphericalProjection, SphericalTriangle};
pub use warps::*;

/// The largest f32 strictly below 1, so that samples stay in [0, 1).
pub const ONE_MINUS_EPSILON: f32 = 1.0 - f32::EPSILON / 2.0;
