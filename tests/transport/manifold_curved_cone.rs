//! The one-refraction connection under a directional light through CURVED smooth boundaries
//! (`curved::connect`: Newton through the renderer's ray casts, specular manifold sampling's
//! trials, f32 verification, light segment, value) against the limit of a shrinking cone of light
//! directions at fixed medium vertices, computed WITHOUT Newton or seeds: uniform directions at
//! `x_j`, the first boundary hit by the scene's own ray cast, the refraction about the
//! interpolated shading normal in closed form (`Patch::refract`), kept when the refracted ray
//! lies within θ of `omega_l`:
//!
//! ```text
//! E Σ_s f_p T(d_jk) (1 − F) η² dω/dω_l  =  lim_θ→0  E ∫ f_p T (1 − F) η² 1[∠(o(ω), ω_l) < θ] dω / Ω(θ)
//! ```
//!
//! (and the refracted ray leaves without meeting the mesh again). This is the sphere-light limit of the study
//! at one vertex, including every solution (several per vertex in the non-convex blob). Meshes
//! with interpolated vertex normals (`scenes/meshes/pebble.ply`, convex, and `blob.ply`,
//! non-convex), glass n = 1.5, an isotropic medium of σt 1.
//!
//! Sample counts: 3 vertices per mesh, 2²² directions uniform in the cone of largest turn
//! (`newton::max_turn`, where every solution lies) and 4096 connections per vertex; agreement
//! within 4 combined standard errors per vertex; θ = 0.01 rad. Vertices are uniform in the mesh;
//! a vertex that no cone direction reaches (the refracted beam does not fill a glass body) is
//! skipped. History, for honesty: the first version used 2²² directions on the whole sphere and
//! θ = 0.03; the blob then failed at a vertex where the connection found nothing and the cone
//! read 0.104 ± 0.003. A probe showed no solution there: the closest refracted direction in that
//! neighbourhood stays 1.13e-2 rad from `omega_l` (a fold of the piecewise-smooth map at a
//! triangle edge), inside the θ = 0.03 cone but not a root — the cone's finite width, not the
//! connection. θ was lowered to 0.01 (below that fold's distance) and the directions confined
//! to the cone of largest turn (6× more hits per direction) after that failure.

use crate::common;
use snee::bsdf::fresnel::fresnel;
use snee::color::Spectrum;
use snee::integrator::manifold::locate::boundary_patch;
use snee::integrator::manifold::newton;
use snee::integrator::manifold::{curved, MediumVertex};
use snee::integrator::stats::LocalStats;
use snee::interaction::offset_origin;
use snee::math::{DVec3, Ray, Vec3};
use snee::sampler::Sampler;
use snee::scene::world::Scene;

fn mesh_scene(file: &str) -> String {
    format!(
        r#"<scene version="3.0.0">
<integrator type="volpath_snee"><integer name="max_depth" value="-1"/><string name="connection" value="complete"/></integrator>
<sensor type="perspective"><float name="fov" value="40"/>
    <transform name="to_world"><lookat origin="0, -4, 0" target="0, 0, 0" up="0, 0, 1"/></transform>
    <film type="hdrfilm"><integer name="width" value="8"/><integer name="height" value="8"/></film></sensor>
<emitter type="directional"><vector name="direction" value="-0.3, -0.2, -0.9"/><rgb name="irradiance" value="1, 1, 1"/></emitter>
<medium type="homogeneous" id="m"><float name="sigma_t" value="1"/><rgb name="albedo" value="0.8"/><phase type="isotropic"/></medium>
<shape type="ply"><string name="filename" value="meshes/{file}"/>
    <bsdf type="dielectric"><float name="int_ior" value="1.5"/></bsdf><ref name="interior" id="m"/></shape>
</scene>"#
    )
}

/// A direction kept by [`one_refraction`].
pub(crate) struct ConeSample {
    /// The direction at `p` and the cosine between the refracted direction and `omega_l`.
    pub w: DVec3,
    pub cos_o: f64,
    /// Phase function, transmittance, `(1 − F) η²`, over the density of `w` (the cone's solid
    /// angle): divided by a light cone's solid angle it estimates that cone's limit.
    pub g: f64,
}

/// One direction of the Newton-free one-refraction reference at `p` (medium 0): `w` uniform in the
/// cone of half-angle `turn` around `omega_l` (every solution lies there), refracted out where it
/// meets the boundary; kept when the refracted direction `o` is within `cos_min` of `omega_l` and
/// its light segment is free (a refracted ray that meets the mesh again is not a one-refraction
/// path).
pub(crate) fn one_refraction(
    scene: &Scene,
    p: Vec3,
    wi: Vec3,
    omega_l: DVec3,
    turn: f64,
    cos_min: f64,
    u: (f64, f64),
) -> Option<ConeSample> {
    let m = &scene.media[0];
    let omega_turn = std::f64::consts::TAU * (1.0 - turn.cos());
    let w = newton::cone_seed(omega_l, turn, u.0, u.1);
    let d = w.as_vec3();
    let si = scene.ray_intersect(&Ray::new(p, d))?;
    let patch = boundary_patch(scene, &si, 0, d)?;
    let r = patch.refract(p.as_dvec3(), w)?;
    let cos_o = r.o.dot(omega_l);
    if cos_o < cos_min {
        return None;
    }
    let o = r.o.as_vec3();
    if scene.ray_intersect(&Ray::new(offset_origin(si.p, si.n, o), o)).is_some() {
        return None;
    }
    let f = fresnel(r.cos_out as f32, patch.eta as f32).0 as f64;
    let g = m.phase.eval(wi, d) as f64
        * (-(m.sigma_t[0] as f64) * r.t).exp()
        * (1.0 - f)
        * patch.eta
        * patch.eta
        * omega_turn;
    Some(ConeSample { w, cos_o, g })
}

/// The mean of `runs` connections `curved::connect` makes at `x_j` to the directional light along
/// `omega_l` (first channel, 0 where it finds nothing), and the variance of that mean.
pub(crate) fn connection_mean(
    scene: &Scene,
    x_j: &MediumVertex,
    omega_l: Vec3,
    runs: u32,
    sampler: &mut Sampler,
    stats: &mut LocalStats,
) -> (f64, f64) {
    let (mut s, mut s2) = (0.0, 0.0);
    for _ in 0..runs {
        let v = curved::connect(scene, x_j, omega_l, Spectrum::ONE, sampler, stats).map_or(0.0, |c| c.value.x as f64);
        s += v;
        s2 += v * v;
    }
    let mean = s / runs as f64;
    (mean, (s2 / runs as f64 - mean * mean).max(0.0) / runs as f64)
}

fn cone_limit_agrees(file: &str, seed: u64) {
    let scene = common::scene(&mesh_scene(file), &[]);
    let omega_l = -Vec3::new(-0.3, -0.2, -0.9).normalize();
    let theta: f64 = 0.01;
    // Directions uniform in the cone of largest turn around omega_l (every solution lies there).
    let turn = newton::max_turn(1.5);
    let cone = std::f64::consts::TAU * (1.0 - theta.cos());
    let mut rng = Sampler::new(seed, 1);
    let mut u = move || rng.next_1d() as f64;
    let mut sampler = Sampler::new(seed + 1, 1);
    let mut stats = LocalStats::default();
    let wi = Vec3::Z;
    let mut lit = 0;
    for _ in 0..20 {
        if lit == 3 {
            break;
        }
        let p = crate::manifold_curved_statue::inside_point(&scene, &mut u);
        let x_j = MediumVertex { p, wi, medium: 0 };
        let n_dirs = 1u64 << 22;
        let (mut sum, mut sq) = (0.0, 0.0);
        for _ in 0..n_dirs {
            let Some(s) = one_refraction(&scene, p, wi, omega_l.as_dvec3(), turn, theta.cos(), (u(), u())) else {
                continue;
            };
            let g = s.g / cone;
            sum += g;
            sq += g * g;
        }
        let cone_mean = sum / n_dirs as f64;
        let cone_se = ((sq / n_dirs as f64 - cone_mean * cone_mean) / n_dirs as f64).sqrt();
        if cone_mean == 0.0 {
            continue; // no light reaches x_j (behind the caustic's envelope): the next vertex
        }
        lit += 1;
        let (mean, var) = connection_mean(&scene, &x_j, omega_l, 4096, &mut sampler, &mut stats);
        let se = var.sqrt();
        let z = (mean - cone_mean) / (se * se + cone_se * cone_se).sqrt();
        eprintln!(
            "{file} x_j {p:?}: connection {mean:.6} ± {se:.6}, cone limit {cone_mean:.6} ± {cone_se:.6}, z {z:.2}"
        );
        assert!(
            z.abs() < 4.0 && se.is_finite(),
            "{file}: connection {mean} ± {se} vs cone limit {cone_mean} ± {cone_se}"
        );
    }
    assert_eq!(lit, 3, "{file}: too few lit vertices");
    eprintln!(
        "{file}: {} solves, {} capped, {} solutions, {} failures",
        stats.manifold_newton_solves, stats.manifold_trials_capped, stats.manifold_solutions, stats.manifold_failures
    );
}

#[test]
fn directional_through_smooth_pebble_matches_cone_limit() {
    cone_limit_agrees("pebble.ply", 31);
}

#[test]
fn directional_through_smooth_blob_matches_cone_limit() {
    cone_limit_agrees("blob.ply", 41);
}
