//! Affine transforms with cached inverse (points, vectors, normals).

use glam::{Mat4, Vec3};

/// An affine transform and its inverse.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Transform {
    /// Forward matrix.
    pub m: Mat4,
    /// Inverse matrix.
    pub m_inv: Mat4,
}

impl Default for Transform {
    fn default() -> Self {
        Self::IDENTITY
    }
}

impl Transform {
    /// The identity.
    pub const IDENTITY: Self = Self {
        m: Mat4::IDENTITY,
        m_inv: Mat4::IDENTITY,
    };

    /// From a matrix; `None` if it is singular or not finite.
    pub fn new(m: Mat4) -> Option<Self> {
        let det = m.determinant();
        if !det.is_finite() || det.abs() < 1e-12 {
            return None;
        }
        Some(Self {
            m,
            m_inv: m.inverse(),
        })
    }

    /// The inverse transform.
    pub fn inverse(&self) -> Self {
        Self {
            m: self.m_inv,
            m_inv: self.m,
        }
    }

    /// self ∘ other (apply `other` first).
    pub fn then_apply_to(&self, other: &Self) -> Self {
        Self {
            m: self.m * other.m,
            m_inv: other.m_inv * self.m_inv,
        }
    }

    /// Transform a point.
    #[inline]
    pub fn point(&self, p: Vec3) -> Vec3 {
        self.m.transform_point3(p)
    }

    /// Transform a vector.
    #[inline]
    pub fn vector(&self, v: Vec3) -> Vec3 {
        self.m.transform_vector3(v)
    }

    /// Transform a normal (by the inverse transpose); not normalised.
    #[inline]
    pub fn normal(&self, n: Vec3) -> Vec3 {
        self.m_inv.transpose().transform_vector3(n)
    }

    /// True if the transform flips handedness (negative determinant).
    pub fn swaps_handedness(&self) -> bool {
        self.m.determinant() < 0.0
    }
}

impl Transform {
    /// pbrt's `LookAt`: the camera-from-world transform of a camera at `eye` looking at
    /// `target` (left-handed: +z forward, +y up, +x right).
    pub fn look_at(eye: glam::Vec3, target: glam::Vec3, up: glam::Vec3) -> anyhow::Result<Self> {
        let dir = (target - eye).normalize_or_zero();
        anyhow::ensure!(dir != glam::Vec3::ZERO, "LookAt: eye and target coincide");
        let right = up.normalize_or_zero().cross(dir);
        anyhow::ensure!(
            right.length_squared() > 1e-12,
            "LookAt: up vector and viewing direction are parallel"
        );
        let right = right.normalize();
        let new_up = dir.cross(right);
        let world_from_camera = Mat4::from_cols(
            right.extend(0.0),
            new_up.extend(0.0),
            dir.extend(0.0),
            eye.extend(1.0),
        );
        let t = Transform::new(world_from_camera)
            .ok_or_else(|| anyhow::anyhow!("LookAt: singular camera transform"))?;
        Ok(t.inverse())
    }

    /// Translation by `v`.
    pub fn translate(v: glam::Vec3) -> Self {
        Self {
            m: Mat4::from_translation(v),
            m_inv: Mat4::from_translation(-v),
        }
    }
}
