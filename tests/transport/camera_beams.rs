//! Camera beams (`manifold/camera_beam.rs`: points on light-traced internal-reflection beams
//! connected to the camera through one refraction, splatted) through whole renders of a glass
//! ball (analytic sphere, n = 1.5, radius 1, σt 1, albedo 0.8, isotropic) under a directional
//! light, box filter. With `reflection_chains`, the chain (verified against the cone limit on this
//! ball, `manifold_chain.rs`) makes the paths camera → x_c → x_b → reflection → refraction → sun
//! from the camera's first medium vertex x_b when camera beams are off, and skips that vertex when
//! they are on (`camera_reflections` 2: also after one or two internal reflections of the camera
//! ray; their share on the ball is small, the solver's laws for them are unit-tested in
//! `camera_beam.rs`): the two renders estimate the same image. Compared: the image and the class
//! `internal_reflection` (where both techniques put these paths), whole-image means with standard
//! errors from the per-pixel second moments, |z| < 4. Power: camera beams carry about 40 % of the
//! class (measured 0.000059 of 0.00015 at 256 spp before this test was written), so a factor-2
//! error in their value moves the class by ~8 standard errors at the count below (2 × 512 spp,
//! fixed before the first run).

use crate::common;
use snee::render::{render, RenderOptions, RenderOutput};
use std::sync::atomic::AtomicBool;

fn ball_scene(camera_beams: bool) -> String {
    format!(
        r#"<scene version="3.0.0">
<integrator type="volpath_snee"><integer name="max_depth" value="-1"/><string name="connection" value="complete"/>
<boolean name="reflection_chains" value="true"/><boolean name="camera_beams" value="{camera_beams}"/>
<integer name="camera_reflections" value="2"/></integrator>
<sensor type="perspective"><float name="fov" value="40"/>
    <transform name="to_world"><lookat origin="0, -4, 0" target="0, 0, 0" up="0, 0, 1"/></transform>
    <film type="hdrfilm"><integer name="width" value="32"/><integer name="height" value="32"/><rfilter type="box"/></film></sensor>
<emitter type="directional"><vector name="direction" value="0.3, 0.2, -1"/><rgb name="irradiance" value="1, 1, 1"/></emitter>
<medium type="homogeneous" id="m"><float name="sigma_t" value="1"/><rgb name="albedo" value="0.8"/><phase type="isotropic"/></medium>
<shape type="sphere"><float name="radius" value="1"/><bsdf type="dielectric"><float name="int_ior" value="1.5"/></bsdf><ref name="interior" id="m"/></shape>
</scene>"#
    )
}

fn render_ball(camera_beams: bool, seed: u64, spp: u32) -> RenderOutput {
    let mut scene = common::scene(&ball_scene(camera_beams), &[]);
    let mut desc = (*scene.integrator).clone();
    desc.moment = true;
    desc.classes = true;
    scene.integrator = snee::integrator::build(desc, &scene);
    let opts = RenderOptions { spp: Some(spp), seed, time_budget: None, progress: false };
    render(&scene, &opts, &AtomicBool::new(false))
}

/// Image mean of channel group `base` (channel average) and its standard error from `m2.` moments.
fn mean_se(out: &RenderOutput, base: &str, spp: u32) -> (f64, f64) {
    let name = |c: &str| if base.is_empty() { c.to_string() } else { format!("{base}.{c}") };
    let idx = |n: String| out.channels.iter().position(|c| *c == n).unwrap_or_else(|| panic!("no channel {n}"));
    let (v, m) = (["R", "G", "B"].map(|c| idx(name(c))), ["R", "G", "B"].map(|c| idx(name(&format!("m2.{c}")))));
    let nch = out.channels.len();
    let pixels = out.data.len() / nch;
    let (mut sum, mut var) = (0.0f64, 0.0f64);
    for p in 0..pixels {
        let px = &out.data[p * nch..(p + 1) * nch];
        let mean = v.iter().map(|&i| px[i] as f64).sum::<f64>() / 3.0;
        let m2 = m.iter().map(|&i| px[i] as f64).sum::<f64>() / 3.0;
        sum += mean;
        var += (m2 - mean * mean).max(0.0) / spp as f64;
    }
    (sum / pixels as f64, var.sqrt() / pixels as f64)
}

#[test]
fn camera_beams_match_the_chain_from_the_first_medium_vertex() {
    let spp = 512;
    let (mut stats_on, mut splats) = (0u64, 0u64);
    for seed in [1u64, 2] {
        let off = render_ball(false, seed, spp);
        let on = render_ball(true, seed, spp);
        let json_on = on.stats.to_json();
        let json_off = off.stats.to_json();
        assert_eq!(json_off["camera_beam_points"].as_u64(), Some(0), "{json_off}");
        stats_on += json_on["camera_beam_points"].as_u64().unwrap();
        splats += json_on["camera_beam_splats"].as_u64().unwrap();
        assert_eq!(json_on["rejected_samples"].as_u64(), Some(0), "{json_on}");
        assert!(on.data.iter().all(|v| v.is_finite()));
        // The chain skips the camera's first medium vertex where camera beams run.
        assert!(json_on["chain_attempts"].as_u64() < json_off["chain_attempts"].as_u64());
        for base in ["", "internal_reflection"] {
            let (a, sa) = mean_se(&off, base, spp);
            let (b, sb) = mean_se(&on, base, spp);
            let z = (b - a) / (sa * sa + sb * sb).sqrt();
            eprintln!("seed {seed} {base:>20}: chain {a:.6} ± {sa:.6}, camera beams {b:.6} ± {sb:.6}, z {z:.2}");
            assert!(z.abs() < 4.0, "{base}: chain {a} ± {sa} vs camera beams {b} ± {sb}");
        }
    }
    assert!(stats_on > 0 && splats > 0, "camera beams ran: {stats_on} points, {splats} splats");
}
