//! Statistical test helpers shared by unit and integration tests: chi-square over the sphere
//! ([`chi2`]) and Student-t tails for batch-based t-tests ([`student_t`]).

pub mod chi2;
pub mod student_t;

use crate::interaction::SurfaceInteraction;
use crate::math::{Frame, Vec2, Vec3};

/// A surface interaction at the origin with normal +Z and the local shading frame equal to the
/// world frame, seen from `wi` (for BSDF tests that evaluate and sample in the local frame).
pub fn si_with_wi(wi: Vec3) -> SurfaceInteraction {
    SurfaceInteraction {
        t: 1.0,
        p: Vec3::ZERO,
        n: Vec3::Z,
        sh_frame: Frame::from_normal(Vec3::Z),
        uv: Vec2::splat(0.5),
        wi,
        shape: 0,
        prim: 0,
    }
}

/// The unit direction at polar angle `theta_deg` from +Z and azimuth `phi_deg` (degrees).
pub fn sph(theta_deg: f32, phi_deg: f32) -> Vec3 {
    let (t, p) = (theta_deg.to_radians(), phi_deg.to_radians());
    Vec3::new(t.sin() * p.cos(), t.sin() * p.sin(), t.cos())
}

/// Push a microfacet roughness as Mitsuba's plugins take it: `alpha` when isotropic, else
/// `alpha_u` and `alpha_v`.
pub fn push_alpha(props: &mut Vec<(&str, crate::scene::desc::Value)>, alpha_u: f32, alpha_v: f32) {
    use crate::scene::desc::Value;
    if alpha_u == alpha_v {
        props.push(("alpha", Value::Float(alpha_u as f64)));
    } else {
        props.push(("alpha_u", Value::Float(alpha_u as f64)));
        props.push(("alpha_v", Value::Float(alpha_v as f64)));
    }
}
