//! Helpers shared by the integration tests: scenes from XML text, renders in independent batches,
//! and a Welch t-test on batch means with Šidák's correction (Student's t and Šidák from
//! `snee::testing`, so no test re-implements them).
#![allow(dead_code, clippy::needless_range_loop)]

use snee::render::{render, RenderOptions};
use snee::scene::build::build_scene;
use snee::scene::world::Scene;
use snee::scene::xml::parse_str;
pub use snee::testing::chi2::sidak;
pub use snee::testing::student_t::t_p_value;
use std::path::PathBuf;
use std::sync::atomic::AtomicBool;

pub fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// Build a scene from XML text (assets resolve against `scenes/`).
pub fn scene(xml: &str, defines: &[(&str, &str)]) -> Scene {
    let defines: Vec<(String, String)> = defines.iter().map(|(k, v)| (k.to_string(), v.to_string())).collect();
    let parsed = parse_str(xml, "test.xml", &root().join("scenes"), &defines).unwrap_or_else(|e| panic!("{}", e));
    build_scene(&parsed).unwrap_or_else(|e| panic!("{}", e))
}

/// Per-batch statistics of a render: mean over the image and over `block`×`block` blocks, RGB.
pub struct Batches {
    /// [batch][statistic][channel]; statistic 0 = image mean, then the blocks.
    pub stats: Vec<Vec<[f64; 3]>>,
    pub rejected: u64,
    pub rays: u64,
}

pub fn render_batches(scene: &Scene, batches: usize, spp: u32, block: usize, seed0: u64) -> Batches {
    let cancel = AtomicBool::new(false);
    let mut out = Batches { stats: Vec::new(), rejected: 0, rays: 0 };
    for b in 0..batches {
        let opts = RenderOptions { spp: Some(spp), seed: seed0 + b as u64, time_budget: None, progress: false };
        let img = render(scene, &opts, &cancel);
        out.rejected += img.stats.rejected_samples;
        out.rays += img.stats.rays;
        let (w, h, nch) = (img.width, img.height, img.channels.len());
        let (bw, bh) = (w.div_ceil(block), h.div_ceil(block));
        let mut s = vec![[0.0f64; 3]; 1 + bw * bh];
        let mut n = vec![0usize; 1 + bw * bh];
        for y in 0..h {
            for x in 0..w {
                let k = 1 + (y / block) * bw + x / block;
                for c in 0..3 {
                    let v = img.data[(y * w + x) * nch + c] as f64;
                    assert!(v.is_finite(), "non-finite pixel");
                    s[0][c] += v;
                    s[k][c] += v;
                }
                n[0] += 1;
                n[k] += 1;
            }
        }
        for (si, ni) in s.iter_mut().zip(&n) {
            for v in si.iter_mut() {
                *v /= *ni as f64;
            }
        }
        out.stats.push(s);
    }
    out
}

/// Sample mean and (unbiased) variance.
pub fn mean_var(v: &[f64]) -> (f64, f64) {
    let n = v.len() as f64;
    let m = v.iter().sum::<f64>() / n;
    (m, v.iter().map(|x| (x - m) * (x - m)).sum::<f64>() / (n - 1.0))
}

/// Welch's test of equal means of every statistic and channel, Šidák-corrected at `alpha`.
/// Returns a report of the failures (empty when all pass) and the image means.
pub fn welch_compare(a: &Batches, b: &Batches, alpha: f64) -> (String, [f64; 3], [f64; 3]) {
    let n_stats = a.stats[0].len();
    let tests = n_stats * 3;
    let level = sidak(alpha, tests);
    let mut report = String::new();
    let mut means = ([0.0; 3], [0.0; 3]);
    for s in 0..n_stats {
        for c in 0..3 {
            let va: Vec<f64> = a.stats.iter().map(|x| x[s][c]).collect();
            let vb: Vec<f64> = b.stats.iter().map(|x| x[s][c]).collect();
            let ((ma, sa), (mb, sb)) = (mean_var(&va), mean_var(&vb));
            if s == 0 {
                means.0[c] = ma;
                means.1[c] = mb;
            }
            let (qa, qb) = (sa / va.len() as f64, sb / vb.len() as f64);
            let se2 = qa + qb;
            if se2 == 0.0 {
                if ma != mb {
                    report += &format!("stat {} ch {}: {} vs {} with zero variance\n", s, c, ma, mb);
                }
                continue;
            }
            let t = (ma - mb) / se2.sqrt();
            let dof = se2 * se2 / (qa * qa / (va.len() as f64 - 1.0) + qb * qb / (vb.len() as f64 - 1.0)).max(1e-300);
            let p = t_p_value(t.abs(), dof.max(1.0));
            if p < level {
                report += &format!("stat {} ch {}: {:.6} vs {:.6} (t = {:.2}, p = {:.2e})\n", s, c, ma, mb, t, p);
            }
        }
    }
    (report, means.0, means.1)
}

/// Relative standard error of the image mean (channel-averaged) of a batch set.
pub fn rel_std_error(a: &Batches) -> f64 {
    let v: Vec<f64> = a.stats.iter().map(|x| (x[0][0] + x[0][1] + x[0][2]) / 3.0).collect();
    let (m, var) = mean_var(&v);
    (var / v.len() as f64).sqrt() / m.abs().max(1e-300)
}

/// A 1×1 film's reading (e.g. an `irradiancemeter`) over `batches` renders with seeds `seed0`,
/// `seed0 + 1`, ...: (mean, standard error of the mean, rejected samples).
pub fn meter_reading(scene: &Scene, spp: u32, batches: u64, seed0: u64) -> (f64, f64, u64) {
    let cancel = AtomicBool::new(false);
    let mut v = Vec::new();
    let mut rejected = 0;
    for b in 0..batches {
        let opts = RenderOptions { spp: Some(spp), seed: seed0 + b, time_budget: None, progress: false };
        let out = render(scene, &opts, &cancel);
        rejected += out.stats.rejected_samples;
        v.push(out.data[0] as f64);
    }
    let (m, var) = mean_var(&v);
    (m, (var / v.len() as f64).sqrt(), rejected)
}

/// A slab 200 mean free paths wide and 100 deep (σt = 1, albedo `albedo`, HG `g`), its top face at
/// z = 0, bounded by the BSDF `boundary` (XML), under a directional beam travelling along −z, read
/// by an `irradiancemeter` on a 10×10 `null` quad facing down just above it.
pub fn slab_xml(integrator: &str, albedo: f64, g: f64, boundary: &str) -> String {
    let integrator = format!(r#"<integrator type="{integrator}"><integer name="max_depth" value="-1"/></integrator>"#);
    slab_scene(&integrator, "0, 0, -1", albedo, g, boundary)
}

/// The slab of [`slab_xml`] with the whole `<integrator>` element given and the beam travelling
/// along `direction` (XML vector text).
pub fn slab_scene(integrator: &str, direction: &str, albedo: f64, g: f64, boundary: &str) -> String {
    let phase = if g == 0.0 {
        r#"<phase type="isotropic"/>"#.to_string()
    } else {
        format!(r#"<phase type="hg"><float name="g" value="{g}"/></phase>"#)
    };
    format!(
        r#"<scene version="3.0.0">
    {integrator}
    <emitter type="directional"><vector name="direction" value="{direction}"/><rgb name="irradiance" value="1, 1, 1"/></emitter>
    <medium type="homogeneous" id="slab"><float name="albedo" value="{albedo}"/><float name="sigma_t" value="1"/>{phase}</medium>
    <shape type="cube">
        <transform name="to_world"><scale x="100" y="100" z="50"/><translate z="-50"/></transform>
        {boundary}
        <ref name="interior" id="slab"/>
    </shape>
    <shape type="rectangle">
        <transform name="to_world"><scale value="5"/><rotate x="1" angle="180"/><translate z="0.01"/></transform>
        <bsdf type="null"/>
        <sensor type="irradiancemeter">
            <film type="hdrfilm"><integer name="width" value="1"/><integer name="height" value="1"/><rfilter type="box"/></film>
        </sensor>
    </shape>
</scene>"#
    )
}

/// A smooth glass boundary (`dielectric`, n = 1.5) and an index-matched one (int = ext = 1: no
/// refraction, no Fresnel), the two boundaries of the manifold tests.
pub const GLASS: &str = r#"<bsdf type="dielectric"><float name="int_ior" value="1.5"/></bsdf>"#;
pub const MATCHED: &str =
    r#"<bsdf type="dielectric"><float name="int_ior" value="1"/><float name="ext_ior" value="1"/></bsdf>"#;

/// `volpath_snee` with `connection = complete` (`snee = mis` and `snee = forward`) against a
/// `volpath` reference: no rejected sample, and both agree at family-wise level 1 % (Šidák over 2).
pub fn assert_complete_agrees(volpath: &Batches, mis: &Batches, fwd: &Batches) {
    assert_eq!(mis.rejected + fwd.rejected, 0);
    let report = agree_with_reference(("volpath", volpath), &[("complete mis", mis), ("complete forward", fwd)], 0.01);
    assert!(report.is_empty(), "{report}");
}

/// Compare several estimators with one reference (Welch, Šidák over the comparisons at family-wise
/// `alpha`), print every image mean and relative standard error, and return the failures' report
/// (empty when all agree).
pub fn agree_with_reference(reference: (&str, &Batches), others: &[(&str, &Batches)], alpha: f64) -> String {
    let alpha = 1.0 - (1.0 - alpha).powf(1.0 / others.len() as f64);
    let mut report = String::new();
    for (name, b) in others {
        let (r, m_ref, m) = welch_compare(reference.1, b, alpha);
        eprintln!("{} {m_ref:?} (rel. s.e. {:.2} %)", reference.0, 100.0 * rel_std_error(reference.1));
        eprintln!("{name} {m:?} (rel. s.e. {:.2} %)", 100.0 * rel_std_error(b));
        if !r.is_empty() {
            report += &format!("{} vs {name}:\n{r}", reference.0);
        }
    }
    report
}

/// A 24×24 view of a cube (rotated 20° about z) of grey HG medium (σt = 2, g = 0.4, albedo
/// 0.9/0.8/0.7) with boundary `bsdf`, lit by `emitter`; `props` go into the `<integrator>` after
/// `max_depth = -1` (the manifold tests).
pub fn medium_cube(integrator: &str, props: &str, bsdf: &str, emitter: &str) -> String {
    format!(
        r#"<scene version="3.0.0">
<integrator type="{integrator}"><integer name="max_depth" value="-1"/>{props}</integrator>
<sensor type="perspective"><float name="fov" value="40"/>
    <transform name="to_world"><lookat origin="2.5, -3.5, 2.5" target="0, 0, 0" up="0, 0, 1"/></transform>
    <film type="hdrfilm"><integer name="width" value="24"/><integer name="height" value="24"/></film></sensor>
{emitter}
<medium type="homogeneous" id="m"><float name="sigma_t" value="2"/>
    <rgb name="albedo" value="0.9, 0.8, 0.7"/><phase type="hg"><float name="g" value="0.4"/></phase></medium>
<shape type="cube">
    <transform name="to_world"><rotate z="1" angle="20"/></transform>
    {bsdf}
    <ref name="interior" id="m"/></shape>
</scene>"#
    )
}

/// Largest relative difference |x − y| / max(|x|, |y|) over every pixel of every channel of `a`
/// except those named in `skip` (each looked up by name in `b`, which must have it; values both
/// zero count as equal). The check of renders that must agree up to float summation order
/// (merged sample ranges, resumed checkpoints).
pub fn max_rel_diff(a: &snee::io::read::Bitmap, b: &snee::io::read::Bitmap, skip: &[&str]) -> f32 {
    assert_eq!((a.width, a.height), (b.width, b.height));
    let mut worst = 0.0f32;
    for (ca, name) in a.channels.iter().enumerate() {
        if skip.contains(&name.as_str()) {
            continue;
        }
        let cb = b.channel(name).unwrap_or_else(|| panic!("channel {name} missing"));
        for i in 0..a.width * a.height {
            let (x, y) = (a.data[i * a.channels.len() + ca], b.data[i * b.channels.len() + cb]);
            let scale = x.abs().max(y.abs());
            if scale > 0.0 {
                worst = worst.max((x - y).abs() / scale);
            }
        }
    }
    worst
}
