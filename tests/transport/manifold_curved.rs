//! The manifold connection through CURVED smooth boundaries (`manifold/curved.rs`): meshes with
//! interpolated shading normals, under an oblique directional light.
//! - An INDEX-MATCHED smooth `dielectric` pebble (a smooth-shaded convex mesh, int_ior = ext_ior
//!   = 1: a delta interface that blocks shadow rays but does not bend them) of HG medium: the
//!   complete estimator must agree with `volpath` through the same mesh with a `null` BSDF, where
//!   ordinary NEE reaches the light (Welch on image and 8×8-block means, Šidák at 1 %). The
//!   paper's estimator fails the same test (it misses single scattering).
//! - The same pebble and the non-convex blob in GLASS (n = 1.5): the connection alone
//!   (`snee = forward`, Newton on every suffix) against the partition (`snee = mis`: SNEE keeps
//!   the suffixes in its support, the connection the rest). SNEE is an independent technique on
//!   its support, so agreement checks the Newton solution, its beam spread `dω/dω_l` and what the
//!   single seed misses there, through a refracting curved surface.
//!
//! Sample counts chosen before the first run: 12 batches × 64 spp (matched), 12 × 32 (glass).

use crate::common;

use common::{agree_with_reference, render_batches, scene, welch_compare, GLASS, MATCHED};

const DIRECTIONAL: &str = r#"<emitter type="directional"><vector name="direction" value="0.5, 0.4, -0.75"/><rgb name="irradiance" value="3, 3, 3"/></emitter>"#;

/// `medium_cube` with the cube replaced by a PLY mesh (smooth shading normals) of `scenes/meshes`.
fn mesh(integrator: &str, props: &str, bsdf: &str, file: &str) -> String {
    common::medium_cube(integrator, props, bsdf, DIRECTIONAL).replace(
        r#"<shape type="cube">"#,
        &format!(r#"<shape type="ply"><string name="filename" value="meshes/{file}"/>"#),
    )
}

const COMPLETE: &str = r#"<string name="connection" value="complete"/>"#;

#[test]
fn curved_matched_agrees_with_volpath_through_null_boundary() {
    let volpath =
        render_batches(&scene(&mesh("volpath", "", r#"<bsdf type="null"/>"#, "pebble.ply"), &[]), 12, 64, 8, 100);
    let complete = render_batches(&scene(&mesh("volpath_snee", COMPLETE, MATCHED, "pebble.ply"), &[]), 12, 64, 8, 200);
    assert_eq!(complete.rejected, 0);
    let (report, m_vp, m_c) = welch_compare(&volpath, &complete, 0.01);
    eprintln!(
        "volpath (null pebble) {m_vp:?} (rel. s.e. {:.2} %)\ncomplete (matched pebble) {m_c:?} (rel. s.e. {:.2} %)",
        100.0 * common::rel_std_error(&volpath),
        100.0 * common::rel_std_error(&complete)
    );
    assert!(report.is_empty(), "volpath vs complete:\n{report}");
    // The test can fail: the paper's estimator misses the single scattering.
    let paper = render_batches(&scene(&mesh("volpath_snee", "", MATCHED, "pebble.ply"), &[]), 12, 16, 8, 300);
    let (report, _, m_p) = welch_compare(&volpath, &paper, 0.01);
    eprintln!("paper {m_p:?}");
    assert!(!report.is_empty(), "the paper's estimator should disagree with volpath here");
}

/// Glass: the connection alone against SNEE on its support plus the connection elsewhere.
fn glass_techniques_agree(file: &str, seed0: u64) {
    let forward = format!(r#"{COMPLETE}<string name="snee" value="forward"/>"#);
    let alone = render_batches(&scene(&mesh("volpath_snee", &forward, GLASS, file), &[]), 12, 32, 8, seed0);
    let mis = render_batches(&scene(&mesh("volpath_snee", COMPLETE, GLASS, file), &[]), 12, 32, 8, seed0 + 100);
    assert_eq!(alone.rejected + mis.rejected, 0);
    let report = agree_with_reference(("complete snee=forward", &alone), &[("complete snee=mis", &mis)], 0.01);
    assert!(report.is_empty(), "{file}: {report}");
}

#[test]
fn curved_glass_pebble_techniques_agree() {
    glass_techniques_agree("pebble.ply", 400);
}

#[test]
fn curved_glass_blob_techniques_agree() {
    glass_techniques_agree("blob.ply", 600);
}

/// On the paper's statue (σt 2 by default, `STATUE_SIGMA_T`), at fixed medium vertices uniform in
/// its medium: the mean of `curved::connect` (the one-refraction connection under the directional
/// light: SMS trials, f32 verification, light segment) against a brute-force reference of the same
/// one-refraction transport that uses no Newton and no seeds — the shrinking-cone limit of
/// `manifold_curved_cone.rs` (directions uniform in the cone of largest turn at `x_j`, the scene's
/// first hit, refraction about the interpolated normal in closed form, kept within θ of `omega_l`,
/// the light segment traced; the sphere-light limit for that vertex). The cone's energy is split
/// by what Newton does when seeded AT the accepted cone direction (converges to a verified
/// solution; converges but verification rejects; fails), and the connection's runs by outcome
/// (capped trials, rejections), to locate a deficit. Ignored: a measurement (~2–4 min).
/// `STATUE_POINTS` vertices (12), `STATUE_DIRS` = log2 of the cone directions (22).
#[test]
#[ignore]
fn diagnose_statue_one_refraction_against_cone() {
    use crate::manifold_curved_cone::{connection_mean, one_refraction};
    use snee::color::Spectrum;
    use snee::integrator::manifold::locate::SceneLocate;
    use snee::integrator::manifold::newton;
    use snee::integrator::manifold::{curved, MediumVertex};
    use snee::integrator::stats::LocalStats;
    use snee::math::Vec3;
    use snee::sampler::Sampler;

    let env = |k: &str, d: usize| std::env::var(k).ok().and_then(|s| s.parse().ok()).unwrap_or(d);
    let sigma_t = std::env::var("STATUE_SIGMA_T").unwrap_or("2".into());
    let scene = crate::manifold_curved_statue::statue(&sigma_t);
    let (ds, _) = scene.sample_emitter_direction(Vec3::ZERO, None, snee::math::Vec2::new(0.5, 0.5), false);
    let omega_l = ds.d;
    let od = omega_l.as_dvec3();
    let wi = Vec3::Z; // isotropic phase: wi does not matter
    let turn = newton::max_turn(curved::largest_eta(&scene, 0));
    let thetas = [0.02f64, 0.01];
    let cones = thetas.map(|t| std::f64::consts::TAU * (1.0 - t.cos()));
    let (points, n_dirs, runs) = (env("STATUE_POINTS", 12), 1u64 << env("STATUE_DIRS", 22), 4096);
    let mut rng = Sampler::new(17, 1);
    let mut u = move || rng.next_1d() as f64;
    let mut sampler = Sampler::new(18, 1);
    // Totals: cone (per θ) mean and variance, the θ = 0.01 split, the connection mean and variance.
    let (mut cone_t, mut cone_v) = ([0.0f64; 2], [0.0f64; 2]);
    let mut split = [0.0f64; 3]; // solvable + verified, solved but rejected, Newton fails
    let (mut conn_t, mut conn_v) = (0.0f64, 0.0f64);
    let mut stats = LocalStats::default();
    let mut diffs: Vec<(f64, f64)> = Vec::new(); // per vertex: connection − cone, connection − verified part
    let mut verified_v = 0.0f64;
    for k in 0..points {
        let p = crate::manifold_curved_statue::inside_point(&scene, &mut u);
        let x_j = MediumVertex { p, wi, medium: 0 };
        let xd = p.as_dvec3();
        let mut locate = SceneLocate { scene: &scene, medium: 0, rays: 0 };
        let (mut sum, mut sq) = ([0.0f64; 2], [0.0f64; 2]);
        let mut vsplit = [0.0f64; 3];
        let mut vsq = 0.0f64; // second moment of the verified part (its standard error)
        for _ in 0..n_dirs {
            let Some(s) = one_refraction(&scene, p, wi, od, turn, thetas[0].cos(), (u(), u())) else { continue };
            let (w, cos_o, g) = (s.w, s.cos_o, s.g);
            for (i, c) in cones.iter().enumerate() {
                if cos_o >= thetas[i].cos() {
                    sum[i] += g / c;
                    sq[i] += (g / c) * (g / c);
                }
            }
            if cos_o >= thetas[1].cos() {
                let cause = match newton::solve(&mut locate, xd, od, w) {
                    Ok(s) => {
                        let ok =
                            curved::value(&scene, &x_j, &s, omega_l, Spectrum::ONE, 1.0, &mut LocalStats::default());
                        if ok.is_some() {
                            0
                        } else {
                            1
                        }
                    }
                    Err(_) => 2,
                };
                vsplit[cause] += g / cones[1] / n_dirs as f64;
                if cause == 0 {
                    vsq += (g / cones[1]) * (g / cones[1]);
                }
            }
        }
        let n = n_dirs as f64;
        let cm = sum.map(|s| s / n);
        let cv = [0, 1].map(|i| (sq[i] / n - cm[i] * cm[i]).max(0.0) / n);
        let before = (stats.manifold_trials_capped, stats.manifold_solutions, stats.manifold_failures);
        let (mean, var) = connection_mean(&scene, &x_j, omega_l, runs, &mut sampler, &mut stats);
        let vvar = (vsq / n - vsplit[0] * vsplit[0]).max(0.0) / n;
        diffs.push((mean - cm[1], mean - vsplit[0]));
        verified_v += vvar;
        eprintln!(
            "{k:2} x_j {p:?}: connection {mean:.5} ± {:.5} | cone θ 0.02 {:.5} ± {:.5}, θ 0.01 {:.5} ± {:.5} (Newton from the cone direction: verified {:.5}, rejected {:.5}, fails {:.5}) | capped {}, verified {}, rejected {}",
            var.sqrt(),
            cm[0],
            cv[0].sqrt(),
            cm[1],
            cv[1].sqrt(),
            vsplit[0],
            vsplit[1],
            vsplit[2],
            stats.manifold_trials_capped - before.0,
            stats.manifold_solutions - before.1,
            stats.manifold_failures - before.2,
        );
        cone_t = [cone_t[0] + cm[0], cone_t[1] + cm[1]];
        cone_v = [cone_v[0] + cv[0], cone_v[1] + cv[1]];
        for (s, v) in split.iter_mut().zip(vsplit) {
            *s += v;
        }
        conn_t += mean;
        conn_v += var;
    }
    let z = |a: f64, va: f64, b: f64, vb: f64| (a - b) / (va + vb).sqrt();
    eprintln!(
        "statue σt {sigma_t}, {points} vertices: connection {conn_t:.5} ± {:.5}; cone θ 0.02 {:.5} ± {:.5} (z {:.2}), θ 0.01 {:.5} ± {:.5} (z {:.2}); θ 0.01 split by Newton from the cone direction: verified {:.5}, rejected {:.5}, fails {:.5}; capped runs {} of {}",
        conn_v.sqrt(),
        cone_t[0],
        cone_v[0].sqrt(),
        z(conn_t, conn_v, cone_t[0], cone_v[0]),
        cone_t[1],
        cone_v[1].sqrt(),
        z(conn_t, conn_v, cone_t[1], cone_v[1]),
        split[0],
        split[1],
        split[2],
        stats.manifold_trials_capped,
        points * runs as usize,
    );
    // Paired over vertices: the spread of the per-vertex differences (it includes the cone's
    // finite-θ error, which differs from vertex to vertex: near-misses at folds read low, the
    // bright side of a caustic high).
    let paired = |f: fn(&(f64, f64)) -> f64| {
        let n = diffs.len() as f64;
        let m = diffs.iter().map(f).sum::<f64>() / n;
        let v = diffs.iter().map(|d| (f(d) - m).powi(2)).sum::<f64>() / (n - 1.0);
        (m * n, (v * n).sqrt())
    };
    let (d_cone, s_cone) = paired(|d| d.0);
    let (d_ver, s_ver) = paired(|d| d.1);
    eprintln!(
        "summed differences, s.e. from the spread over vertices: connection − cone(θ 0.01) {d_cone:.5} ± {s_cone:.5}; connection − cone directions whose Newton reaches a verified root {d_ver:.5} ± {s_ver:.5} (that part: {:.5} ± {:.5})",
        split[0],
        verified_v.sqrt()
    );
}

/// A probe (ignored) behind `diagnose_statue_one_refraction_against_cone`: at the statue's
/// vertices, the cone directions within θ = 0.01 of the light where `newton::solve` seeded there
/// fails, classified by failure and by what a plain local Newton (same closed form, more steps,
/// more halvings) does from the same seed.
#[test]
#[ignore]
fn probe_statue_newton_failures_near_roots() {
    use snee::integrator::manifold::curved;
    use snee::integrator::manifold::locate::{boundary_patch, SceneLocate};
    use snee::integrator::manifold::newton::{self, Failure, Locate};
    use snee::math::{DVec3, Ray, Vec3};
    use snee::sampler::Sampler;

    let env = |k: &str, d: usize| std::env::var(k).ok().and_then(|s| s.parse().ok()).unwrap_or(d);
    let scene = crate::manifold_curved_statue::statue("2");
    let (ds, _) = scene.sample_emitter_direction(Vec3::ZERO, None, snee::math::Vec2::new(0.5, 0.5), false);
    let od = ds.d.as_dvec3().normalize();
    let turn = newton::max_turn(curved::largest_eta(&scene, 0));
    let theta: f64 = 0.01;
    let mut rng = Sampler::new(17, 1);
    let mut u = move || rng.next_1d() as f64;
    let l = newton::tangents(od);
    let res = |o: DVec3| [(o - od).dot(l.0), (o - od).dot(l.1)];
    let (mut fails, mut kinds, mut local_ok, mut total) = (0u64, [0u64; 2], [0u64; 4], 0u64);
    let mut iters_hist = [0u64; 26];
    for k in 0..env("STATUE_POINTS", 2) {
        let p = crate::manifold_curved_statue::inside_point(&scene, &mut u);
        let xd = p.as_dvec3();
        let mut locate = SceneLocate { scene: &scene, medium: 0, rays: 0 };
        let mut shown = 0;
        for _ in 0..(1u64 << env("STATUE_DIRS", 22)) {
            let w = newton::cone_seed(od, turn, u(), u());
            let d = w.as_vec3();
            let Some(si) = scene.ray_intersect(&Ray::new(p, d)) else { continue };
            let Some(patch) = boundary_patch(&scene, &si, 0, d) else { continue };
            let Some(r) = patch.refract(xd, w) else { continue };
            if r.o.dot(od) < theta.cos() {
                continue;
            }
            total += 1;
            let err = match newton::solve(&mut locate, xd, od, w) {
                Ok(_) => continue,
                Err(e) => e,
            };
            fails += 1;
            kinds[matches!(err.0, Failure::NoConvergence) as usize] += 1;
            iters_hist[(err.1 as usize).min(25)] += 1;
            // A plain local Newton: the closed form of the CURRENT located patch, full steps
            // halved up to 30 times until |o − ω_l| decreases, up to 200 steps; records the
            // residuals and the patches visited.
            let mut omega = w;
            let mut pa = locate.locate(xd, omega).unwrap();
            let mut norms = vec![];
            let mut dets = vec![];
            let mut patches = 0;
            let mut outcome = 3; // 0 converged, 1 line search failed, 2 lost, 3 out of steps
            for _ in 0..200 {
                let Some(rr) = pa.refract(xd, omega) else {
                    outcome = 2;
                    break;
                };
                let norm = (rr.o - od).length();
                norms.push(norm);
                if norm < 1e-8 {
                    outcome = 0;
                    break;
                }
                let t = newton::tangents(omega);
                let Some(j) =
                    newton::central_jacobian(1e-6, |a, b| Some(res(pa.refract(xd, newton::moved(omega, t, a, b))?.o)))
                else {
                    outcome = 2;
                    break;
                };
                let det = j[0][0] * j[1][1] - j[0][1] * j[1][0];
                dets.push(det);
                let c = res(rr.o);
                let mut da = -(j[1][1] * c[0] - j[0][1] * c[1]) / det;
                let mut db = -(-j[1][0] * c[0] + j[0][0] * c[1]) / det;
                let mut moved = None;
                for _ in 0..30 {
                    let cand = newton::moved(omega, t, da, db);
                    if let Some(pc) = locate.locate(xd, cand) {
                        if let Some(rc) = pc.refract(xd, cand) {
                            if (rc.o - od).length() < norm {
                                moved = Some((cand, pc));
                                break;
                            }
                        }
                    }
                    da *= 0.5;
                    db *= 0.5;
                }
                let Some((cand, pc)) = moved else {
                    outcome = 1;
                    break;
                };
                if let (newton::Surface::Triangle { p: a, .. }, newton::Surface::Triangle { p: b, .. }) =
                    (pa.surface, pc.surface)
                {
                    patches += (a != b) as u32;
                }
                omega = cand;
                pa = pc;
            }
            local_ok[outcome] += 1;
            if shown < 6 {
                shown += 1;
                let nd = norms.len();
                eprintln!(
                    "vertex {k}: solve {:?} after {}; local Newton outcome {outcome} after {nd} steps, {patches} patch changes; |o−ω_l| first {:.2e}, last 5 {:?}; |det| first {:.2e}, last {:?}",
                    err.0,
                    err.1,
                    norms[0],
                    &norms[nd.saturating_sub(5)..].iter().map(|x| format!("{x:.1e}")).collect::<Vec<_>>(),
                    dets.first().copied().unwrap_or(0.0).abs(),
                    dets.last().map(|x| x.abs())
                );
            }
        }
    }
    eprintln!(
        "cone directions within θ {theta}: {total}; newton::solve fails on {fails} (lost {}, no convergence {}; iterations histogram {:?}); local Newton from the same seeds: converged {}, line search failed {}, lost {}, out of 200 steps {}",
        kinds[0], kinds[1], iters_hist, local_ok[0], local_ok[1], local_ok[2], local_ok[3]
    );
}

/// The truncation of specular manifold sampling's count on the statue (ignored: a measurement,
/// ~2 min): at vertices uniform in the statue's medium (σt 2), `newton::sample_solution`'s
/// estimator replicated (the deterministic seed solved first and drawn with probability 1/4 when
/// it converged, else `newton::random_seed`) with the count continued past the renderer's cap
/// (`newton::DIRECTIONAL_MAX_TRIALS` = 4096) up to 32 768 on the SAME draws, so the mean of
/// `f(s) (min(N, 32768) − min(N, 4096))` is the part of the transport the cap of 4096 drops that a
/// cap of 32 768 would keep (a lower bound on the whole truncation). `STATUE_POINTS` (24) vertices
/// × 2048 runs.
#[test]
#[ignore]
fn diagnose_statue_sms_cap() {
    use snee::color::Spectrum;
    use snee::integrator::manifold::locate::SceneLocate;
    use snee::integrator::manifold::newton;
    use snee::integrator::manifold::{curved, MediumVertex};
    use snee::integrator::stats::LocalStats;
    use snee::math::Vec3;
    use snee::sampler::Sampler;

    let points = std::env::var("STATUE_POINTS").ok().and_then(|s| s.parse().ok()).unwrap_or(24);
    let scene = crate::manifold_curved_statue::statue("2");
    let (ds, _) = scene.sample_emitter_direction(Vec3::ZERO, None, snee::math::Vec2::new(0.5, 0.5), false);
    let omega_l = ds.d;
    let od = omega_l.as_dvec3().normalize();
    let turn = newton::max_turn(curved::largest_eta(&scene, 0));
    let mut rng = Sampler::new(23, 1);
    let mut u = move || rng.next_1d() as f64;
    let (cap, long_cap, runs) = (newton::DIRECTIONAL_MAX_TRIALS, 32768u32, 2048);
    let (mut at_cap, mut at_long, mut n_capped, mut n_long_capped) = (0.0f64, 0.0f64, 0u64, 0u64);
    let mut diffs = Vec::new();
    for k in 0..points {
        let p = crate::manifold_curved_statue::inside_point(&scene, &mut u);
        let x_j = MediumVertex { p, wi: Vec3::Z, medium: 0 };
        let xd = p.as_dvec3();
        let mut locate = SceneLocate { scene: &scene, medium: 0, rays: 0 };
        let det = newton::refracted_seed(&mut locate, xd, od).and_then(|s| newton::solve(&mut locate, xd, od, s).ok());
        let p_det = if det.is_some() { 0.25 } else { 0.0 };
        let (mut s_cap, mut s_long) = (0.0f64, 0.0f64);
        for _ in 0..runs {
            let draw = |locate: &mut SceneLocate, u: &mut dyn FnMut() -> f64| {
                if u() < p_det {
                    det
                } else {
                    let seed = newton::random_seed(locate, xd, od, turn, newton::P_REFRACTED_RANDOM, u);
                    newton::solve(locate, xd, od, seed).ok()
                }
            };
            let Some(s) = draw(&mut locate, &mut u) else { continue };
            let (n, long_capped) =
                newton::bernoulli_trials_capped(s.omega, long_cap, || draw(&mut locate, &mut u).map(|t| t.omega));
            let f = curved::value(&scene, &x_j, &s, omega_l, Spectrum::ONE, 1.0, &mut LocalStats::default())
                .map_or(0.0, |c| c.value.x as f64);
            n_capped += (n >= cap) as u64;
            n_long_capped += long_capped as u64;
            s_cap += f * n.min(cap) as f64;
            s_long += f * n as f64;
        }
        let (m_cap, m_long) = (s_cap / runs as f64, s_long / runs as f64);
        eprintln!("{k:2} x_j {p:?}: cap {cap} {m_cap:.5}, cap {long_cap} {m_long:.5}");
        at_cap += m_cap;
        at_long += m_long;
        diffs.push(m_long - m_cap);
    }
    let n = diffs.len() as f64;
    let mean = diffs.iter().sum::<f64>() / n;
    let sd = (diffs.iter().map(|d| (d - mean).powi(2)).sum::<f64>() / (n - 1.0)).sqrt();
    eprintln!(
        "statue σt 2, {points} vertices × {runs} runs: Σ mean estimate at cap {cap} {at_cap:.5}, at cap {long_cap} {at_long:.5}: the cap of {cap} drops {:.5} ± {:.5} ({:.2} % ± {:.2} %); runs reaching {cap}: {n_capped}, reaching {long_cap}: {n_long_capped} of {}",
        mean * n,
        sd * n.sqrt(),
        100.0 * mean * n / at_long,
        100.0 * sd * n.sqrt() / at_long,
        points * runs
    );
}
