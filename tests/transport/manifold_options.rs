//! The `connection` parameter of `volpath_snee`: parsed with a positioned error for a bad value,
//! reported by `snee info` and in the render statistics (which estimator ran, manifold counters).

use snee::render::{render, RenderOptions};
use snee::scene::build::build_scene;
use snee::scene::xml::parse_str;
use std::path::Path;
use std::sync::atomic::AtomicBool;

fn xml(connection: &str) -> String {
    format!(
        r#"<scene version="3.0.0">
<integrator type="volpath_snee">
    <string name="connection" value="{connection}"/>
</integrator>
<emitter type="directional"><vector name="direction" value="0, 0, -1"/></emitter>
<medium type="homogeneous" id="m"><float name="sigma_t" value="1"/><float name="albedo" value="0.8"/></medium>
<shape type="cube"><bsdf type="dielectric"/><ref name="interior" id="m"/></shape>
<sensor type="perspective"><transform name="to_world"><lookat origin="0, 0, 5" target="0, 0, 0" up="0, 1, 0"/></transform>
    <film type="hdrfilm"><integer name="width" value="8"/><integer name="height" value="8"/></film></sensor>
</scene>"#
    )
}

fn build(connection: &str) -> Result<(snee::scene::xml::ParsedScene, snee::scene::world::Scene), snee::scene::Error> {
    let parsed = parse_str(&xml(connection), "c.xml", Path::new("."), &[])?;
    let scene = build_scene(&parsed)?;
    Ok((parsed, scene))
}

#[test]
fn bad_connection_is_a_positioned_error() {
    let e = build("newton").err().expect("an error");
    let msg = e.to_string();
    assert!(msg.starts_with("c.xml:3:"), "{msg}");
    assert!(msg.contains("connection") && msg.contains("paper, complete"), "{msg}");
}

#[test]
fn info_and_stats_say_which_estimator_ran() {
    for (c, attempts) in [("paper", false), ("complete", true)] {
        let (parsed, scene) = build(c).unwrap();
        let info = snee::info::summary(&parsed, &scene);
        assert!(info.to_text().contains(&format!("connection = {c}")), "{}", info.to_text());
        assert_eq!(info.to_json()["integrator"]["connection"], c);
        let opts = RenderOptions { spp: Some(4), seed: 1, time_budget: None, progress: false };
        let out = render(&scene, &opts, &AtomicBool::new(false));
        let json = out.stats.to_json();
        assert_eq!(json["connection"], c);
        assert_eq!(json["manifold_attempts"].as_u64().unwrap() > 0, attempts, "{json}");
        if attempts {
            assert!(json["manifold_solutions"].as_u64().unwrap() > 0, "{json}");
        }
    }
}

/// A glass sphere (a curved boundary) of a medium under a directional light, with
/// `reflection_chains` set.
fn chain_scene(connection: &str, chains: bool) -> Result<snee::scene::world::Scene, snee::scene::Error> {
    let xml = xml(connection)
        .replace(
            r#"<string name="connection""#,
            &format!("<boolean name=\"reflection_chains\" value=\"{chains}\"/>\n    <string name=\"connection\""),
        )
        .replace(r#"<shape type="cube">"#, r#"<shape type="sphere">"#);
    build_scene(&parse_str(&xml, "c.xml", Path::new("."), &[])?)
}

#[test]
fn reflection_chains_run_only_when_asked_and_need_complete() {
    let e = chain_scene("paper", true).err().expect("an error");
    let msg = e.to_string();
    assert!(msg.starts_with("c.xml:3:") && msg.contains("reflection_chains needs connection = complete"), "{msg}");
    for chains in [false, true] {
        let scene = chain_scene("complete", chains).unwrap();
        let opts = RenderOptions { spp: Some(16), seed: 1, time_budget: None, progress: false };
        let json = render(&scene, &opts, &AtomicBool::new(false)).stats.to_json();
        assert!(json["manifold_attempts"].as_u64().unwrap() > 0, "{json}");
        assert_eq!(json["chain_attempts"].as_u64().unwrap() > 0, chains, "{json}");
    }
}
