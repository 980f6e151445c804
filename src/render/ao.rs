//! Ambient occlusion at one surface point, as an integral over primary sample space `[0,1)²`.
//!
//! A sample `u = (u₀, u₁)` maps to the cosine-weighted direction with `sin θ = √u₀` and
//! `φ = 2π u₁` about the normal, so that the ambient occlusion `A = (1/π) ∫ V(ω) cos θ dω`
//! equals `∫_{[0,1)²} V(u) du`, with `V = 1` when nothing lies within the maximum distance.
//! The Monte Carlo estimate is the mean of `V` over a pattern's points; its variance is the
//! sampler's spectrum against `V`'s (lattice form), which is why `V` can be rasterized into a
//! [`GridIntegrand`].

use super::geometry::{Hit, NearShapes, Ray, Scene, Vec3};
use crate::error::Result;
use crate::integrand::GridIntegrand;
use crate::pointset::PointSet;
use std::f64::consts::PI;

/// Offset of secondary-ray origins along the normal, against self-intersection (the scene's
/// unit is the room's side).
const SURFACE_OFFSET: f64 = 1e-7;

/// A surface point with an orthonormal frame about its normal.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ShadingPoint {
    origin: Vec3,
    tangent: Vec3,
    bitangent: Vec3,
    normal: Vec3,
}

impl ShadingPoint {
    /// The frame at a hit (Duff et al.'s branchless orthonormal basis).
    pub fn new(hit: &Hit) -> Self {
        let n = hit.normal;
        let sign = 1f64.copysign(n.z);
        let a = -1.0 / (sign + n.z);
        let b = n.x * n.y * a;
        Self {
            origin: hit.point + n * SURFACE_OFFSET,
            tangent: Vec3::new(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x),
            bitangent: Vec3::new(b, sign + n.y * n.y * a, -n.y),
            normal: n,
        }
    }

    /// The cosine-weighted direction for `sin θ = r`, `(cos φ, sin φ)`.
    fn direction(&self, r: f64, cos_phi: f64, sin_phi: f64) -> Vec3 {
        let cos_theta = (1.0 - r * r).max(0.0).sqrt();
        self.tangent * (r * cos_phi) + self.bitangent * (r * sin_phi) + self.normal * cos_theta
    }

    /// `V(u)`: 1 if the direction of `u` is free of surfaces up to `max_distance`, else 0.
    pub fn visibility(&self, scene: &Scene, u: &[f64], max_distance: f64) -> f64 {
        self.visibility_near(scene, NearShapes::ALL, u, max_distance)
    }

    /// The shapes this point's rays can meet within `max_distance`: computed once, it lets
    /// [`visibility_near`](Self::visibility_near) skip the others for every ray.
    pub fn near(&self, scene: &Scene, max_distance: f64) -> NearShapes {
        scene.near(self.origin, max_distance)
    }

    /// As [`visibility`](Self::visibility), testing only the shapes of `near` (from
    /// [`near`](Self::near) with the same scene and distance): the same value.
    pub fn visibility_near(
        &self,
        scene: &Scene,
        near: NearShapes,
        u: &[f64],
        max_distance: f64,
    ) -> f64 {
        let (sin_phi, cos_phi) = (2.0 * PI * u[1]).sin_cos();
        self.visible(scene, near, u[0].sqrt(), cos_phi, sin_phi, max_distance)
    }

    /// `V` along the direction with `sin θ = r` and `(cos φ, sin φ)`.
    fn visible(
        &self,
        scene: &Scene,
        near: NearShapes,
        r: f64,
        cos: f64,
        sin: f64,
        max_distance: f64,
    ) -> f64 {
        let ray = Ray {
            origin: self.origin,
            direction: self.direction(r, cos, sin),
        };
        if scene.occluded_near(&ray, max_distance, near) {
            0.0
        } else {
            1.0
        }
    }

    /// The Monte Carlo estimate of the ambient occlusion: the mean of `V` over `points` (2D).
    pub fn estimate(&self, scene: &Scene, points: &PointSet, max_distance: f64) -> f64 {
        let near = self.near(scene, max_distance);
        let total: f64 = points
            .points()
            .map(|u| self.visibility_near(scene, near, u, max_distance))
            .sum();
        total / points.len() as f64
    }

    /// `V` rasterized on a `resolution × resolution` grid, one ray through each cell centre;
    /// cell `(x, y)` holds `V((x + ½)/R, (y + ½)/R)`: a tabulation by point samples
    /// ([`GridMeaning::PointSamples`](crate::integrand::GridMeaning)).
    ///
    /// # Errors
    /// A zero resolution.
    pub fn visibility_grid(
        &self,
        scene: &Scene,
        resolution: usize,
        max_distance: f64,
    ) -> Result<GridIntegrand> {
        let centre = |i: usize| (i as f64 + 0.5) / resolution as f64;
        // Each row shares its φ and each column its radius: 2R transcendental calls, not 2R².
        let radii: Vec<f64> = (0..resolution).map(|x| centre(x).sqrt()).collect();
        let near = self.near(scene, max_distance);
        let mut values = Vec::with_capacity(resolution * resolution);
        for y in 0..resolution {
            let (sin, cos) = (2.0 * PI * centre(y)).sin_cos();
            values.extend(
                radii
                    .iter()
                    .map(|&r| self.visible(scene, near, r, cos, sin, max_distance)),
            );
        }
        Ok(GridIntegrand::new(resolution, resolution, values)?
            .with_meaning(crate::integrand::GridMeaning::PointSamples))
    }
}
