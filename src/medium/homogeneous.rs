//! Mitsuba's `homogeneous` medium: constant extinction `sigma_t` (times `scale`) and single-scattering
//! `albedo`, with a nested phase function (isotropic by default).
//!
//! ```xml
//! <medium type="homogeneous" id="milk">
//!     <rgb name="albedo" value="0.8, 0.8, 0.8"/>
//!     <float name="sigma_t" value="1"/>
//!     <float name="scale" value="34"/>
//!     <phase type="isotropic"/>
//! </medium>
//! ```

use super::phase::Phase;
use crate::color::Spectrum;
use crate::scene::desc::{ObjectDesc, PluginKind};
use crate::scene::{Error, Result};
use glam::Vec3;

#[derive(Clone, Debug)]
pub struct Homogeneous {
    /// Extinction coefficient (already multiplied by `scale`).
    pub sigma_t: Spectrum,
    pub albedo: Spectrum,
    pub phase: Phase,
    pub sample_emitters: bool,
    pub id: Option<String>,
}

impl Homogeneous {
    pub fn from_desc(obj: &ObjectDesc) -> Result<Homogeneous> {
        if obj.plugin != "homogeneous" {
            return Err(Error::at(
                &obj.pos,
                format!("medium \"{}\" is not supported (supported: homogeneous)", obj.plugin),
            ));
        }
        let props = &obj.props;
        let albedo = props.color("albedo", Vec3::splat(0.75))?;
        let sigma_t = props.color("sigma_t", Vec3::ONE)?;
        let scale = props.float("scale", 1.0)?;
        let sample_emitters = props.bool("sample_emitters", true)?;
        let phase = match props.object_of(PluginKind::Phase)? {
            Some(p) => Phase::from_desc(&p)?,
            None => Phase::Isotropic,
        };
        if albedo.min_element() < 0.0 || albedo.max_element() > 1.0 {
            return Err(props.error("albedo", "homogeneous: albedo must lie in [0, 1]"));
        }
        if sigma_t.min_element() < 0.0 || !(scale >= 0.0 && scale.is_finite()) {
            return Err(props.error("sigma_t", "homogeneous: sigma_t and scale must be non-negative"));
        }
        props.finish()?;
        Ok(Homogeneous { sigma_t: sigma_t * scale, albedo, phase, sample_emitters, id: obj.id.clone() })
    }
}

impl Homogeneous {
    /// Free-flight distance sampled in colour channel `channel` (Mitsuba's `sample_interaction`):
    /// `t = −ln(1 − u) / σt[channel]`; infinite when σt[channel] = 0.
    #[inline]
    pub fn sample_distance(&self, u: f32, channel: usize) -> f32 {
        let s = self.sigma_t[channel];
        if s > 0.0 {
            -(1.0 - u).ln() / s
        } else {
            f32::INFINITY
        }
    }

    /// Transmittance over distance `t`.
    #[inline(always)]
    pub fn transmittance(&self, t: f32) -> Spectrum {
        crate::math::fast::exp3(-self.sigma_t * t)
    }

    #[inline]
    pub fn sigma_s(&self) -> Spectrum {
        self.sigma_t * self.albedo
    }
}
