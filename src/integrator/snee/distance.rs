//! Distance sampling on a ray for placing the subdivision vertex `x_j` (docs/snee.md §2.2):
//! transmittance sampling in the path's channel, equiangular sampling about a centre point
//! (Kulla & Fajardo 2012), and their one-sample mixture. Untruncated: `t ∈ [0, ∞)`.

use crate::math::Vec3;

/// Below this perpendicular distance (relative to 1 + |t0|) equiangular sampling is degenerate.
const MIN_REL_DISTANCE: f32 = 1e-6;

/// The mixture `pdf_t = c_tr·pdf_tr + c_eq·pdf_eq` on the ray `o + t·d` about the centre `q`.
#[derive(Clone, Copy, Debug)]
pub struct DistanceSampler {
    /// `sigma_t` in the path's channel (`st`).
    pub st: f32,
    /// Parameter of the centre's projection onto the ray.
    pub t0: f32,
    /// Perpendicular distance of the centre from the ray (`D`).
    pub dist: f32,
    /// `θ_a = atan2(−t0, D)`; `θ_b = π/2`.
    pub theta_a: f32,
    /// Mixture weight of transmittance sampling (`c_eq = 1 − c_tr`).
    pub c_tr: f32,
}

impl DistanceSampler {
    /// `None` when neither technique is available (`st = 0` and the centre on the ray).
    #[inline]
    pub fn new(o: Vec3, d: Vec3, q: Vec3, st: f32) -> Option<DistanceSampler> {
        let t0 = (q - o).dot(d);
        let dist = (q - o - t0 * d).length();
        let has_eq = dist > MIN_REL_DISTANCE * (1.0 + t0.abs()) && dist.is_finite();
        let has_tr = st > 0.0 && st.is_finite();
        let c_tr = match (has_tr, has_eq) {
            (true, true) => 0.5,
            (true, false) => 1.0,
            (false, true) => 0.0,
            (false, false) => return None,
        };
        Some(DistanceSampler { st, t0, dist, theta_a: (-t0).atan2(dist), c_tr })
    }

    /// Transmittance density `st·exp(−st·t)`.
    #[inline]
    pub fn pdf_tr(&self, t: f32) -> f32 {
        if self.st > 0.0 && t >= 0.0 {
            self.st * (-self.st * t).exp()
        } else {
            0.0
        }
    }

    /// Equiangular density `D / ((θ_b − θ_a)(D² + (t − t0)²))`.
    #[inline]
    pub fn pdf_eq(&self, t: f32) -> f32 {
        if !(t >= 0.0) || !(self.dist > 0.0) {
            return 0.0;
        }
        let x = t - self.t0;
        self.dist / ((std::f32::consts::FRAC_PI_2 - self.theta_a) * (self.dist * self.dist + x * x))
    }

    /// The mixture density.
    #[inline]
    pub fn pdf(&self, t: f32) -> f32 {
        let mut p = 0.0;
        if self.c_tr > 0.0 {
            p += self.c_tr * self.pdf_tr(t);
        }
        if self.c_tr < 1.0 {
            p += (1.0 - self.c_tr) * self.pdf_eq(t);
        }
        p
    }

    /// Sample `t` from the mixture with one uniform number (reused after the technique choice).
    /// May return `∞` for u at the end of the range (a failed sample).
    #[inline]
    pub fn sample(&self, u: f32) -> f32 {
        if u < self.c_tr {
            let u = u / self.c_tr;
            -(1.0 - u).ln() / self.st
        } else {
            let u = if self.c_tr > 0.0 { (u - self.c_tr) / (1.0 - self.c_tr) } else { u };
            let theta = self.theta_a + u * (std::f32::consts::FRAC_PI_2 - self.theta_a);
            (self.t0 + self.dist * theta.tan()).max(0.0)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// ∫₀^∞ pdf by the substitution t = s/(1−s) (midpoint rule in s).
    fn integral(f: impl Fn(f32) -> f32) -> f64 {
        let n = 200_000;
        (0..n)
            .map(|i| {
                let s = (i as f64 + 0.5) / n as f64;
                let t = s / (1.0 - s);
                f(t as f32) as f64 / ((1.0 - s) * (1.0 - s))
            })
            .sum::<f64>()
            / n as f64
    }

    #[test]
    fn densities_integrate_to_one() {
        for (q, st) in
            [(Vec3::new(0.3, 1.0, 0.0), 2.0), (Vec3::new(0.01, -2.0, 0.0), 0.5), (Vec3::new(1.0, 3.0, 0.0), 0.0)]
        {
            let s = DistanceSampler::new(Vec3::ZERO, Vec3::Y, q, st).unwrap();
            let i_eq = integral(|t| s.pdf_eq(t));
            assert!((i_eq - 1.0).abs() < 2e-3, "eq {}", i_eq);
            if st > 0.0 {
                assert!((integral(|t| s.pdf_tr(t)) - 1.0).abs() < 2e-3);
            }
            assert!((integral(|t| s.pdf(t)) - 1.0).abs() < 2e-3);
        }
    }
}
