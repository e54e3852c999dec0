//! Distributed rendering: `--sample-range` parts merged with `snee merge` reproduce the
//! single-process render (locally and through a local Ray cluster started by the test), and
//! `merge` refuses parts that do not belong together.

mod common;

use snee::io::read::{read_image, Bitmap};
use std::path::{Path, PathBuf};
use std::process::Command;

const SNEE: &str = env!("CARGO_BIN_EXE_snee");
/// Tiny film, few samples: the Cornell box with second moments.
const SCENE: &str = "scenes/cornell_box.xml";
const FILM: [&str; 4] = ["-D", "width=24", "-D", "height=18"];
const SPP: u32 = 21;
const SEED: &str = "7";
/// Largest accepted relative difference per value: float rounding of sums of ≤ 21 positive
/// samples in a different grouping (f32 ε = 1.2e-7), far below the Monte Carlo noise a wrong
/// or repeated sample would cause (≥ 1e-2 at 21 spp).
const REL_TOL: f32 = 1e-5;
/// Channels not compared here: `W`, the filter-weight sums that partial renders carry.
const SKIP: &[&str] = &["W"];

fn folder(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("snee-distributed-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn snee(args: &[&str]) -> std::process::Output {
    let out = Command::new(SNEE).args(args).current_dir(env!("CARGO_MANIFEST_DIR")).output().unwrap();
    assert!(out.status.success(), "snee {args:?} failed: {}", String::from_utf8_lossy(&out.stderr));
    out
}

fn render(out: &Path, extra: &[&str]) {
    let spp = SPP.to_string();
    let mut args = vec!["render", SCENE, "-o", out.to_str().unwrap(), "--spp", &spp, "--seed", SEED, "--moment", "-q"];
    args.extend(FILM);
    args.extend(extra);
    snee(&args);
}

fn single_run(dir: &Path) -> Bitmap {
    let full = dir.join("single.exr");
    render(&full, &[]);
    let img = read_image(&full, false).unwrap();
    assert!(img.channel("m2.R").is_some());
    // Not a flat image: the comparison means something.
    let r = img.channel("R").unwrap();
    let distinct: std::collections::BTreeSet<u32> =
        img.data.chunks(img.channels.len()).map(|p| p[r].to_bits()).collect();
    assert!(distinct.len() > 100, "{} distinct values", distinct.len());
    img
}

/// Cuts of 0..SPP into `n` ranges of near-equal size (most start inside a sampler chunk).
fn cuts(n: u32) -> Vec<(u32, u32)> {
    (0..n).map(|k| (SPP * k / n, SPP * (k + 1) / n)).collect()
}

#[test]
fn ranges_2_3_7_merge_to_the_single_run() {
    let dir = folder("split");
    let single = single_run(&dir);
    for n in [2u32, 3, 7] {
        let mut parts = Vec::new();
        for (s, e) in cuts(n) {
            let p = dir.join(format!("part{n}_{s}_{e}.exr"));
            render(&p, &["--sample-range", &format!("{s}..{e}")]);
            parts.push(p.to_str().unwrap().to_string());
        }
        let merged = dir.join(format!("merged{n}.exr"));
        let mut args = vec!["merge", "-o", merged.to_str().unwrap(), "-q"];
        args.extend(parts.iter().rev().map(|s| s.as_str()));
        snee(&args);
        let m = read_image(&merged, false).unwrap();
        let d = common::max_rel_diff(&single, &m, SKIP);
        eprintln!("{n} ranges: max relative difference {d:e}");
        assert!(d <= REL_TOL, "{n} ranges: max relative difference {d:e}");
    }
    // A full range is the single run, and the merge of one full part is itself.
    let p = dir.join("full_range.exr");
    render(&p, &["--sample-range", &format!("0..{SPP}")]);
    assert_eq!(common::max_rel_diff(&single, &read_image(&p, false).unwrap(), SKIP), 0.0);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn merge_refuses_parts_of_different_runs_and_names_missing_ranges() {
    let dir = folder("refuse");
    let a = dir.join("a.exr");
    let b = dir.join("b.exr");
    let c = dir.join("c.exr");
    render(&a, &["--sample-range", "0..5"]);
    render(&b, &["--sample-range", "9..21"]);
    let spp = SPP.to_string();
    let mut args = vec!["render", SCENE, "-o", c.to_str().unwrap(), "--spp", &spp, "--seed", "8", "--moment", "-q"];
    args.extend(FILM);
    args.extend(["--sample-range", "5..9"]);
    snee(&args);
    let merge = |parts: &[&Path]| {
        let mut cmd = Command::new(SNEE);
        cmd.args(["merge", "-o", dir.join("m.exr").to_str().unwrap()]).args(parts);
        let out = cmd.output().unwrap();
        (out.status.success(), String::from_utf8_lossy(&out.stderr).into_owned())
    };
    let (ok, msg) = merge(&[&a, &b]);
    assert!(!ok && msg.contains("5..9"), "{msg}");
    let (ok, msg) = merge(&[&a, &b, &c]);
    assert!(!ok && msg.contains("seed"), "{msg}");
    let (ok, msg) = merge(&[&a, &a]);
    assert!(!ok && msg.contains("overlap"), "{msg}");
    // A plain render has no part metadata.
    let plain = dir.join("plain.exr");
    let mut args = vec!["render", SCENE, "-o", plain.to_str().unwrap(), "--spp", "2", "-q"];
    args.extend(FILM);
    snee(&args);
    let (ok, msg) = merge(&[&plain]);
    assert!(!ok && msg.contains("plain.exr"), "{msg}");
    let _ = std::fs::remove_dir_all(&dir);
}

/// Python with Ray, installing `scripts/requirements-ray.txt` when `import ray` fails.
fn python_with_ray() -> &'static str {
    let has_ray = || Command::new("python3").args(["-c", "import ray"]).output().map(|o| o.status.success());
    match has_ray() {
        Err(e) => panic!("python3 is needed for the Ray test: {e}"),
        Ok(true) => {}
        Ok(false) => {
            let st = Command::new("python3")
                .args(["-m", "pip", "install", "-q", "-r", "scripts/requirements-ray.txt"])
                .current_dir(env!("CARGO_MANIFEST_DIR"))
                .status()
                .unwrap();
            assert!(st.success(), "installing scripts/requirements-ray.txt failed");
            assert!(has_ray().unwrap(), "ray still not importable after installing it");
        }
    }
    "python3"
}

/// Through a local Ray cluster started by the driver: 3 tasks, one of whose workers is killed
/// (SIGKILL) on its first attempt by a wrapper around snee, so the task must be retried; the merged
/// image matches the single-process render.
#[test]
fn ray_local_cluster_merge_matches_single_process() {
    let python = python_with_ray();
    let dir = folder("ray");
    let single = single_run(&dir);
    let wrapper = dir.join("snee-killing-its-worker.sh");
    let marker = dir.join("worker-killed");
    std::fs::write(
        &wrapper,
        format!(
            "#!/bin/sh\nif [ \"$1\" = render ] && mkdir {marker} 2>/dev/null; then kill -9 $PPID; sleep 10; exit 1; fi\nexec {SNEE} \"$@\"\n",
            marker = marker.display()
        ),
    )
    .unwrap();
    use std::os::unix::fs::PermissionsExt;
    std::fs::set_permissions(&wrapper, std::fs::Permissions::from_mode(0o755)).unwrap();
    let out = dir.join("ray.exr");
    let spp = SPP.to_string();
    let mut args = vec!["scripts/ray_render.py", SCENE, "-o", out.to_str().unwrap(), "--spp", &spp];
    args.extend(["--seed", SEED, "--moment", "--tasks", "3", "--num-cpus", "2", "-q"]);
    args.extend(["--snee", wrapper.to_str().unwrap()]);
    args.extend(FILM);
    let st = Command::new(python).args(&args).current_dir(env!("CARGO_MANIFEST_DIR")).output().unwrap();
    assert!(st.status.success(), "ray_render.py failed: {}", String::from_utf8_lossy(&st.stderr));
    assert!(marker.exists(), "no worker was killed: the retry was not exercised");
    let merged = read_image(&out, false).unwrap();
    let d = common::max_rel_diff(&single, &merged, SKIP);
    eprintln!("Ray, 3 tasks, one worker killed and its task retried: max relative difference {d:e}");
    assert!(d <= REL_TOL, "Ray: max relative difference {d:e}");
    let _ = std::fs::remove_dir_all(&dir);
}
