//! Physical checks of `volpath` with participating media, independent of Mitsuba:
//! - thick slabs under a collimated beam at normal incidence with an index-matched (`null`)
//!   boundary, read by an `irradiancemeter` on a `null` quad just above: the reading equals the
//!   adding-doubling total reflectance (`tests/data/adding_doubling.json`, computed with
//!   iadpython by `scripts/adding_doubling.py`) within 1 %;
//! - a white furnace: an albedo-1 medium in an index-matched sphere under a uniform `constant`
//!   environment renders the environment;
//! - no NaN/Inf for degenerate media (σt = 0, albedo 1, g = ±0.99, camera inside a medium).

mod common;

use snee::render::{render, RenderOptions};
use snee::scene::world::Scene;
use std::path::Path;
use std::sync::atomic::AtomicBool;

fn load(xml: &str) -> Scene {
    common::scene(xml, &[])
}

fn meter_reading(scene: &Scene, spp: u32, batches: u64) -> (f64, f64, u64) {
    common::meter_reading(scene, spp, batches, 77)
}

/// The slab of `common::slab_xml` with an index-matched (`null`) boundary, under `volpath`.
fn slab_scene(albedo: f64, g: f64) -> String {
    common::slab_xml("volpath", albedo, g, r#"<bsdf type="null"/>"#)
}

#[test]
fn slab_reflectance_matches_adding_doubling() {
    let data: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/adding_doubling.json"))
            .unwrap(),
    )
    .unwrap();
    let entries = data["entries"].as_array().unwrap();
    let mut report = Vec::new();
    let mut failures = Vec::new();
    // Strongly forward-scattering, low-albedo slabs (a = 0.8, g = 0.9: R = 0.029) and a = 0.99 need
    // far more samples for a 0.35 % standard error; they are left to scripts, not the suite.
    for (albedo, g) in [(0.8, 0.0), (0.95, 0.5), (0.3, 0.0), (0.95, -0.3), (0.3, -0.3)] {
        let e = entries
            .iter()
            .find(|e| {
                e["albedo"].as_f64() == Some(albedo) && e["g"].as_f64() == Some(g) && e["n"].as_f64() == Some(1.0)
            })
            .expect("entry in adding_doubling.json");
        let r_ad = e["R_total"].as_f64().unwrap();
        let scene = load(&slab_scene(albedo, g));
        let (r, se, rejected) = meter_reading(&scene, 32768, 16);
        let rel = (r - r_ad) / r_ad;
        report.push(format!(
            "a={albedo} g={g}: snee {r:.5} ± {se:.5}, adding-doubling {r_ad:.5}, rel {:+.3}%",
            rel * 100.0
        ));
        assert_eq!(rejected, 0, "non-finite samples");
        // Within 1 %, with enough samples that the test could see a 1 % error (standard error < 0.35 %).
        if rel.abs() > 0.01 || se / r_ad > 0.0035 {
            failures.push(report.last().unwrap().clone());
        }
    }
    eprintln!("{}", report.join("\n"));
    assert!(failures.is_empty(), "slab reflectance off:\n{}", failures.join("\n"));
}

#[test]
fn white_furnace() {
    let scene = load(
        r#"<scene version="3.0.0">
    <integrator type="volpath"/>
    <emitter type="constant"><rgb name="radiance" value="1, 1, 1"/></emitter>
    <shape type="sphere">
        <bsdf type="null"/>
        <medium name="interior" type="homogeneous">
            <rgb name="albedo" value="1, 1, 1"/><float name="sigma_t" value="3"/>
            <phase type="hg"><float name="g" value="0.6"/></phase>
        </medium>
    </shape>
    <sensor type="perspective">
        <float name="fov" value="30"/>
        <transform name="to_world"><lookat origin="0, 0, 5" target="0, 0, 0" up="0, 1, 0"/></transform>
        <film type="hdrfilm"><integer name="width" value="16"/><integer name="height" value="16"/><rfilter type="box"/></film>
    </sensor>
</scene>"#,
    );
    // Grey extinction: with chromatic σt, volpath's single-channel RGB estimator has heavy tails
    // (weights exp((σt[c] − σt[k]) t)), which `volpathmis` addresses; its furnace is tested there.
    let cancel = AtomicBool::new(false);
    let mut means = Vec::new();
    for b in 0..8 {
        let out =
            render(&scene, &RenderOptions { spp: Some(64), seed: 3 + b, time_budget: None, progress: false }, &cancel);
        assert_eq!(out.stats.rejected_samples, 0);
        let n = out.width * out.height;
        means.push((0..n).map(|i| out.data[i * out.channels.len()] as f64).sum::<f64>() / n as f64);
    }
    let m = means.iter().sum::<f64>() / 8.0;
    let se = (means.iter().map(|x| (x - m) * (x - m)).sum::<f64>() / 7.0 / 8.0).sqrt();
    eprintln!("furnace: {m:.5} ± {se:.5}");
    // Every sample is 1 in expectation: within 0.5 % and 4 standard errors.
    assert!((m - 1.0).abs() < 0.005 && (m - 1.0).abs() < 4.0 * se.max(1e-4), "furnace mean {m} ± {se}");
}

#[test]
fn degenerate_media_stay_finite() {
    for (sigma_t, albedo, g) in [(0.0, 0.5, 0.0), (2.0, 1.0, 0.99), (2.0, 1.0, -0.99), (50.0, 0.999, 0.9)] {
        let xml = format!(
            r#"<scene version="3.0.0">
    <integrator type="volpath"><integer name="max_depth" value="200"/></integrator>
    <emitter type="directional"><vector name="direction" value="0.3, -1, 0.2"/><rgb name="irradiance" value="2, 2, 2"/></emitter>
    <emitter type="constant"><rgb name="radiance" value="0.3, 0.3, 0.3"/></emitter>
    <medium type="homogeneous" id="m">
        <rgb name="albedo" value="{albedo}, {albedo}, {albedo}"/><float name="sigma_t" value="{sigma_t}"/>
        <phase type="hg"><float name="g" value="{g}"/></phase>
    </medium>
    <shape type="sphere"><float name="radius" value="2"/><bsdf type="dielectric"/><ref name="interior" id="m"/></shape>
    <shape type="sphere"><float name="radius" value="0.3"/><bsdf type="diffuse"/><ref name="exterior" id="m"/></shape>
    <sensor type="perspective">
        <ref id="m"/>
        <float name="fov" value="90"/>
        <transform name="to_world"><lookat origin="0, 0, 1.2" target="0, 0, 0" up="0, 1, 0"/></transform>
        <film type="hdrfilm"><integer name="width" value="12"/><integer name="height" value="12"/></film>
    </sensor>
</scene>"#
        );
        let scene = load(&xml);
        let cancel = AtomicBool::new(false);
        let out =
            render(&scene, &RenderOptions { spp: Some(32), seed: 1, time_budget: None, progress: false }, &cancel);
        assert_eq!(out.stats.rejected_samples, 0, "σt={sigma_t} a={albedo} g={g}: rejected samples");
        assert!(out.data.iter().all(|v| v.is_finite()), "σt={sigma_t} a={albedo} g={g}: non-finite pixels");
    }
}
