//! Phase functions: `isotropic` and Henyey-Greenstein `hg` (parameter `g`, default 0.8).
//!
//! ```xml
//! <phase type="hg"><float name="g" value="0.7"/></phase>
//! ```

use crate::scene::desc::ObjectDesc;
use crate::scene::{Error, Result};

#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Phase {
    Isotropic,
    /// Henyey-Greenstein with asymmetry `g` in (-1, 1).
    Hg {
        g: f32,
    },
}

impl Phase {
    pub fn from_desc(obj: &ObjectDesc) -> Result<Phase> {
        let props = &obj.props;
        let phase = match obj.plugin.as_str() {
            "isotropic" => Phase::Isotropic,
            "hg" => {
                let g = props.float("g", 0.8)?;
                if !(g > -1.0 && g < 1.0) {
                    return Err(props.error("g", format!("hg: g = {} must lie in (-1, 1)", g)));
                }
                Phase::Hg { g }
            }
            other => {
                return Err(Error::at(
                    &obj.pos,
                    format!("phase function \"{}\" is not supported (supported: isotropic, hg)", other),
                ))
            }
        };
        props.finish()?;
        Ok(phase)
    }
}

use crate::math::{warp, Frame, Vec2, Vec3, INV_FOUR_PI};

impl Phase {
    /// Phase function value (= its sampling density) for incident `wi` (pointing back towards the
    /// previous vertex, Mitsuba's `mei.wi`) and outgoing `wo`.
    #[inline]
    pub fn eval(&self, wi: Vec3, wo: Vec3) -> f32 {
        match *self {
            Phase::Isotropic => INV_FOUR_PI,
            // cos θ between the forward direction −wi and wo.
            Phase::Hg { g } => hg(-wi.dot(wo), g),
        }
    }

    /// Sample `wo` given `wi`: (wo, weight = value/pdf = 1, pdf).
    #[inline]
    pub fn sample(&self, wi: Vec3, sample: Vec2) -> (Vec3, f32, f32) {
        match *self {
            Phase::Isotropic => (warp::square_to_uniform_sphere(sample), 1.0, INV_FOUR_PI),
            Phase::Hg { g } => {
                let cos_theta = if g.abs() < 1e-3 {
                    1.0 - 2.0 * sample.x
                } else {
                    let sqr = (1.0 - g * g) / (1.0 - g + 2.0 * g * sample.x);
                    ((1.0 + g * g - sqr * sqr) / (2.0 * g)).clamp(-1.0, 1.0)
                };
                let sin_theta = (1.0 - cos_theta * cos_theta).max(0.0).sqrt();
                let (sin_phi, cos_phi) = crate::math::fast::sincos_2pi(sample.y);
                let local = Vec3::new(sin_theta * cos_phi, sin_theta * sin_phi, cos_theta);
                let wo = Frame::from_normal(-wi).to_world(local);
                (wo, 1.0, hg(cos_theta, g))
            }
        }
    }
}

/// Henyey-Greenstein density for the cosine between the forward direction and `wo`.
#[inline]
pub fn hg(cos_theta: f32, g: f32) -> f32 {
    let denom = 1.0 + g * g - 2.0 * g * cos_theta;
    INV_FOUR_PI * (1.0 - g * g) / (denom * denom.max(0.0).sqrt())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::testing::chi2::chi2_sphere;

    #[test]
    fn hg_chi2_and_normalisation() {
        let wi = Vec3::new(0.3, -0.4, 0.866).normalize();
        for g in [-0.9, -0.5, 0.0, 0.3, 0.8, 0.9] {
            let phase = if g == 0.0 { Phase::Isotropic } else { Phase::Hg { g } };
            let r = chi2_sphere(|_, u| Some(phase.sample(wi, u).0), |wo| phase.eval(wi, wo), 40, 80, 400_000, 0.01, 7);
            assert!(r.passed, "g = {}: {}", g, r.report);
            assert!((r.pdf_integral - 1.0).abs() < 2e-3, "g = {}: ∫p = {}", g, r.pdf_integral);
        }
    }

    #[test]
    fn hg_sign_convention() {
        // Positive g scatters forward: along the ray direction −wi.
        let wi = Vec3::Z;
        let p = Phase::Hg { g: 0.8 };
        assert!(p.eval(wi, -Vec3::Z) > 10.0 * p.eval(wi, Vec3::Z));
        let (wo, w, pdf) = p.sample(wi, Vec2::new(0.5, 0.25));
        assert!(w == 1.0 && (pdf - p.eval(wi, wo)).abs() < 1e-4 * pdf);
    }
}
