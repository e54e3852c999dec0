//! Unbiasedness of `volpath_snee` on a small convex scene: a sphere of chromatic HG medium inside
//! a GGX `roughdielectric` (α = 0.2), lit by an envmap and a small sphere light.
//! - `volpath_snee` (mis) agrees with `volpath` (Welch test on image and 8×8-block means of
//!   independent batches, Šidák-corrected at 1 %);
//! - with `transport = snee`, the `snee`, `forward` and `mis` modes agree with each other.

use crate::common;

use common::{render_batches, scene, welch_compare};

fn xml(integrator: &str, extra: &str) -> String {
    format!(
        r#"<scene version="3.0.0">
<integrator type="{integrator}"><integer name="max_depth" value="12"/>{extra}</integrator>
<sensor type="perspective"><float name="fov" value="30"/>
    <transform name="to_world"><lookat origin="0, 0, 4" target="0, 0, 0" up="0, 1, 0"/></transform>
    <film type="hdrfilm"><integer name="width" value="24"/><integer name="height" value="24"/></film></sensor>
<emitter type="envmap"><string name="filename" value="textures/sky.exr"/></emitter>
<shape type="sphere"><point name="center" x="3" y="4" z="2"/><float name="radius" value="0.3"/>
    <emitter type="area"><rgb name="radiance" value="40, 40, 40"/></emitter></shape>
<medium type="homogeneous" id="m"><rgb name="sigma_t" value="1, 0.6, 0.3"/><float name="scale" value="3"/>
    <rgb name="albedo" value="0.9, 0.8, 0.7"/><phase type="hg"><float name="g" value="0.5"/></phase></medium>
<shape type="sphere"><float name="radius" value="1"/>
    <bsdf type="roughdielectric"><string name="distribution" value="ggx"/><float name="alpha" value="0.2"/><float name="int_ior" value="1.33"/></bsdf>
    <ref name="interior" id="m"/></shape>
</scene>"#
    )
}

#[test]
fn mis_agrees_with_volpath() {
    let vp = render_batches(&scene(&xml("volpath", ""), &[]), 12, 12, 8, 1000);
    let sn = render_batches(&scene(&xml("volpath_snee", ""), &[]), 12, 12, 8, 2000);
    assert_eq!(sn.rejected, 0);
    let (report, m_vp, m_sn) = welch_compare(&vp, &sn, 0.01);
    eprintln!("volpath {:?}\nvolpath_snee {:?}", m_vp, m_sn);
    assert!(report.is_empty(), "volpath vs volpath_snee:\n{}", report);
}

#[test]
fn snee_transport_modes_agree() {
    let t = r#"<string name="transport" value="snee"/>"#;
    let mis = render_batches(&scene(&xml("volpath_snee", t), &[]), 12, 8, 8, 3000);
    let sn = render_batches(
        &scene(&xml("volpath_snee", &format!(r#"{t}<string name="snee" value="snee"/>"#)), &[]),
        12,
        8,
        8,
        4000,
    );
    let fw = render_batches(
        &scene(&xml("volpath_snee", &format!(r#"{t}<string name="snee" value="forward"/>"#)), &[]),
        12,
        8,
        8,
        5000,
    );
    assert_eq!(mis.rejected + sn.rejected + fw.rejected, 0);
    let (r1, m_sn, m_fw) = welch_compare(&sn, &fw, 0.01 / 2.0);
    let (r2, m_mis, _) = welch_compare(&mis, &sn, 0.01 / 2.0);
    eprintln!("snee {:?}\nforward {:?}\nmis {:?}", m_sn, m_fw, m_mis);
    assert!(m_sn[0] > 0.0);
    assert!(r1.is_empty(), "snee vs forward:\n{}", r1);
    assert!(r2.is_empty(), "mis vs snee:\n{}", r2);
}

/// `snee_rate` = 0: SNEE never runs and no suffix is tracked, so the image is volpath's, bit for bit.
#[test]
fn rate_zero_is_volpath() {
    let vp = render_batches(&scene(&xml("volpath", ""), &[]), 2, 4, 8, 6000);
    let sn = render_batches(&scene(&xml("volpath_snee", r#"<float name="snee_rate" value="0"/>"#), &[]), 2, 4, 8, 6000);
    assert_eq!(vp.stats, sn.stats);
    assert_eq!(vp.rays, sn.rays);
}

/// Any rate is unbiased: SNEE's density in MIS is `r · pdf_snee` (docs/snee.md §5).
#[test]
fn partial_rate_agrees_with_full_rate() {
    let full =
        render_batches(&scene(&xml("volpath_snee", r#"<float name="snee_rate" value="1"/>"#), &[]), 12, 12, 8, 7000);
    let part =
        render_batches(&scene(&xml("volpath_snee", r#"<float name="snee_rate" value="0.3"/>"#), &[]), 12, 12, 8, 8000);
    let (report, m_full, m_part) = welch_compare(&full, &part, 0.01);
    eprintln!("rate 1 {:?}\nrate 0.3 {:?}", m_full, m_part);
    assert!(report.is_empty(), "snee_rate 1 vs 0.3:\n{}", report);
}

#[test]
fn rate_out_of_range_is_an_error() {
    let text = xml("volpath_snee", r#"<float name="snee_rate" value="1.5"/>"#);
    let parsed = snee::scene::xml::parse_str(&text, "rate.xml", &common::root().join("scenes"), &[]).unwrap();
    let err = snee::scene::build::build_scene(&parsed).err().expect("snee_rate 1.5 must be rejected");
    let s = err.to_string();
    assert!(s.starts_with("rate.xml:2:") && s.contains("snee_rate must be in [0, 1]"), "{}", s);
}

/// A glass (smooth `dielectric`) sphere of thin medium (optical size 2 < 4, so SNEE's rate under
/// `complete` is 0, docs/snee.md §5) lit by `emitter`.
fn smooth_sphere(integrator: &str, extra: &str, emitter: &str) -> String {
    format!(
        r#"<scene version="3.0.0">
<integrator type="{integrator}"><integer name="max_depth" value="12"/>{extra}</integrator>
<sensor type="perspective"><float name="fov" value="30"/>
    <transform name="to_world"><lookat origin="0, 0, 4" target="0, 0, 0" up="0, 1, 0"/></transform>
    <film type="hdrfilm"><integer name="width" value="16"/><integer name="height" value="16"/></film></sensor>
{emitter}
<medium type="homogeneous" id="m"><float name="sigma_t" value="1"/><rgb name="albedo" value="0.9, 0.8, 0.7"/></medium>
<shape type="sphere"><float name="radius" value="1"/>
    <bsdf type="dielectric"><float name="int_ior" value="1.5"/></bsdf>
    <ref name="interior" id="m"/></shape>
</scene>"#
    )
}

const ENVMAP: &str = r#"<emitter type="envmap"><string name="filename" value="textures/sky.exr"/></emitter>"#;
const SPHERE_LIGHT: &str = r#"<shape type="sphere"><point name="center" x="3" y="4" z="2"/><float name="radius" value="0.3"/>
    <emitter type="area"><rgb name="radiance" value="40, 40, 40"/></emitter></shape>"#;

/// The curved connection's top rate as built, checked to be the one the scene's options (which
/// SNEE's weight reads) hold too.
fn connection_rate(scene: &snee::scene::world::Scene) -> Option<f32> {
    match &scene.integrator {
        snee::integrator::desc::Integrator::VolpathSnee(d, s) => {
            assert_eq!(d.snee.connection_rate, s.options.connection_rate);
            s.options.connection_rate
        }
        _ => panic!("not volpath_snee"),
    }
}

fn forward_only(scene: &snee::scene::world::Scene) -> bool {
    match &scene.integrator {
        snee::integrator::desc::Integrator::VolpathSnee(_, s) => s.forward_only,
        _ => panic!("not volpath_snee"),
    }
}

/// Where nothing of `volpath_snee` runs (`Snee::forward_only`), it renders with volpath's loop:
/// the same statistics and ray counts, bit for bit. The rule is decided at scene load; where a
/// technique applies (a sphere light, which the curved connection serves; SNEE at its default
/// rate under `paper`) the loop is `volpath_snee`'s.
#[test]
fn forward_only_where_nothing_applies() {
    let complete = r#"<string name="connection" value="complete"/>"#;
    let vp = scene(&smooth_sphere("volpath", "", ENVMAP), &[]);
    let idle = scene(&smooth_sphere("volpath_snee", complete, ENVMAP), &[]);
    assert!(forward_only(&idle));
    let (a, b) = (render_batches(&vp, 2, 4, 8, 9000), render_batches(&idle, 2, 4, 8, 9000));
    assert_eq!((a.stats, a.rays), (b.stats, b.rays));
    // `snee = forward` is volpath wherever SNEE applies (here: rough glass, default rate).
    let fwd = scene(&xml("volpath_snee", r#"<string name="snee" value="forward"/>"#), &[]);
    assert!(forward_only(&fwd));
    let (a, b) = (render_batches(&scene(&xml("volpath", ""), &[]), 2, 4, 8, 9100), render_batches(&fwd, 2, 4, 8, 9100));
    assert_eq!((a.stats, a.rays), (b.stats, b.rays));
    // A sphere light through this thin medium (optical size 2): the curved area-light connection
    // runs at the default top rate of `curved_finite::default_top_rate`, (1/256) / m(2) with
    // m(τ) = (1 − e^{−τ})/τ, so volpath_snee's loop runs; likewise with a rate given, or a thicker
    // medium (σt 3, optical size 6: (1/256) / m(6)). The options every technique reads (SNEE's weight
    // reads the scene's) hold the rate as built.
    let thin = scene(&smooth_sphere("volpath_snee", complete, SPHERE_LIGHT), &[]);
    assert!(!forward_only(&thin));
    let m = |tau: f64| (1.0 - (-tau).exp()) / tau;
    let close = |q: Option<f32>, want: f64| q.is_some_and(|q| (q as f64 / want - 1.0).abs() < 1e-6);
    assert!(close(connection_rate(&thin), (1.0 / 256.0) / m(2.0)), "{:?}", connection_rate(&thin));
    let rate = format!(r#"{complete}<float name="connection_rate" value="0.05"/>"#);
    let given = scene(&smooth_sphere("volpath_snee", &rate, SPHERE_LIGHT), &[]);
    assert!(!forward_only(&given));
    assert_eq!(connection_rate(&given), Some(0.05));
    let thick = smooth_sphere("volpath_snee", complete, SPHERE_LIGHT)
        .replace(r#"<float name="sigma_t" value="1"/>"#, r#"<float name="sigma_t" value="3"/>"#);
    let thick = scene(&thick, &[]);
    assert!(!forward_only(&thick));
    assert!(close(connection_rate(&thick), (1.0 / 256.0) / m(6.0)), "{:?}", connection_rate(&thick));
    // Optical size 20: the rule reaches `RATE` and leaves the option unset (`RATE` stands).
    let thicker = smooth_sphere("volpath_snee", complete, SPHERE_LIGHT)
        .replace(r#"<float name="sigma_t" value="1"/>"#, r#"<float name="sigma_t" value="10"/>"#);
    assert_eq!(connection_rate(&scene(&thicker, &[])), None);
    // A directional light: the camera's glints run on the glass even where the medium does not
    // sample emitters (no SNEE, no connection).
    let sun = r#"<emitter type="directional"><vector name="direction" value="0, -1, -1"/></emitter>"#;
    let quiet = smooth_sphere("volpath_snee", complete, sun).replace(
        r#"<float name="sigma_t" value="1"/>"#,
        r#"<float name="sigma_t" value="1"/><boolean name="sample_emitters" value="false"/>"#,
    );
    assert!(!forward_only(&scene(&quiet, &[])));
    // Techniques that apply keep volpath_snee's loop.
    assert!(!forward_only(&scene(&smooth_sphere("volpath_snee", "", SPHERE_LIGHT), &[])));
    assert!(!forward_only(&scene(&xml("volpath_snee", ""), &[])));
    let snee_only = r#"<string name="transport" value="snee"/><float name="snee_rate" value="0"/>"#;
    assert!(!forward_only(&scene(&xml("volpath_snee", snee_only), &[])));
}
