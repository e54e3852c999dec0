//! Where SNEE runs, and how often (docs/snee.md §5): the per-medium rate `r` and the mixture of
//! ↓ and ↑, computed once at scene load ([`build`]), and the SNEE vertex `x_i` of a scatter.

use super::options::{Snee, SneeOptions};
use super::{Boundary, SneeVertex};
use crate::math::Vec3;
use crate::scene::world::{Scene, SceneEmitter};

/// `volpath_snee`'s tables for `scene` (docs/snee.md §5 and §2.5).
pub fn build(scene: &Scene, options: SneeOptions) -> Snee {
    let has_non_delta_emitter = scene.emitters.iter().any(|e| match e {
        SceneEmitter::Area { .. } => true,
        SceneEmitter::Other(e) => !e.is_delta(),
    });
    Snee {
        options,
        rates: medium_rates(scene, options),
        has_non_delta_emitter,
        flat: Vec::new(),
        rough: Vec::new(),
        curved: Vec::new(),
        records: Default::default(),
        forward_only: false,
        has_directional: false,
        meter_glint: None,
        camera: None,
        split: None,
        beams: Vec::new(),
        camera_beams: false,
    }
}

/// Per medium of `scene`: `None` where SNEE does not apply (the medium does not sample emitters,
/// or no dielectric/roughdielectric shape encloses it), else the SNEE rate `r` (`snee_rate`, or
/// [`auto_rate`]).
pub fn medium_rates(scene: &Scene, opts: SneeOptions) -> Vec<Option<f32>> {
    (0..scene.media.len() as u32)
        .map(|medium| {
            let boundaries: Vec<Boundary> = scene
                .shapes
                .iter()
                .filter(|s| s.interior == Some(medium) && s.exterior.is_none())
                .filter_map(|s| Boundary::of(&scene.bsdfs[s.bsdf as usize]))
                .collect();
            if boundaries.is_empty() || !scene.media[medium as usize].sample_emitters {
                return None;
            }
            Some(opts.rate.unwrap_or_else(|| auto_rate(scene, &boundaries)))
        })
        .collect()
}

/// SNEE rate where SNEE is an extra technique beside a forward one (docs/snee.md §5).
pub const AUTO_RATE_SHARED: f32 = 0.25;

/// The default SNEE rate of a medium enclosed by `boundaries` (docs/snee.md §5):
/// - 1 when some boundary is smooth and the scene has a delta emitter: then SNEE is the only
///   technique for that light's suffixes (forward tracing cannot hit a delta emitter through a
///   delta interface), and every SNEE sample pays for itself;
/// - otherwise [`AUTO_RATE_SHARED`]: forward tracing also produces every suffix (BSDF or emitter
///   sampling at `x_k`), and SNEE costs about 4 rays (probe, light segment, two visibility tests)
///   against volpath's ~2 per medium vertex. Measured on the paper configurations (statue, equal
///   time 5–6 s, 1 thread, 2–3 seeds, efficiency over volpath): envmap GGX 0.2 0.93–0.96 at
///   r = 0.25 vs 0.85–0.86 at r = 1; GGX 0.04 1.20–1.27 vs 0.79–1.08; sphere light + smooth 1.09 vs
///   0.86 (r = 0.1 was within noise of 0.25).
pub fn auto_rate(scene: &Scene, boundaries: &[Boundary]) -> f32 {
    let smooth = boundaries.iter().any(|b| matches!(b, Boundary::Smooth { .. }));
    let delta_light = scene.emitters.iter().any(|e| matches!(e, SceneEmitter::Other(e) if e.is_delta()));
    if smooth && delta_light {
        1.0
    } else {
        AUTO_RATE_SHARED
    }
}

/// SNEE rate under `connection = complete` in a medium whose curved smooth boundary the
/// area-light connection (`manifold/curved_finite.rs`) serves, in a scene lit by area lights only
/// (docs/snee.md §5): 0, SNEE does not run there. The connection and forward tracing make every
/// suffix SNEE would make, and SNEE's MIS weight re-solves the connection's Newton problem for
/// each of its samples. Measured on `sphere_smooth_st34` / `st02` (docs/snee.md §5): r = 0 with
/// `q = 0.05` 1.48× / 0.90× `volpath` (median of per-seed ratios, absolute variance) against
/// 1.25× / 0.72× for r = 0.25 with `q = 0.1`.
pub const AUTO_RATE_COMPLETE_AREA: f32 = 0.0;

/// Optical size below which SNEE does not run under `connection = complete` in a medium behind a
/// smooth boundary under non-delta lights (docs/snee.md §5): there few paths reach the boundary
/// after two medium vertices and SNEE's samples cost more than they bring.
pub const THIN_OPTICAL_SIZE: f32 = 4.0;

/// Is `medium` optically thin ([`optical_size`] below [`THIN_OPTICAL_SIZE`])? Where SNEE, the rough
/// connection's full rate and the curved area-light connection give way under `complete`.
pub fn optically_thin(scene: &Scene, medium: u32) -> bool {
    optical_size(scene, medium) < THIN_OPTICAL_SIZE
}

/// The optical size of `medium`: its smallest extinction coefficient (over channels) times the
/// shortest side of the bounding box of the shapes that enclose it.
pub fn optical_size(scene: &Scene, medium: u32) -> f32 {
    let mut lo = Vec3::splat(f32::INFINITY);
    let mut hi = Vec3::splat(f32::NEG_INFINITY);
    for s in scene.shapes.iter().filter(|s| s.interior == Some(medium) && s.exterior.is_none()) {
        let b = s.bounds();
        lo = lo.min(b.min);
        hi = hi.max(b.max);
    }
    let side = (hi - lo).min_element().max(0.0);
    scene.media[medium as usize].sigma_t.min_element() * side
}

/// The curved area-light connection's mean rate (docs/manifold.md §8.2, "Thin media"): its expected
/// attempts per medium vertex for vertices spread evenly through the medium, which
/// `manifold::curved_finite::default_top_rate` holds fixed across optical sizes. An attempt costs
/// up to ~100 ray casts (the Newton solves from `newton_point::SEEDS` seeds and their verification, §8.2), so 1/256 keeps its expected cost
/// under half a ray cast per vertex, against volpath's ~2 per sample. Chosen from that cost, not from
/// renders; in a thick medium (`τ` ≥ ~15) the top rate it gives reaches `curved_finite::RATE` and
/// `RATE` stands.
pub const CONNECTION_MEAN_RATE: f64 = 1.0 / 256.0;

/// `m(τ) = (1 − e^{−τ})/τ`: the mean of `e^{−σ_t t}` for `t` uniform along a chord of optical length
/// `τ` (1 at `τ` = 0; `1/τ` for large `τ`); `τ ≤ 0` gives 1.
pub fn mean_depth_factor(tau: f64) -> f64 {
    if tau < 1e-6 {
        return 1.0;
    }
    -(-tau).exp_m1() / tau
}

/// With `connection = complete` and no `snee_rate` given: the default rates of [`auto_rate`]
/// revised once the manifold tables in `snee` are built (docs/snee.md §5), from the scene's light
/// types, the medium's boundary kind and its optical size only. SNEE does not run (`r = 0`) in a
/// medium with a CURVED smooth boundary (not one of the flat boundaries of `snee.flat`) when the
/// scene has no delta emitter and either
/// - the curved area-light connection serves the medium and every emitter is an area light
///   ([`AUTO_RATE_COMPLETE_AREA`]), or
/// - the medium is optically thin ([`optical_size`] below [`THIN_OPTICAL_SIZE`]).
///
/// Elsewhere (delta lights; rough or flat boundaries; thick media under an environment) the rates of
/// [`auto_rate`] stand.
pub fn complete_rates(scene: &Scene, snee: &mut Snee) {
    if snee.options.rate.is_some() {
        return;
    }
    let area_only = scene.emitters.iter().all(|e| matches!(e, SceneEmitter::Area { .. }));
    let delta_light = scene.emitters.iter().any(|e| matches!(e, SceneEmitter::Other(e) if e.is_delta()));
    for (m, rate) in snee.rates.iter_mut().enumerate() {
        // Curved: smooth, and no flat boundary the closed-form connections serve.
        let curved = smooth_boundary(scene, m as u32) && snee.flat.get(m).is_none_or(|f| f.is_none());
        if rate.is_none() || delta_light || !curved {
            continue;
        }
        if area_only && snee.curved.get(m).copied().unwrap_or(false) {
            *rate = Some(AUTO_RATE_COMPLETE_AREA);
        } else if optically_thin(scene, m as u32) {
            *rate = Some(0.0);
        }
    }
}

/// Is some boundary enclosing `medium` a smooth `dielectric`?
fn smooth_boundary(scene: &Scene, medium: u32) -> bool {
    scene
        .shapes
        .iter()
        .filter(|s| s.interior == Some(medium) && s.exterior.is_none())
        .any(|s| matches!(Boundary::of(&scene.bsdfs[s.bsdf as usize]), Some(Boundary::Smooth { .. })))
}

/// The SNEE vertex at a real scatter `p` of depth `depth`, or `None` where SNEE does not run
/// (nor need forward suffixes be tracked: rate 0 with all transport kept).
pub fn snee_vertex(snee: &Snee, medium: u32, p: Vec3, wi: Vec3, depth: u32, max_depth: u32) -> Option<SneeVertex> {
    if depth.saturating_add(2) >= max_depth {
        return None;
    }
    let rate = snee.rates.get(medium as usize).copied().flatten()?;
    if rate == 0.0 && snee.options.keeps_all() {
        return None;
    }
    Some(SneeVertex { p, wi, medium, rate })
}

/// Mixture weights `(c_down, c_up)` of Eq. 8 (docs/snee.md §2.5).
#[inline]
pub fn mixture(snee: &Snee, boundary: Boundary) -> (f32, f32) {
    match boundary {
        Boundary::Smooth { .. } if !snee.has_non_delta_emitter => (1.0, 0.0),
        _ => (0.5, 0.5),
    }
}

#[cfg(test)]
mod tests {
    use super::mean_depth_factor;

    /// `m(τ)` is the mean of `e^{−t}` over `t` uniform in `[0, τ]`: checked by a midpoint sum, and
    /// its limits (1 at 0, `1/τ` for large `τ`).
    #[test]
    fn mean_depth_factor_is_the_mean_transmittance() {
        for tau in [1e-3, 0.86, 2.0, 14.6, 100.0] {
            let n = 100_000;
            let sum: f64 = (0..n).map(|i| (-(i as f64 + 0.5) / n as f64 * tau).exp()).sum();
            let m = mean_depth_factor(tau);
            assert!((m - sum / n as f64).abs() < 1e-8 * m.max(1.0), "τ {tau}: {m} vs {}", sum / n as f64);
        }
        assert_eq!(mean_depth_factor(0.0), 1.0);
        assert!((mean_depth_factor(1e4) * 1e4 - 1.0).abs() < 1e-9);
    }
}
