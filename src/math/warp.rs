//! Sample warps from the unit square (Mitsuba's `warp` namespace), each with its pdf.

use super::fast::sincos_2pi;
use super::{INV_FOUR_PI, INV_PI, INV_TWO_PI};
use glam::{Vec2, Vec3};

/// Uniform on the unit disk, concentric mapping (Shirley & Chiu 1997).
#[inline]
pub fn square_to_uniform_disk_concentric(s: Vec2) -> Vec2 {
    let x = 2.0 * s.x - 1.0;
    let y = 2.0 * s.y - 1.0;
    if x == 0.0 && y == 0.0 {
        return Vec2::ZERO;
    }
    // φ = (π/4)·(y/x), or π/2 − (π/4)·(x/y), as a fraction of a turn.
    let (r, turns) = if x * x > y * y { (x, 0.125 * (y / x)) } else { (y, 0.25 - 0.125 * (x / y)) };
    let (sin_phi, cos_phi) = sincos_2pi(turns);
    Vec2::new(r * cos_phi, r * sin_phi)
}

/// Cosine-weighted hemisphere around +Z.
#[inline]
pub fn square_to_cosine_hemisphere(s: Vec2) -> Vec3 {
    let p = square_to_uniform_disk_concentric(s);
    let z = (1.0 - p.length_squared()).max(0.0).sqrt();
    Vec3::new(p.x, p.y, z)
}

#[inline]
pub fn square_to_cosine_hemisphere_pdf(v: Vec3) -> f32 {
    if v.z > 0.0 {
        INV_PI * v.z
    } else {
        0.0
    }
}

/// Uniform on the unit sphere.
#[inline]
pub fn square_to_uniform_sphere(s: Vec2) -> Vec3 {
    let z = 1.0 - 2.0 * s.y;
    let r = (1.0 - z * z).max(0.0).sqrt();
    let (sin_phi, cos_phi) = sincos_2pi(s.x);
    Vec3::new(r * cos_phi, r * sin_phi, z)
}

#[inline]
pub fn square_to_uniform_sphere_pdf() -> f32 {
    INV_FOUR_PI
}

/// Uniform on the hemisphere around +Z.
#[inline]
pub fn square_to_uniform_hemisphere(s: Vec2) -> Vec3 {
    let z = s.y;
    let r = (1.0 - z * z).max(0.0).sqrt();
    let (sin_phi, cos_phi) = sincos_2pi(s.x);
    Vec3::new(r * cos_phi, r * sin_phi, z)
}

#[inline]
pub fn square_to_uniform_hemisphere_pdf() -> f32 {
    INV_TWO_PI
}

/// Uniform in the cone of directions around +Z with `cos θ ≥ cos_cutoff`.
#[inline]
pub fn square_to_uniform_cone(s: Vec2, cos_cutoff: f32) -> Vec3 {
    let cos_theta = (1.0 - s.y) + s.y * cos_cutoff;
    let sin_theta = (1.0 - cos_theta * cos_theta).max(0.0).sqrt();
    let (sin_phi, cos_phi) = sincos_2pi(s.x);
    Vec3::new(sin_theta * cos_phi, sin_theta * sin_phi, cos_theta)
}

#[inline]
pub fn square_to_uniform_cone_pdf(v: Vec3, cos_cutoff: f32) -> f32 {
    if v.z >= cos_cutoff {
        INV_TWO_PI / (1.0 - cos_cutoff)
    } else {
        0.0
    }
}

/// Uniform on a triangle: barycentrics (b1, b2) (Mitsuba's `square_to_uniform_triangle`).
#[inline]
pub fn square_to_uniform_triangle(s: Vec2) -> Vec2 {
    let t = (1.0 - s.x).max(0.0).sqrt();
    Vec2::new(1.0 - t, t * s.y)
}

/// Standard normal via Box-Muller on one coordinate pair.
#[inline]
pub fn square_to_std_normal(s: Vec2) -> Vec2 {
    let r = (-2.0 * (1.0 - s.x).ln()).sqrt();
    let (sin_phi, cos_phi) = sincos_2pi(s.y);
    Vec2::new(r * cos_phi, r * sin_phi)
}

#[cfg(test)]
mod tests {
    use super::*;
    #[test]
    fn unit_length() {
        for i in 0..16 {
            for j in 0..16 {
                let s = Vec2::new((i as f32 + 0.5) / 16.0, (j as f32 + 0.5) / 16.0);
                assert!((square_to_uniform_sphere(s).length() - 1.0).abs() < 1e-5);
                assert!((square_to_cosine_hemisphere(s).length() - 1.0).abs() < 1e-5);
                assert!((square_to_uniform_cone(s, 0.5).length() - 1.0).abs() < 1e-5);
            }
        }
    }
}
