//! The manifold connection to a SPHERE light through CURVED smooth boundaries
//! (`manifold/curved_finite.rs`, docs/manifold.md §8.2): smooth-shaded PLY meshes (vertex
//! normals) bounding an HG medium (`common::medium_cube` with the cube replaced by the mesh),
//! lit by a sphere light (hidden from the camera).
//! - GLASS (n = 1.5) pebble (convex) and blob (non-convex): forward tracing reaches the sphere
//!   light through the smooth boundary, so `volpath` converges; `complete` with `snee = mis`
//!   (connection, forward tracing and SNEE under the three-way power heuristic, the connection's
//!   density evaluated by re-solving from each path's seed) and with `snee = forward` (connection
//!   and forward tracing) must agree with it.
//! - INDEX-MATCHED pebble (int_ior = ext_ior = 1): `complete` against `volpath` through the same
//!   mesh with a `null` BSDF (ordinary NEE reaches the light there).
//!
//! Criterion: Welch test on the image mean and 8×8-block means of independent batches, Šidák at
//! family-wise 1 %. Sample counts chosen before the first run: glass 12 × 1024 spp (`volpath`) and
//! 12 × 256 (`complete`), as `manifold_finite.rs`; matched 12 × 64 each.

use crate::common;
use snee::math::{Ray, Vec3};

use common::{render_batches, scene, welch_compare, GLASS, MATCHED};

const SPHERE: &str = r#"<shape type="sphere"><point name="center" x="-2" y="1" z="3"/><float name="radius" value="0.5"/>
        <emitter type="area"><rgb name="radiance" value="20, 20, 20"/></emitter></shape>"#;

// SNEE's rate given: by default SNEE does not run here (docs/snee.md §5), and this test checks
// the three-way MIS with SNEE; `COMPLETE_FORWARD` covers the default (no SNEE).
// The rate is given (these media are optically thin, where the default top rate is lower:
// `technique_weights_sum_to_one_at_the_default_rate` covers it).
const COMPLETE: &str = r#"<string name="connection" value="complete"/><float name="snee_rate" value="0.25"/><float name="connection_rate" value="0.05"/>"#;
const COMPLETE_FORWARD: &str = r#"<string name="connection" value="complete"/><string name="snee" value="forward"/><float name="connection_rate" value="0.05"/>"#;

/// `medium_cube` with the cube replaced by a PLY mesh of `scenes/meshes`, emitters hidden.
fn mesh(integrator: &str, extra: &str, bsdf: &str, file: &str) -> String {
    let props = format!(r#"<boolean name="hide_emitters" value="true"/>{extra}"#);
    common::medium_cube(integrator, &props, bsdf, SPHERE).replace(
        r#"<shape type="cube">"#,
        &format!(r#"<shape type="ply"><string name="filename" value="meshes/{file}"/>"#),
    )
}

fn glass_agrees_with_volpath(file: &str, seed: u64) {
    let volpath = render_batches(&scene(&mesh("volpath", "", GLASS, file), &[]), 12, 1024, 8, seed);
    let mis = render_batches(&scene(&mesh("volpath_snee", COMPLETE, GLASS, file), &[]), 12, 256, 8, seed + 100);
    let fwd = render_batches(&scene(&mesh("volpath_snee", COMPLETE_FORWARD, GLASS, file), &[]), 12, 256, 8, seed + 200);
    common::assert_complete_agrees(&volpath, &mis, &fwd);
}

#[test]
fn sphere_light_through_glass_pebble_agrees_with_volpath() {
    glass_agrees_with_volpath("pebble.ply", 50_000);
}

#[test]
fn sphere_light_through_glass_blob_agrees_with_volpath() {
    glass_agrees_with_volpath("blob.ply", 60_000);
}

/// `complete` at its DEFAULT rates (neither `snee_rate` nor `connection_rate` given) through the
/// glass pebble, a thin medium (σt 2, optical size τ = 2.48): SNEE does not run there
/// (`snee::rate::complete_rates`), and the curved area-light connection's top rate is
/// `curved_finite::default_top_rate`'s `(1/256) / m(τ)` = 0.0106, a fifth of `RATE`, set when the
/// integrator is built; the connection and forward tracing (whose MIS density re-solves at that
/// built rate) must agree with `volpath`. Sample counts fixed before the first run: 12 × 1024 spp
/// for `volpath` (as the glass tests above), 12 × 256 for `complete`; 15 s on the loaded machine.
/// Measured: image means 0.00824 / 0.00870 (red), relative standard errors 2.4 % / 2.1 %, no test
/// failed. Shown to fail: with the forward side's density taken at `RATE` instead of the built
/// rate (`curved_finite::density`'s `q` times `RATE / rate(opts)`), `complete` read 0.00583, 29 %
/// darker, t = 10.2 on the image mean and failures in two blocks.
#[test]
fn default_rates_in_a_thin_medium_agree_with_volpath() {
    use snee::integrator::manifold::{curved_finite::RATE, tables};
    let complete =
        scene(&mesh("volpath_snee", r#"<string name="connection" value="complete"/>"#, GLASS, "pebble.ply"), &[]);
    let q = complete.integrator.snee.connection_rate.expect("a thin medium: a default top rate below RATE");
    let snee = tables(&complete).expect("volpath_snee");
    let tau = snee::integrator::snee::rate::optical_size(&complete, 0);
    eprintln!("optical size {tau}, default top rate {q}");
    assert!((q as f64) < RATE / 4.0, "top rate {q}");
    assert!(snee.rates.iter().all(|r| r.is_none_or(|r| r == 0.0)), "SNEE runs: {:?}", snee.rates);
    // The connection and the forward side's re-solves both run (a 64-spp render's counters).
    let opts = snee::render::RenderOptions { spp: Some(64), seed: 1, time_budget: None, progress: false };
    let stats = snee::render::render(&complete, &opts, &std::sync::atomic::AtomicBool::new(false)).stats;
    assert!(stats.manifold_solutions > 0 && stats.manifold_resolve_matches > 0, "{stats:?}");
    let volpath = render_batches(&scene(&mesh("volpath", "", GLASS, "pebble.ply"), &[]), 12, 1024, 8, 90_000);
    let batches = render_batches(&complete, 12, 256, 8, 90_100);
    assert_eq!(batches.rejected, 0);
    let report = common::agree_with_reference(("volpath", &volpath), &[("complete, default rates", &batches)], 0.01);
    assert!(report.is_empty(), "{report}");
}

#[test]
fn sphere_light_through_matched_pebble_agrees_with_null_boundary() {
    let volpath =
        render_batches(&scene(&mesh("volpath", "", r#"<bsdf type="null"/>"#, "pebble.ply"), &[]), 12, 64, 8, 70_000);
    let complete =
        render_batches(&scene(&mesh("volpath_snee", COMPLETE, MATCHED, "pebble.ply"), &[]), 12, 64, 8, 70_100);
    assert_eq!(complete.rejected, 0);
    let (report, m_vp, m_c) = welch_compare(&volpath, &complete, 0.01);
    eprintln!(
        "volpath (null pebble) {m_vp:?} ({:.2} %)\ncomplete (matched pebble) {m_c:?} ({:.2} %)",
        100.0 * common::rel_std_error(&volpath),
        100.0 * common::rel_std_error(&complete)
    );
    assert!(report.is_empty(), "volpath vs complete:\n{report}");
}

/// The three techniques' weights of the same suffix, each computed where that technique would
/// compute it (the connection's own weight; a forward path's weight at the light hit, re-solving
/// from the path's seed; SNEE's weight for its sample), sum to 1 on suffixes the connection
/// samples in the glass pebble (x_i, x_j random inside, `y` from the connection's own emitter
/// sample). 400 attempts, chosen before the first run. History, for honesty: the first version
/// asserted 1e-2 on every suffix and passed at `RATE = 1` (worst 1.8e-3, the connection's weight
/// dominating); at `RATE = 0.1` the worst was 1.6e-2, traced to SNEE's side evaluating `cos θ_y`
/// from the normal of an f32 ray hit on the sphere light, imprecise at grazing angles; the
/// assertion covered `cos θ_y > 0.1` only. Since every side takes the sphere's normal from the
/// light point itself (`curved_finite::light_normal`), the weights must sum to 1 within 1e-6 at
/// every angle, grazing (`cos θ_y ≤ 0.1`) included (the worst of each printed).
#[test]
fn technique_weights_sum_to_one_on_sampled_suffixes() {
    let scene = scene(&mesh("volpath_snee", COMPLETE, GLASS, "pebble.ply"), &[]);
    let mut rng = snee::sampler::Sampler::new(17, 1);
    weights_sum_to_one(&scene, 400, 1e-6, |_| {
        let mut u3 = || Vec3::new(rng.next_1d(), rng.next_1d(), rng.next_1d()) - Vec3::splat(0.5);
        let x_i = u3() * 0.4;
        (x_i, x_i + u3() * 0.3)
    });
}

/// The same at the DEFAULT top rate (no `connection_rate`; SNEE's rate given so that it runs): in
/// this thin pebble the rate is `curved_finite::default_top_rate`'s, set when the integrator is
/// built. The connection and a forward path read it from the built options, SNEE's weight from
/// the scene's; the weights sum to 1 only if both hold the same rate (before the built options
/// were stored in the scene's, SNEE's side read `RATE` here). Same attempts and tolerance as above.
/// Measured: 169 suffixes, all shared, worst |Σw − 1| 9.3e-8 (cos θ_y > 0.1) and 2.2e-7 (grazing);
/// with the scene's options set back to the parsed ones (no rate), 0.64 and 0.65.
#[test]
fn technique_weights_sum_to_one_at_the_default_rate() {
    use snee::integrator::manifold::curved_finite::RATE;
    let xml = r#"<string name="connection" value="complete"/><float name="snee_rate" value="0.25"/>"#;
    let scene = scene(&mesh("volpath_snee", xml, GLASS, "pebble.ply"), &[]);
    let q = scene.integrator.snee.connection_rate.expect("a thin medium: a default top rate below RATE");
    assert!((q as f64) < RATE, "{q}");
    let mut rng = snee::sampler::Sampler::new(17, 1);
    weights_sum_to_one(&scene, 400, 1e-6, |_| {
        let mut u3 = || Vec3::new(rng.next_1d(), rng.next_1d(), rng.next_1d()) - Vec3::splat(0.5);
        let x_i = u3() * 0.4;
        (x_i, x_i + u3() * 0.3)
    });
}

/// The same on the paper's statue under its sphere light (σt 34), where the procedure's seeds find
/// several distinct solutions at many vertices (each weighed at its three places). Medium vertices `x_j` uniform in the statue with
/// optical depth below 3 towards the light's centre (where the connection finds solutions), `x_i`
/// within 0.02 of it. (First tried on the non-convex blob of the tests above: 0 of 400 attempts
/// found two solutions there.)
/// Ignored: 4.5 minutes on the idle machine. Sample counts, for honesty: 100 attempts with at least
/// 5 connections with several solutions asserted found 4 and failed the count; the attempts were
/// raised to 400 (24 such connections, 160 suffixes), the count kept at 5. Worst |Σw − 1|: 4.6e-6
/// (cos θ_y > 0.1), 2.8e-6 (grazing), asserted below [`STATUE_ROUNDING`]. SNEE rebuilds
/// `x_j → x_k` from two f32 points, so its look-up of the connection's density allows their
/// rounding (`curved_finite::direction_tolerance`); without that allowance one suffix's SNEE weight
/// leaves the density out and the sum is off by 1.07e-3.
#[test]
#[ignore]
fn technique_weights_sum_to_one_on_the_statue_with_several_solutions() {
    use crate::manifold_curved_statue::inside_point;
    let scene = statue_scene(34.0, COMPLETE);
    let center = Vec3::new(28.6788, 81.9152, 49.6732);
    let mut rng = snee::sampler::Sampler::new(13, 1);
    let mut u = move || rng.next_1d() as f64;
    let multi = weights_sum_to_one(&scene, 400, STATUE_ROUNDING, |_| loop {
        let x_j = inside_point(&scene, &mut u);
        let to_c = (center - x_j).normalize();
        let Some(si) = scene.ray_intersect(&Ray::new(x_j, to_c)) else { continue };
        if si.t * 34.0 > 3.0 {
            continue;
        }
        let d = Vec3::new(u() as f32, u() as f32, u() as f32) - Vec3::splat(0.5);
        return (x_j + d * 0.04, x_j);
    });
    assert!(multi >= 5, "{multi} connections with several solutions on the statue");
}

/// The weights' tolerance on the statue: SNEE's direction rebuilt from f32 points ~100 units from
/// the origin, `x_k` a few hundredths from `x_j`, turns by up to ~1e-4 rad, and its densities by up
/// to ~1e-5 relative (the pebble, coordinates below 1, keeps 1e-6).
const STATUE_ROUNDING: f64 = 1e-5;

/// The paper's statue under its sphere light (`scenes/paper/sphere_smooth_st34.xml`) at `sigma_t`,
/// `volpath_snee` with the integrator properties `props`.
fn statue_scene(sigma_t: f64, props: &str) -> snee::scene::world::Scene {
    let xml = std::fs::read_to_string(common::root().join("scenes/paper/sphere_smooth_st34.xml")).unwrap();
    let xml = xml
        .replace(r#"<integrator type="$integrator">"#, &format!(r#"<integrator type="volpath_snee">{props}"#))
        .replace(r#"value="statue.ply""#, r#"value="paper/statue.ply""#)
        .replace(r#"<float name="sigma_t" value="34"/>"#, &format!(r#"<float name="sigma_t" value="{sigma_t}"/>"#));
    common::scene(&xml, &[])
}

/// The check of the tests above on `scene` (its only emitter a sphere light), with `(x_i, x_j)`
/// drawn by `vertices` (given the attempt's index); returns how many connections found several
/// solutions.
fn weights_sum_to_one(
    scene: &snee::scene::world::Scene,
    attempts: u32,
    tolerance: f64,
    mut vertices: impl FnMut(u32) -> (Vec3, Vec3),
) -> u32 {
    use snee::integrator::manifold::{curved_finite, finite, MediumVertex};
    use snee::integrator::snee::SneeVertex;
    use snee::integrator::stats::LocalStats;
    use snee::interaction::{offset_origin, spawn_ray_between};
    use snee::math::{Ray, Vec2};
    // The options as the renderer's stages read them (the built `Snee`'s; SNEE's weight reads the
    // scene's, which must be the same).
    let opts = match &scene.integrator {
        snee::integrator::desc::Integrator::VolpathSnee(_, s) => s.options,
        _ => panic!("not volpath_snee"),
    };
    let mut rng = snee::sampler::Sampler::new(11, 1);
    let (mut multi, mut missed) = (0, 0);
    let mut stats = LocalStats::default();
    let (mut checked, mut shared, mut hidden, mut worst, mut worst_grazing) = (0, 0, 0, 0.0f64, 0.0f64);
    for attempt in 0..attempts {
        let (p_i, p_j) = vertices(attempt);
        let wi = Vec3::new(rng.next_1d(), rng.next_1d(), rng.next_1d()) - Vec3::splat(0.5);
        let x_i = SneeVertex { p: p_i, wi: wi.normalize(), medium: 0, rate: 1.0 };
        let x_j = MediumVertex { p: p_j, wi: (x_i.p - p_j).normalize(), medium: 0 };
        let finite::Pick::Finite(lp) = finite::pick(scene, Vec2::new(rng.next_1d(), rng.next_1d())) else {
            panic!("the sphere light is the only emitter")
        };
        let connections = curved_finite::connect(scene, opts, Some(&x_i), &x_j, &lp, 0.0, 0, &mut stats);
        multi += (connections.len() > 1) as u32;
        for c in connections {
            // The forward path: the same suffix, the light hit along the refracted direction.
            let omega_l = c.light.omega_l;
            // (On the statue the f32 ray from `x_k` can miss the small light at its rim: skipped, counted.)
            let Some(mut hit) = scene.ray_intersect(&Ray::new(offset_origin(c.si_k.p, c.si_k.n, omega_l), omega_l))
            else {
                missed += 1;
                continue;
            };
            // The same suffix: the sampled point (the f32 hit differs from it by ~1e-6, which moves
            // `G` by up to 1.6 % next to a caustic, a different path). The hit's own normal is kept:
            // every side takes the sphere's normal from the light point (`curved_finite::light_normal`).
            hit.p = lp.y;
            let pending = curved_finite::Pending { x_i: Some(x_i), x_j, si_k: c.si_k, omega_jk: c.omega };
            let w_fwd =
                curved_finite::forward_weight(scene, opts, &pending, &hit, omega_l, 0, &mut stats).unwrap() as f64;
            // SNEE makes the suffix only when x_k is visible from x_i (its probe's first hit); x_i can
            // lie outside the inscribed mesh near its facets, and then SNEE's weight is not defined.
            let inner_k = offset_origin(c.si_k.p, c.si_k.n, x_i.p - c.si_k.p);
            if scene.ray_test(&spawn_ray_between(x_i.p, inner_k)) {
                hidden += 1;
                continue;
            }
            let suffix = snee::integrator::snee::SneeSuffix { x_i, x_j: x_j.p, si_k: c.si_k };
            let w_snee = curved_finite::snee_weight(scene, opts.technique, &suffix, &c.light, 0).unwrap();
            let sum = c.weight + w_fwd + w_snee;
            let cos_y = -lp.area.expect("an area light").0.dot(omega_l);
            if cos_y > 0.1 {
                worst = worst.max((sum - 1.0).abs());
            } else {
                worst_grazing = worst_grazing.max((sum - 1.0).abs());
            }
            checked += 1;
            shared += (c.weight < 0.99 && (w_fwd > 0.01 || w_snee > 0.01)) as u32;
        }
    }
    eprintln!("{checked} suffixes ({hidden} with x_k hidden from x_i skipped, {missed} whose f32 ray missed the light), {shared} shared (no weight above 0.99), {multi} connections with several solutions; worst |Σw − 1| = {worst:.2e} (cos θ_y > 0.1), {worst_grazing:.2e} (grazing)");
    assert!(checked > attempts / 8 && shared > 5, "too few suffixes checked ({checked}, {shared} shared)");
    assert!(worst < tolerance && worst_grazing < tolerance, "weights sum to 1 ± {worst} (grazing ± {worst_grazing})");
    multi
}

/// SNEE's default rate under `connection = complete` (docs/snee.md §5, `snee::rate::complete_rates`):
/// 0 in the glass pebble lit by the sphere light only (the curved area-light connection serves it),
/// and under an environment 0 when the medium is optically thin, the shared rate when thick; the
/// paper's estimator, a given `snee_rate` and a delta light keep their rates.
#[test]
fn default_snee_rate_under_complete() {
    let rate = |xml: &str| {
        let s = scene(xml, &[]);
        snee::integrator::manifold::tables(&s).expect("volpath_snee").rates[0]
    };
    let complete = r#"<string name="connection" value="complete"/>"#;
    let sphere = mesh("volpath_snee", complete, GLASS, "pebble.ply");
    assert_eq!(rate(&sphere), Some(0.0));
    assert_eq!(rate(&mesh("volpath_snee", "", GLASS, "pebble.ply")), Some(snee::integrator::snee::AUTO_RATE_SHARED));
    assert_eq!(rate(&mesh("volpath_snee", COMPLETE, GLASS, "pebble.ply")), Some(0.25));
    let env = r#"<emitter type="constant"><rgb name="radiance" value="1, 1, 1"/></emitter>"#;
    let with_env = |sigma_t: &str| {
        sphere
            .replace(SPHERE, env)
            .replace(r#"<float name="sigma_t" value="2"/>"#, &format!(r#"<float name="sigma_t" value="{sigma_t}"/>"#))
    };
    assert_eq!(rate(&with_env("0.1")), Some(0.0));
    assert_eq!(rate(&with_env("1000")), Some(snee::integrator::snee::AUTO_RATE_SHARED));
    let sun = r#"<emitter type="directional"><vector name="direction" x="0" y="0" z="-1"/></emitter>"#;
    assert_eq!(rate(&sphere.replace(SPHERE, sun)), Some(1.0));
}

/// `connection_rate` outside (0, 1] is an error with its position, not a panic.
#[test]
fn connection_rate_out_of_range_is_an_error() {
    for q in ["0", "1.5", "-1"] {
        let props =
            format!(r#"<string name="connection" value="complete"/><float name="connection_rate" value="{q}"/>"#);
        let text = mesh("volpath_snee", &props, GLASS, "pebble.ply");
        let parsed = snee::scene::xml::parse_str(&text, "q.xml", &common::root().join("scenes"), &[]).unwrap();
        let err = snee::scene::build::build_scene(&parsed).err().expect("connection_rate must be rejected");
        let s = err.to_string();
        assert!(s.starts_with("q.xml:") && s.contains("connection_rate must be in (0, 1]"), "{}", s);
    }
}

/// How often the connection's deterministic procedure (`newton_point::solve_distinct`) finds the
/// suffix a FORWARD path made, on the paper's statue under its sphere light
/// (`scenes/paper/sphere_smooth_st34.xml`; σt from `STATUE_SIGMA_T`, default 34): a forward hit
/// the procedure misses keeps MIS weight 1 (docs/manifold.md §8.2), a firefly of `L_e` ≈ 900.
/// Medium vertices uniform in the medium (those with optical depth below 3 towards the light's
/// centre), directions uniform in the cone of half-angle 70° around the light's centre, traced to
/// the boundary, refracted about the interpolated normal in closed form, and kept when the
/// refracted ray hits the light's front; each such suffix weighs `e^{−σt d_jk}`. Printed per
/// seed set (the first seed; chains of 2–4 refracted seeds; the first and a ring of 8; the exact
/// forward direction, which shows every suffix is reachable; the procedure itself): the weighted
/// share of suffixes whose solution is among the set's distinct solutions, and its mean solves and
/// rays per call; and the first seed's misses by cause (no seed, another solution, lost, not
/// converged). Ignored: a measurement (4–15 min on the shared machine), no assertion.
#[test]
#[ignore]
fn diagnose_statue_forward_suffixes_found() {
    use crate::manifold_curved_statue::inside_point;
    use snee::integrator::manifold::locate::{boundary_patch, SceneLocate};
    use snee::integrator::manifold::newton::Failure;
    use snee::integrator::manifold::newton_point::{
        point_seed, refracted_seed_along, solve_distinct, solve_point, SEEDS,
    };
    use snee::math::{DVec3, Ray, Vec3};
    let sigma_t: f64 = std::env::var("STATUE_SIGMA_T").ok().and_then(|s| s.parse().ok()).unwrap_or(34.0);
    // STATUE_PROCEDURE_ONLY set: only the procedure's row (about a tenth of the time).
    let procedure_only = std::env::var("STATUE_PROCEDURE_ONLY").is_ok();
    let xml = std::fs::read_to_string(common::root().join("scenes/paper/sphere_smooth_st34.xml")).unwrap();
    let xml = xml
        .replace(
            r#"<integrator type="$integrator">"#,
            r#"<integrator type="volpath_snee"><string name="connection" value="complete"/>"#,
        )
        .replace(r#"value="statue.ply""#, r#"value="paper/statue.ply""#)
        .replace(r#"<float name="sigma_t" value="34"/>"#, &format!(r#"<float name="sigma_t" value="{sigma_t}"/>"#));
    let scene = common::scene(&xml, &[]);
    let center = Vec3::new(28.6788, 81.9152, 49.6732);
    // Seed sets, each tried in full (every distinct converged solution kept): the first seed; the
    // chain of refracted seeds along the previous seed (`refracted_seed_along`); the first seed and
    // a ring of 8 at 0.1 rad; the exact forward direction (reachability).
    // STATUE_EXTRA_RING="R N": one more set, the procedure's seeds and a second ring of N seeds at
    // R rad around the first (a candidate procedure).
    const SETS: usize = 8;
    let names = ["first", "chain 2", "chain 3", "chain 4", "first + ring 8", "exact w (reach)", "procedure", "+ ring"];
    let extra: Option<(f64, usize)> = std::env::var("STATUE_EXTRA_RING").ok().map(|s| {
        let v: Vec<&str> = s.split_whitespace().collect();
        (v[0].parse().unwrap(), v[1].parse().unwrap())
    });
    let sets =
        if procedure_only { 6..if extra.is_some() { 8 } else { 7 } } else { 0..if extra.is_some() { 8 } else { 7 } };
    let mut rng = snee::sampler::Sampler::new(7, 1);
    let mut u = move || rng.next_1d() as f64;
    let (mut total, mut hits, mut solutions) = (0.0f64, 0u32, 0u64);
    let mut found = [0.0f64; SETS];
    let mut cost = [(0u64, 0u64); SETS];
    // The first seed's outcome on the suffixes it misses: no seed, another solution, lost, not converged.
    let mut cause = [0.0f64; 4];
    let cos_max = 70f64.to_radians().cos();
    let mut vertices = 0;
    while vertices < 300 {
        let x_j = inside_point(&scene, &mut u);
        let to_c = (center - x_j).normalize();
        let Some(si) = scene.ray_intersect(&Ray::new(x_j, to_c)) else { continue };
        if si.t as f64 * sigma_t > 3.0 {
            continue;
        }
        vertices += 1;
        let c = to_c.as_dvec3();
        let (t1, t2) = snee::integrator::manifold::newton::tangents(c);
        for _ in 0..4000 {
            let z = 1.0 - u() * (1.0 - cos_max);
            let phi = 2.0 * std::f64::consts::PI * u();
            let r = (1.0 - z * z).sqrt();
            let w = (c * z + t1 * (r * phi.cos()) + t2 * (r * phi.sin())).normalize();
            let Some(si) = scene.ray_intersect(&Ray::new(x_j, w.as_vec3())) else { continue };
            let Some(patch) = boundary_patch(&scene, &si, 0, w.as_vec3()) else { continue };
            let Some(rf) = patch.refract(x_j.as_dvec3(), w) else { continue };
            let o = rf.o.as_vec3();
            let start = snee::interaction::offset_origin(si.p, si.n, o);
            let Some(hit) = scene.ray_intersect(&Ray::new(start, o)) else { continue };
            if scene.shapes[hit.shape as usize].emitter.is_none() || hit.n.dot(o) >= 0.0 {
                continue;
            }
            let y: DVec3 = hit.p.as_dvec3();
            let x = x_j.as_dvec3();
            let weight = (-sigma_t * rf.t).exp();
            total += weight;
            hits += 1;
            for v in sets.clone() {
                let mut locate = SceneLocate { scene: &scene, medium: 0, rays: 0 };
                let first = point_seed(&mut locate, x, y);
                let mut seeds: Vec<DVec3> = Vec::new();
                match v {
                    0..=3 => {
                        let mut s = first;
                        for _ in 0..=v {
                            let Some(d) = s else { break };
                            seeds.push(d);
                            s = refracted_seed_along(&mut locate, x, y, d);
                        }
                    }
                    4 => {
                        if let Some(f) = first {
                            seeds.push(f);
                            let t = snee::integrator::manifold::newton::tangents(f);
                            for i in 0..8 {
                                let a = i as f64 * std::f64::consts::FRAC_PI_4;
                                seeds.push(snee::integrator::manifold::newton::moved(
                                    f,
                                    t,
                                    0.1 * a.cos(),
                                    0.1 * a.sin(),
                                ));
                            }
                        }
                    }
                    7 => {
                        let (radius, count) = extra.unwrap();
                        let mut s = first;
                        for _ in 0..4 {
                            let Some(d) = s else { break };
                            seeds.push(d);
                            s = refracted_seed_along(&mut locate, x, y, d);
                        }
                        if let Some(f) = first {
                            let t = snee::integrator::manifold::newton::tangents(f);
                            for (r, n) in [(0.1, 8), (radius, count)] {
                                for i in 0..n {
                                    let a = i as f64 * std::f64::consts::TAU / n as f64;
                                    seeds.push(snee::integrator::manifold::newton::moved(
                                        f,
                                        t,
                                        r * a.cos(),
                                        r * a.sin(),
                                    ));
                                }
                            }
                        }
                    }
                    _ => seeds.push(w),
                }
                if v == 6 {
                    let d = solve_distinct(&mut locate, x, y, first, SEEDS);
                    cost[v].0 += d.solves as u64;
                    cost[v].1 += locate.rays;
                    if d.solutions.iter().any(|s| (s.omega - w).length() < 1e-4) {
                        found[v] += weight;
                    }
                    solutions += d.solutions.len() as u64;
                    continue;
                }
                let mut sols: Vec<DVec3> = Vec::new();
                let mut first_outcome = 0;
                for (k, &sd) in seeds.iter().enumerate() {
                    cost[v].0 += 1;
                    let r = solve_point(&mut locate, x, y, sd);
                    if k == 0 {
                        first_outcome = match r {
                            Ok(s) if (s.omega - w).length() < 1e-4 => 4,
                            Ok(_) => 1,
                            Err((Failure::Lost, _)) => 2,
                            Err((Failure::NoConvergence, _)) => 3,
                        };
                    }
                    if let Ok(s) = r {
                        if sols.iter().all(|o| (*o - s.omega).length() >= 1e-4) {
                            sols.push(s.omega);
                        }
                    }
                }
                cost[v].1 += locate.rays;
                if sols.iter().any(|o| (*o - w).length() < 1e-4) {
                    found[v] += weight;
                }
                if v == 0 && first_outcome != 4 {
                    cause[if seeds.is_empty() { 0 } else { first_outcome }] += weight;
                }
            }
        }
    }
    eprintln!("σt {sigma_t}: {vertices} vertices, {hits} forward suffixes reaching the light");
    for v in sets {
        eprintln!(
            "{:>16}: found {:.1} % of the weighted suffixes; {:.2} solves, {:.1} rays per call",
            names[v],
            100.0 * found[v] / total,
            cost[v].0 as f64 / hits as f64,
            cost[v].1 as f64 / hits as f64
        );
    }
    eprintln!("procedure: {:.2} distinct solutions per call", solutions as f64 / hits as f64);
    eprintln!(
        "first seed's misses ({:.1} %): no seed {:.1} %, another solution {:.1} %, lost {:.1} %, not converged {:.1} %",
        100.0 * cause.iter().sum::<f64>() / total,
        100.0 * cause[0] / total,
        100.0 * cause[1] / total,
        100.0 * cause[2] / total,
        100.0 * cause[3] / total
    );
}
