//! The `snee` command line: summaries, errors with `file:line:col`, render options, statistics
//! and determinism across thread counts.

use crate::snee;
use std::path::PathBuf;

fn out_dir() -> PathBuf {
    let d = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("target/test-output/cli");
    std::fs::create_dir_all(&d).unwrap();
    d
}

#[test]
fn info_summarises_a_scene() {
    let o = snee().args(["info", "scenes/directional_area.xml"]).output().unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let text = String::from_utf8_lossy(&o.stdout);
    for needle in
        ["integrator path", "shape serialized", "triangles:", "bounds:", "emitters: 3", "film: 128x96", "spp: 64"]
    {
        assert!(text.contains(needle), "missing {:?} in:\n{}", needle, text);
    }
    let o = snee().args(["info", "scenes/cornell_box.xml", "--json", "-D", "spp=7"]).output().unwrap();
    assert!(o.status.success());
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(v["spp"], 7);
    assert!(v["triangles"].as_u64().unwrap() > 0);
}

#[test]
fn errors_name_file_line_and_column() {
    let dir = out_dir();
    let bad = dir.join("bad.xml");
    std::fs::write(
        &bad,
        "<scene version=\"3.0.0\">\n    <bsdf type=\"roughdielectric\">\n        <float name=\"alhpa\" value=\"0.1\"/>\n    </bsdf>\n</scene>\n",
    )
    .unwrap();
    let o = snee().args(["info", bad.to_str().unwrap()]).output().unwrap();
    assert!(!o.status.success());
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.starts_with(&format!("{}:3:9:", bad.display())), "{}", err);
    assert!(err.contains("alhpa") && err.contains("alpha"), "{}", err);

    // Unknown plugin, missing file, unused -D, malformed -D: all non-zero with a message.
    std::fs::write(&bad, "<scene version=\"3.0.0\">\n  <shape type=\"teapot\"/>\n</scene>\n").unwrap();
    let o = snee().args(["info", bad.to_str().unwrap()]).output().unwrap();
    assert!(!o.status.success() && String::from_utf8_lossy(&o.stderr).contains(":2:3:"));
    let o = snee().args(["info", "scenes/does_not_exist.xml"]).output().unwrap();
    assert!(!o.status.success() && String::from_utf8_lossy(&o.stderr).contains("does_not_exist.xml"));
    let o = snee().args(["info", "scenes/cornell_box.xml", "-D", "nonsense=1"]).output().unwrap();
    assert!(!o.status.success() && String::from_utf8_lossy(&o.stderr).contains("nonsense"));
    let o = snee().args(["render", "scenes/cornell_box.xml", "-D", "spp"]).output().unwrap();
    assert!(!o.status.success() && String::from_utf8_lossy(&o.stderr).contains("NAME=VALUE"));
}

#[test]
fn render_writes_exr_png_and_stats() {
    let dir = out_dir();
    let exr = dir.join("cornell.exr");
    let stats = dir.join("stats.json");
    let o = snee()
        .args(["render", "scenes/cornell_box.xml", "-o", exr.to_str().unwrap(), "--spp", "2", "--png", "-q"])
        .args(["--stats", stats.to_str().unwrap(), "-D", "width=32", "-D", "height=24"])
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(exr.with_extension("png").exists());
    let img = snee::io::read::read_image(&exr, false).unwrap();
    assert_eq!((img.width, img.height), (32, 24));
    let s: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&stats).unwrap()).unwrap();
    for key in ["seconds", "spp", "samples_per_second", "rays_per_second", "rejected_samples"] {
        assert!(s.get(key).is_some(), "stats lack {}", key);
    }
    assert_eq!(s["spp"], 2);
    assert_eq!(s["samples"], 2 * 32 * 24);
}

#[test]
fn time_budget_stops_the_render() {
    let dir = out_dir();
    let exr = dir.join("budget.exr");
    let stats = dir.join("budget.json");
    let t = std::time::Instant::now();
    let o = snee()
        .args(["render", "scenes/glass_envmap.xml", "-o", exr.to_str().unwrap(), "--time", "1", "-q"])
        .args(["--stats", stats.to_str().unwrap()])
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(t.elapsed().as_secs_f64() < 20.0);
    let s: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&stats).unwrap()).unwrap();
    assert!(s["spp"].as_u64().unwrap() >= 1);
    assert!(s["seconds"].as_f64().unwrap() < 5.0);
}

#[test]
fn same_seed_same_image_whatever_the_thread_count() {
    let dir = out_dir();
    let mut images = Vec::new();
    for threads in ["1", "2"] {
        let exr = dir.join(format!("det{}.exr", threads));
        let o = snee()
            .args([
                "render",
                "scenes/rough_glass_ggx.xml",
                "-o",
                exr.to_str().unwrap(),
                "--spp",
                "3",
                "--seed",
                "9",
                "-q",
            ])
            .args(["--threads", threads, "-D", "width=40", "-D", "height=30"])
            .output()
            .unwrap();
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        images.push(snee::io::read::read_image(&exr, false).unwrap().data);
    }
    let differing = images[0].iter().zip(&images[1]).filter(|(a, b)| a.to_bits() != b.to_bits()).count();
    assert_eq!(differing, 0, "{} values differ between 1 and 2 threads", differing);
}

#[test]
fn compare_reports_metrics_and_z_test() {
    let dir = out_dir();
    let exr = dir.join("cmp.exr");
    let o = snee()
        .args(["render", "scenes/cornell_box.xml", "-o", exr.to_str().unwrap(), "--spp", "16", "--moment", "-q"])
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let o = snee()
        .args(["compare", exr.to_str().unwrap(), "reference/cornell_box.exr", "--spp-a", "16", "--json"])
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert!((v["mean_ratio"].as_f64().unwrap() - 1.0).abs() < 0.05);
    assert!(v["rel_mse"].as_f64().unwrap() > 0.0);
    assert!(v["z_test"]["tests"].as_u64().unwrap() == 96 * 96 * 3);
}

#[test]
fn convergence_csv_at_doubling_sample_counts() {
    let dir = out_dir();
    let csv = dir.join("conv.csv");
    let o = snee()
        .args(["render", "scenes/cornell_box.xml", "-o", dir.join("conv.exr").to_str().unwrap(), "--spp", "16", "-q"])
        .args(["--reference", "reference/cornell_box.exr", "--convergence", csv.to_str().unwrap()])
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let text = std::fs::read_to_string(&csv).unwrap();
    let rows: Vec<Vec<f64>> =
        text.lines().skip(1).map(|l| l.split(',').map(|v| v.parse::<f64>().unwrap()).collect()).collect();
    assert_eq!(rows.iter().map(|r| r[1] as u32).collect::<Vec<_>>(), vec![1, 2, 4, 8, 16]);
    // An unbiased render's relMSE roughly halves with every doubling of the samples.
    assert!(rows[4][2] < rows[0][2] / 4.0, "{}", text);
    assert!(rows.windows(2).all(|w| w[1][0] >= w[0][0]));
}
