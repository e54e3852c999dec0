//! Clear refusals before work starts: zero or negative sample counts, and films, meshes and
//! textures whose declared sizes need more memory than the machine has (`SNEE_MEMORY_AVAILABLE`
//! stands in for a small machine). Each exits non-zero with a message naming the parameter and,
//! for scene input, its `file:line:col`.

use crate::snee;
use std::path::PathBuf;
use std::process::Output;

fn out_dir(name: &str) -> PathBuf {
    let d = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("target/test-output/refusals").join(name);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// The run failed, wrote nothing to `out`, and its stderr contains every needle.
fn refused(o: &Output, out: Option<&PathBuf>, needles: &[&str]) {
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(!o.status.success(), "expected a refusal, got success; stderr:\n{err}");
    for n in needles {
        assert!(err.contains(n), "missing {n:?} in:\n{err}");
    }
    assert!(!err.contains("panicked"), "{err}");
    if let Some(p) = out {
        assert!(!p.exists(), "{} was written", p.display());
    }
}

const SCENE: &str = r#"<scene version="3.0.0">
    <default name="w" value="32"/>
    <default name="h" value="24"/>
    <sensor type="perspective">
        <film type="hdrfilm">
            <integer name="width" value="$w"/>
            <integer name="height" value="$h"/>
        </film>
    </sensor>
    <shape type="sphere"><emitter type="area"/></shape>
</scene>
"#;

#[test]
fn zero_and_negative_spp_are_refused() {
    let d = out_dir("spp");
    let scene = d.join("s.xml");
    std::fs::write(&scene, SCENE).unwrap();
    let out = d.join("out.exr");
    let _ = std::fs::remove_file(&out);
    for (spp, msg) in [("0", "got 0"), ("-3", "got -3"), ("two", "got \"two\"")] {
        let o = snee()
            .args(["render", scene.to_str().unwrap(), "-q", "--spp", spp, "-o", out.to_str().unwrap()])
            .output()
            .unwrap();
        refused(&o, Some(&out), &["--spp", msg]);
    }
    // The scene's own count: sample_count 0 names its position.
    let zero = d.join("zero.xml");
    std::fs::write(
        &zero,
        SCENE.replace(
            "</film>",
            "</film>\n        <sampler type=\"independent\"><integer name=\"sample_count\" value=\"0\"/></sampler>",
        ),
    )
    .unwrap();
    let o = snee().args(["render", zero.to_str().unwrap(), "-q", "-o", out.to_str().unwrap()]).output().unwrap();
    refused(&o, Some(&out), &["zero.xml:9:", "sample_count", "got 0"]);
    // A positive count renders.
    let o = snee()
        .args(["render", scene.to_str().unwrap(), "-q", "--spp", "1", "-o", out.to_str().unwrap()])
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
}

#[test]
fn a_film_larger_than_memory_is_refused_at_its_width() {
    let d = out_dir("film");
    let scene = d.join("film.xml");
    std::fs::write(&scene, SCENE).unwrap();
    let out = d.join("out.exr");
    let _ = std::fs::remove_file(&out);
    // 65536 x 65536 RGB needs about 160 GiB: refused on any machine this test runs on.
    let o = snee()
        .args(["render", scene.to_str().unwrap(), "-q", "-D", "w=65536", "-D", "h=65536", "-o", out.to_str().unwrap()])
        .output()
        .unwrap();
    refused(&o, Some(&out), &["film.xml:6:", "width x height 65536 x 65536", "needs about 160.0 GiB", "available"]);
    // With 1 MiB available, a 32 x 24 film (30 KiB) passes and a 512 x 512 one (10 MiB) does not.
    let o = snee().env("SNEE_MEMORY_AVAILABLE", "1M").args(["info", scene.to_str().unwrap()]).output().unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let o = snee()
        .env("SNEE_MEMORY_AVAILABLE", "1M")
        .args(["info", scene.to_str().unwrap(), "-D", "w=512", "-D", "h=512"])
        .output()
        .unwrap();
    refused(
        &o,
        None,
        &["film.xml:6:", "needs about 10.0 MiB", "only 1.0 MiB is available (set by SNEE_MEMORY_AVAILABLE)"],
    );
}

/// A binary PLY with `n` vertices at the origin and no faces.
fn ply(n: usize) -> Vec<u8> {
    let mut b = format!(
        "ply\nformat binary_little_endian 1.0\nelement vertex {n}\nproperty float x\nproperty float y\n\
         property float z\nelement face 0\nproperty list uchar int vertex_indices\nend_header\n"
    )
    .into_bytes();
    b.resize(b.len() + 12 * n, 0);
    b
}

#[test]
fn meshes_and_textures_larger_than_memory_are_refused_at_their_header() {
    let d = out_dir("assets");
    // 100000 vertices need about 6.1 MiB by the estimate; with 1 MiB available the PLY is refused
    // at its `element vertex` line, before any vertex is decoded.
    std::fs::write(d.join("big.ply"), ply(100_000)).unwrap();
    let scene = d.join("mesh.xml");
    std::fs::write(
        &scene,
        SCENE.replace(
            "<shape type=\"sphere\">",
            "<shape type=\"ply\"><string name=\"filename\" value=\"big.ply\"/></shape>\n    <shape type=\"sphere\">",
        ),
    )
    .unwrap();
    let o = snee().env("SNEE_MEMORY_AVAILABLE", "1M").args(["info", scene.to_str().unwrap()]).output().unwrap();
    refused(&o, None, &["big.ply:3:1: element vertex 100000", "needs about 6.1 MiB", "1.0 MiB is available"]);

    // A PNG whose header declares 20000 x 20000 RGBA pixels: refused at the texture's filename.
    let mut png = vec![0x89, b'P', b'N', b'G', 0x0d, 0x0a, 0x1a, 0x0a, 0, 0, 0, 13];
    png.extend_from_slice(b"IHDR");
    png.extend_from_slice(&20000u32.to_be_bytes());
    png.extend_from_slice(&20000u32.to_be_bytes());
    png.extend_from_slice(&[8, 6, 0, 0, 0, 0, 0, 0, 0]);
    std::fs::write(d.join("huge.png"), &png).unwrap();
    let scene = d.join("tex.xml");
    std::fs::write(
        &scene,
        SCENE.replace(
            "<shape type=\"sphere\">",
            "<shape type=\"sphere\">\n        <bsdf type=\"diffuse\"><texture type=\"bitmap\" name=\"reflectance\">\n            \
             <string name=\"filename\" value=\"huge.png\"/></texture></bsdf>",
        ),
    )
    .unwrap();
    let o = snee().env("SNEE_MEMORY_AVAILABLE", "1G").args(["info", scene.to_str().unwrap()]).output().unwrap();
    refused(&o, None, &["tex.xml:12:13: filename: the image (20000 x 20000, 4 channels) needs about 16.4 GiB"]);
}
