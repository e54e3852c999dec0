//! Transport-class channels (`snee render --classes`, docs/classes.md): they sum to the image on
//! every paper configuration with every integrator, a slab whose single scattering is known
//! analytically puts exactly that into `single`, and `snee merge` keeps the classes.

mod common;

use snee::integrator::classes::{PathClass, N_CLASSES};
use snee::integrator::manifold::Connection;
use snee::integrator::{self, IntegratorKind};
use snee::io::read::read_image;
use snee::render::{render, RenderOptions, RenderOutput};
use snee::scene::build::build_scene;
use snee::scene::world::Scene;
use snee::scene::xml::parse_file;
use std::process::Command;
use std::sync::atomic::AtomicBool;

fn render_opts(scene: &Scene, spp: u32, seed: u64) -> RenderOutput {
    let opts = RenderOptions { spp: Some(spp), seed, time_budget: None, progress: false };
    render(scene, &opts, &AtomicBool::new(false))
}

/// The value of channel `name` at pixel `i`.
fn channel(out: &RenderOutput, name: &str, i: usize) -> f32 {
    let c = out.channels.iter().position(|c| c == name).unwrap_or_else(|| panic!("no channel {name}"));
    out.data[i * out.channels.len() + c]
}

/// Switch `scene` to integrator `kind` (with `connection` for `volpath_snee`), classes and moments on.
fn set_integrator(scene: &mut Scene, kind: IntegratorKind, connection: Connection) {
    let mut desc = (*scene.integrator).clone();
    desc.kind = kind;
    desc.connection = connection;
    desc.moment = true;
    desc.classes = true;
    scene.integrator = integrator::build(desc, scene);
}

/// Every paper configuration (scenes/paper/*.xml, 12×16 pixels, 4 spp) with every integrator:
/// per pixel and channel, the classes sum to the image up to float rounding (the image and the
/// classes add the same contributions in another grouping: a few ulps of the largest term), each
/// class's second moment is at least its squared mean (box filter: the mean of squared samples),
/// and `path` puts everything into `surface`.
#[test]
fn classes_sum_to_the_image_on_every_paper_configuration() {
    let dir = common::root().join("scenes/paper");
    let mut files: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| {
            p.extension().is_some_and(|e| e == "xml") && !p.file_name().unwrap().to_string_lossy().starts_with('.')
        })
        .collect();
    files.sort();
    assert_eq!(files.len(), 18, "the 18 paper configurations");
    let defines = vec![("width".to_string(), "12".to_string()), ("height".to_string(), "16".to_string())];
    let methods = [
        (IntegratorKind::Path, Connection::Paper),
        (IntegratorKind::Volpath, Connection::Paper),
        (IntegratorKind::Volpathmis, Connection::Paper),
        (IntegratorKind::VolpathSnee, Connection::Paper),
        (IntegratorKind::VolpathSnee, Connection::Complete),
    ];
    let mut worst = 0.0f32;
    for file in &files {
        let mut scene = build_scene(&parse_file(file, &defines).unwrap()).unwrap();
        for (kind, connection) in methods {
            set_integrator(&mut scene, kind, connection);
            let out = render_opts(&scene, 4, 11);
            let name = format!("{} {kind:?} {}", file.file_name().unwrap().to_string_lossy(), connection.name());
            let mut non_surface = 0.0f32;
            for i in 0..out.width * out.height {
                for c in ["R", "G", "B"] {
                    let image = channel(&out, c, i);
                    let values: Vec<f32> =
                        PathClass::ALL.iter().map(|k| channel(&out, &format!("{}.{c}", k.name()), i)).collect();
                    let sum: f32 = values.iter().sum();
                    let scale: f32 = values.iter().map(|v| v.abs()).sum::<f32>().max(image.abs());
                    let diff = (sum - image).abs();
                    if scale > 0.0 {
                        worst = worst.max(diff / scale);
                    }
                    assert!(diff <= 1e-5 * scale + 1e-30, "{name}: pixel {i} {c}: classes sum to {sum}, image {image}");
                    for (k, v) in PathClass::ALL.iter().zip(&values) {
                        let m2 = channel(&out, &format!("{}.m2.{c}", k.name()), i);
                        assert!(v.is_finite() && m2.is_finite(), "{name}: non-finite {}", k.name());
                        assert!(m2 >= v * v * (1.0 - 1e-5), "{name}: {}.m2.{c} = {m2} < mean² = {}", k.name(), v * v);
                    }
                    non_surface += values[1..].iter().map(|v| v.abs()).sum::<f32>();
                }
            }
            if kind == IntegratorKind::Path {
                assert_eq!(non_surface, 0.0, "{name}: path must put everything into `surface`");
            }
        }
    }
    eprintln!("largest relative difference between the class sum and the image: {worst:.2e}");
}

/// Single scattering of a semi-infinite index-matched slab (albedo `a`, isotropic phase) under a
/// normal collimated beam of irradiance 1, read as radiant exitance: L(μ) = a/(4π)·1/(1 + μ), so
/// M = 2π ∫₀¹ L(μ) μ dμ = (a/2)(1 − ln 2).
fn single_scattering_exitance(albedo: f64) -> f64 {
    albedo / 2.0 * (1.0 - std::f64::consts::LN_2)
}

/// The `null`-bounded slab under a directional beam (tests/common's slab): `single` (V–L, one
/// medium vertex) must read the analytic single-scattering exitance, with every bounce order
/// present (max_depth −1); with max_depth 2 only single scattering is possible and every other
/// class is exactly 0. For volpath, volpathmis and volpath_snee.
#[test]
fn single_class_is_analytic_single_scattering() {
    const N: usize = 16;
    const SPP: u32 = 16384;
    let albedo = 0.8;
    let expected = single_scattering_exitance(albedo);
    let mut report = Vec::new();
    let mut failures = Vec::new();
    for kind in ["volpath", "volpathmis", "volpath_snee"] {
        for max_depth in [-1, 2] {
            let integrator =
                format!(r#"<integrator type="{kind}"><integer name="max_depth" value="{max_depth}"/></integrator>"#);
            let xml = common::slab_scene(&integrator, "0, 0, -1", albedo, 0.0, r#"<bsdf type="null"/>"#);
            let mut scene = common::scene(&xml, &[]);
            scene.integrator.classes = true;
            let mut single = Vec::new();
            let mut image = Vec::new();
            for b in 0..N {
                let out = render_opts(&scene, SPP, 900 + b as u64);
                let others: f32 = PathClass::ALL
                    .iter()
                    .filter(|k| **k != PathClass::Single && **k != PathClass::Other)
                    .map(|k| channel(&out, &format!("{}.R", k.name()), 0).abs())
                    .sum();
                assert_eq!(others, 0.0, "{kind} max_depth {max_depth}: a class that cannot occur is not 0");
                if max_depth == 2 {
                    assert_eq!(channel(&out, "other.R", 0), 0.0, "{kind}: multiple scattering at max_depth 2");
                }
                single.push(channel(&out, "single.R", 0) as f64);
                image.push(channel(&out, "R", 0) as f64);
            }
            let (m, var) = common::mean_var(&single);
            let se = (var / N as f64).sqrt();
            let (total, _) = common::mean_var(&image);
            let z = (m - expected) / se;
            report.push(format!(
                "{kind} max_depth {max_depth}: single {m:.5} ± {se:.5} (analytic {expected:.5}, z = {z:+.2}), image {total:.5}"
            ));
            // Family-wise level 1 % over the 6 cases (Šidák: |z| < 3.01), and a standard error
            // small enough that a 1 % error in `single` would be seen.
            if z.abs() > 3.01 || se / expected > 0.01 / 3.0 {
                failures.push(report.last().unwrap().clone());
            }
        }
    }
    eprintln!("{}", report.join("\n"));
    assert!(failures.is_empty(), "single scattering off:\n{}", failures.join("\n"));
}

/// `snee merge` of `--sample-range` parts rendered with `--classes --moment` gives the single run's
/// class channels (up to float summation order), and refuses to merge a part with classes and
/// one without.
#[test]
fn merge_keeps_the_classes() {
    let dir = std::env::temp_dir().join(format!("snee-classes-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let snee = |args: &[&str]| {
        Command::new(env!("CARGO_BIN_EXE_snee")).args(args).current_dir(env!("CARGO_MANIFEST_DIR")).output().unwrap()
    };
    let path = |n: &str| dir.join(n).to_str().unwrap().to_string();
    let scene = "scenes/paper/sphere_smooth_st02.xml";
    let base =
        ["-D", "width=12", "-D", "height=16", "-D", "integrator=volpath_snee", "--spp", "9", "--seed", "5", "-q"];
    let run = |out: &str, extra: &[&str]| {
        let mut args = vec!["render", scene, "-o", out];
        args.extend(base);
        args.extend(extra);
        let o = snee(&args);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    };
    run(&path("full.exr"), &["--classes", "--moment"]);
    run(&path("a.exr"), &["--classes", "--moment", "--sample-range", "0..4"]);
    run(&path("b.exr"), &["--classes", "--moment", "--sample-range", "4..9"]);
    run(&path("plain.exr"), &["--moment", "--sample-range", "4..9"]);
    let o = snee(&["merge", &path("a.exr"), &path("b.exr"), "-o", &path("merged.exr")]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let full = read_image(std::path::Path::new(&path("full.exr")), false).unwrap();
    let merged = read_image(std::path::Path::new(&path("merged.exr")), false).unwrap();
    let mut worst = 0.0f32;
    let mut class_channels = 0;
    for (cf, name) in full.channels.iter().enumerate() {
        let cm = merged.channel(name).unwrap_or_else(|| panic!("merge lost channel {name}"));
        class_channels += PathClass::ALL.iter().any(|k| name.starts_with(&format!("{}.", k.name()))) as usize;
        for i in 0..full.width * full.height {
            let (x, y) = (full.data[i * full.channels.len() + cf], merged.data[i * merged.channels.len() + cm]);
            let scale = x.abs().max(y.abs());
            if scale > 0.0 {
                worst = worst.max((x - y).abs() / scale);
            }
        }
    }
    assert_eq!(class_channels, N_CLASSES * 6, "class channels R, G, B and m2.R, m2.G, m2.B");
    // Float rounding of sums of ≤ 9 samples in another grouping (f32 ε = 1.2e-7).
    assert!(worst < 1e-5, "merged classes differ from the single run by {worst}");
    let o = snee(&["merge", &path("a.exr"), &path("plain.exr"), "-o", &path("bad.exr")]);
    assert!(!o.status.success(), "a part with classes merged with one without");
    let _ = std::fs::remove_dir_all(&dir);
}

/// Single scattering of the same slab behind a smooth dielectric (η = 1.5, normal beam): the beam
/// enters with irradiance 1 − F(1), the single-scattered radiance inside is
/// (1 − F(1))·a/(4π)·1/(1 + μ), and the exitance is the flux that leaves through the interface,
/// M = 2π ∫ (1 − F(μ)) μ (1 − F(1)) a/(4π)/(1 + μ) dμ over internal cosines μ (total internal
/// reflection: F = 1). Forward tracing cannot make these paths (delta light behind a delta
/// interface); `volpath_snee` with `connection = complete` makes them by the manifold connection,
/// and they must all land in `single`.
#[test]
fn single_class_behind_smooth_glass_is_analytic_single_scattering() {
    const N: usize = 16;
    const SPP: u32 = 16384;
    let (albedo, eta) = (0.8f64, 1.5f32);
    let t0 = 1.0 - snee::bsdf::fresnel::fresnel(1.0, eta).0 as f64;
    let steps = 20000;
    let expected: f64 = (0..steps)
        .map(|i| {
            let mu = (i as f64 + 0.5) / steps as f64;
            // Inside the medium: incidence from the η side (negative cosine in Mitsuba's convention).
            let t = 1.0 - snee::bsdf::fresnel::fresnel(-mu as f32, eta).0 as f64;
            0.5 * t * mu * t0 * albedo / (1.0 + mu) / steps as f64
        })
        .sum();
    let integrator = r#"<integrator type="volpath_snee"><integer name="max_depth" value="-1"/>
        <string name="connection" value="complete"/></integrator>"#;
    let boundary = format!(
        r#"<bsdf type="dielectric"><float name="int_ior" value="{eta}"/><float name="ext_ior" value="1"/></bsdf>"#
    );
    let xml = common::slab_scene(integrator, "0, 0, -1", albedo, 0.0, &boundary);
    let mut scene = common::scene(&xml, &[]);
    scene.integrator.classes = true;
    let single: Vec<f64> =
        (0..N).map(|b| channel(&render_opts(&scene, SPP, 1300 + b as u64), "single.R", 0) as f64).collect();
    let (m, var) = common::mean_var(&single);
    let se = (var / N as f64).sqrt();
    let z = (m - expected) / se;
    eprintln!("smooth slab: single {m:.5} ± {se:.5}, analytic {expected:.5}, z = {z:+.2}");
    // Level 1 % (|z| < 2.58), with a standard error that would show a 1 % error.
    assert!(z.abs() < 2.58 && se / expected < 0.01 / 2.58, "single {m} ± {se} vs analytic {expected}");
}
