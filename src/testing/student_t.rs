//! Student-t tail probabilities for the batch-based statistical tests (Welch-style t-tests on
//! image, block and pixel means), via the regularized incomplete beta function.

use super::chi2::ln_gamma;

/// Two-sided p-value of `t` with `dof` degrees of freedom: P(|T| ≥ |t|) = I_{dof/(dof+t²)}(dof/2, 1/2).
pub fn t_p_value(t: f64, dof: f64) -> f64 {
    incomplete_beta(0.5 * dof, 0.5, dof / (dof + t * t))
}

/// Regularized incomplete beta I_x(a, b) (continued fraction with the modified Lentz method).
pub fn incomplete_beta(a: f64, b: f64, x: f64) -> f64 {
    if x <= 0.0 {
        return 0.0;
    }
    if x >= 1.0 {
        return 1.0;
    }
    if x > (a + 1.0) / (a + b + 2.0) {
        return 1.0 - incomplete_beta(b, a, 1.0 - x);
    }
    let bt = (ln_gamma(a + b) - ln_gamma(a) - ln_gamma(b) + a * x.ln() + b * (1.0 - x).ln()).exp();
    let tiny = |v: f64| if v.abs() < 1e-300 { 1e-300 } else { v };
    let (qab, qap, qam) = (a + b, a + 1.0, a - 1.0);
    let mut c = 1.0;
    let mut d = 1.0 / tiny(1.0 - qab * x / qap);
    let mut h = d;
    for m in 1..300 {
        let m = m as f64;
        let m2 = 2.0 * m;
        let aa = m * (b - m) * x / ((qam + m2) * (a + m2));
        d = 1.0 / tiny(1.0 + aa * d);
        c = tiny(1.0 + aa / c);
        h *= d * c;
        let aa = -(a + m) * (qab + m) * x / ((a + m2) * (qap + m2));
        d = 1.0 / tiny(1.0 + aa * d);
        c = tiny(1.0 + aa / c);
        let del = d * c;
        h *= del;
        if (del - 1.0).abs() < 1e-12 {
            break;
        }
    }
    bt * h / a
}

#[cfg(test)]
mod tests {
    use super::*;
    #[test]
    fn known_quantiles() {
        // Two-sided 5 % points of Student's t: 2.131 (15 dof), 2.228 (10 dof), 12.706 (1 dof).
        assert!((t_p_value(2.131, 15.0) - 0.05).abs() < 5e-4);
        assert!((t_p_value(2.228, 10.0) - 0.05).abs() < 5e-4);
        assert!((t_p_value(12.706, 1.0) - 0.05).abs() < 5e-4);
        assert!((t_p_value(0.0, 7.0) - 1.0).abs() < 1e-12);
        assert!((incomplete_beta(2.0, 3.0, 0.4) - 0.5248).abs() < 1e-4);
    }
}
