//! Densities of a suffix `x_i → x_j → x_k → emitter` (docs/snee.md §2.5 and §3): SNEE's own
//! (`pdf_snee`, the answer SNEE gives when another technique made the suffix), and forward
//! tracing's, in the common measure of §1.

use super::distance::DistanceSampler;
use super::options::Snee;
use super::rate::mixture;
use super::{with_wi, Boundary, LightSample, SneeSuffix};
use crate::bsdf::fresnel::fresnel;
use crate::bsdf::{BsdfContext, TransportMode};
use crate::math::INV_FOUR_PI;
use crate::scene::world::Scene;

/// Densities of one suffix under every technique, in the common measure of docs/snee.md §1.
#[derive(Clone, Copy, Debug, Default)]
pub struct SuffixPdfs {
    /// `pdf_snee` (0 outside SNEE's support).
    pub snee: f64,
    /// `p_fwd · p_light(omega_l)`: forward NEE at a rough `x_k` (0 at a smooth one).
    pub fwd_nee: f64,
    /// `p_fwd · bsdf.pdf(omega_kj → omega_l)` at a rough `x_k`, `p_fwd · (1 − F)` at a smooth one
    /// (0 for delta emitters, which cannot be hit).
    pub fwd_bsdf: f64,
}

/// SNEE's density of a suffix (docs/snee.md §2.5) times the rate `r` of running SNEE at `x_i`,
/// given that it lies in SNEE's support (visibility is the caller's business).
pub fn pdf_snee(scene: &Scene, snee: &Snee, s: &SneeSuffix, light: &LightSample, channel: usize) -> f64 {
    let si_k = &s.si_k;
    let Some(boundary) = Boundary::of(scene.bsdf(si_k)) else { return 0.0 };
    let m = &scene.media[s.x_i.medium as usize];
    let st = m.sigma_t[channel];
    let (c_down, c_up) = mixture(snee, boundary);

    // Probe (Eq. 5), area measure.
    let v_ik = si_k.p - s.x_i.p;
    let d_ik2 = v_ik.length_squared() as f64;
    let omega_ik = v_ik.normalize();
    let pdf_probe = INV_FOUR_PI as f64 * omega_ik.dot(si_k.n).abs() as f64 / d_ik2;

    // ↓ (Eq. 6).
    let v_kj = s.x_j - si_k.p;
    let t_kj = v_kj.length();
    let omega_in = v_kj / t_kj;
    let pdf_t_down = DistanceSampler::new(si_k.p, omega_in, s.x_i.p, st).map_or(0.0, |d| d.pdf(t_kj)) as f64;
    let p_light = light.p_light as f64;
    let t_kj2 = (t_kj as f64) * (t_kj as f64);
    let pdf_down = match boundary {
        Boundary::Rough => {
            let si = with_wi(si_k, light.omega_l);
            let p_bsdf_imp =
                scene.bsdf(si_k).pdf(&BsdfContext::new(TransportMode::Importance), &si, si.to_local(omega_in));
            p_light * p_bsdf_imp as f64 * pdf_t_down / t_kj2
        }
        Boundary::Smooth { eta } => {
            // dω_in/dω_l = |cos θ_l| / (η² |cos θ_in|). With a delta emitter this is the 1-D
            // density p_light·pdf_t divided by the t²·dω_in/dω_l that the integrand gains when
            // the Dirac is integrated out (docs/snee.md §2.3): the same expression.
            let cos_l = si_k.to_local(light.omega_l).z.abs() as f64;
            let cos_in = si_k.to_local(omega_in).z.abs() as f64;
            let jacobian = cos_l / ((eta as f64) * (eta as f64) * cos_in);
            p_light * pdf_t_down / (t_kj2 * jacobian)
        }
    };

    // ↑ (Eq. 7).
    let pdf_up = match boundary {
        Boundary::Smooth { .. } if light.delta => 0.0,
        _ => {
            let v_ij = s.x_j - s.x_i.p;
            let t_ij = v_ij.length();
            let omega_ij = v_ij / t_ij;
            let pdf_t_up = DistanceSampler::new(s.x_i.p, omega_ij, si_k.p, st).map_or(0.0, |d| d.pdf(t_ij)) as f64;
            let p = m.phase.eval(s.x_i.wi, omega_ij) as f64 * pdf_t_up / ((t_ij as f64) * (t_ij as f64));
            match boundary {
                Boundary::Rough => p * p_light,
                Boundary::Smooth { .. } => p,
            }
        }
    };
    let p = s.x_i.rate as f64 * pdf_probe * (c_down as f64 * pdf_down + c_up as f64 * pdf_up);
    if p.is_finite() {
        p
    } else {
        0.0
    }
}

/// All techniques' densities of a suffix in the common measure (docs/snee.md §3).
pub fn suffix_pdfs(scene: &Scene, snee: &Snee, s: &SneeSuffix, light: &LightSample, channel: usize) -> SuffixPdfs {
    let si_k = &s.si_k;
    let bsdf = scene.bsdf(si_k);
    let Some(boundary) = Boundary::of(bsdf) else { return SuffixPdfs::default() };
    let m = &scene.media[s.x_i.medium as usize];
    let st = m.sigma_t[channel] as f64;
    let v_ij = s.x_j - s.x_i.p;
    let t_ij = v_ij.length();
    let omega_ij = v_ij / t_ij;
    let v_jk = si_k.p - s.x_j;
    let d_jk = v_jk.length();
    let omega_jk = v_jk / d_jk;
    let (t_ij, d_jk64) = (t_ij as f64, d_jk as f64);
    // p_fwd(x_j, x_k | x_i): phase, free flight to x_j, phase, survival to x_k.
    let p_fwd = m.phase.eval(s.x_i.wi, omega_ij) as f64 * st * (-st * t_ij).exp() / (t_ij * t_ij)
        * m.phase.eval(-omega_ij, omega_jk) as f64
        * (-st * d_jk64).exp()
        * omega_jk.dot(si_k.n).abs() as f64
        / (d_jk64 * d_jk64);
    let si_kj = with_wi(si_k, -omega_jk);
    let (fwd_nee, fwd_bsdf) = match boundary {
        Boundary::Rough => {
            let p_bsdf = if light.delta {
                0.0
            } else {
                bsdf.pdf(&BsdfContext::default(), &si_kj, si_k.to_local(light.omega_l)) as f64
            };
            (p_fwd * light.p_light as f64, p_fwd * p_bsdf)
        }
        Boundary::Smooth { eta } => {
            let p_refract = if light.delta { 0.0 } else { 1.0 - fresnel(si_kj.wi.z, eta).0 as f64 };
            (0.0, p_fwd * p_refract)
        }
    };
    let finite = |x: f64| if x.is_finite() { x } else { 0.0 };
    SuffixPdfs { snee: pdf_snee(scene, snee, s, light, channel), fwd_nee: finite(fwd_nee), fwd_bsdf: finite(fwd_bsdf) }
}
