//! Materials: what a surface is made of, turned into a [`Bsdf`] at each hit (textures resolved).
//! TODO(issue 4/5): phong, conductor, coated diffuse, dielectric, mix, textures.

pub mod texture;

pub use texture::Texture;

use crate::bsdf::{Bsdf, Lambert};
use crate::geometry::SurfaceHit;

/// A surface material description.
#[derive(Clone, Debug)]
pub enum Material {
    /// Lambertian diffuse with a reflectance texture.
    Diffuse {
        /// Albedo.
        reflectance: Texture,
    },
}

impl Material {
    /// The BSDF at a hit. `front` is true when the ray arrives on the side of `hit.ng`
    /// (transmissive materials need it to orient their index of refraction).
    pub fn bsdf(&self, hit: &SurfaceHit, front: bool) -> Bsdf {
        let _ = front;
        match self {
            Material::Diffuse { reflectance } => Bsdf::Lambert(Lambert {
                r: reflectance
                    .eval(hit.uv)
                    .clamp(crate::Rgb::ZERO, crate::Rgb::ONE),
            }),
        }
    }
}
