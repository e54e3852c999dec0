//! Nothing lost: a render killed with SIGKILL after its first checkpoint resumes to the image of
//! an uninterrupted run; outputs are replaced atomically; `-o` writes what its extension says.

mod common;

use snee::io::read::read_image;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

const SNEE: &str = env!("CARGO_BIN_EXE_snee");
const SCENE: &str = "scenes/cornell_box.xml";
const FILM: [&str; 4] = ["-D", "width=32", "-D", "height=24"];
const SPP: &str = "512";
/// Float rounding of sums of positive samples grouped differently (see tests/distributed.rs).
const REL_TOL: f32 = 1e-5;

fn folder(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("snee-checkpoint-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn render_args<'a>(out: &'a str, seed: &'a str) -> Vec<&'a str> {
    let mut a = vec!["render", SCENE, "-o", out, "--spp", SPP, "--seed", seed, "--moment", "-q"];
    a.extend(FILM);
    a
}

fn run(args: &[&str]) -> std::process::Output {
    Command::new(SNEE).args(args).current_dir(env!("CARGO_MANIFEST_DIR")).output().unwrap()
}

#[test]
fn sigkill_after_first_checkpoint_then_resume_gives_the_uninterrupted_image() {
    let dir = folder("kill");
    let full = dir.join("full.exr");
    let out = run(&render_args(full.to_str().unwrap(), "3"));
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));

    let part = dir.join("part.exr");
    let mut args = render_args(part.to_str().unwrap(), "3");
    args.extend(["--checkpoint", "0"]);
    let mut child =
        Command::new(SNEE).args(&args).current_dir(env!("CARGO_MANIFEST_DIR")).stderr(Stdio::null()).spawn().unwrap();
    let t0 = Instant::now();
    while !part.exists() {
        assert!(t0.elapsed() < Duration::from_secs(60), "no checkpoint written within 60 s");
        assert!(child.try_wait().unwrap().is_none(), "render ended before its first checkpoint was seen");
        std::thread::sleep(Duration::from_millis(2));
    }
    child.kill().unwrap(); // SIGKILL
    child.wait().unwrap();
    let checkpoint = snee::merge::Part::read(&part).unwrap();
    let (s, e) = checkpoint.meta.range;
    eprintln!("killed after the checkpoint of samples {s}..{e} of {SPP}");
    assert_eq!(s, 0);
    assert!(e > 0 && e < SPP.parse().unwrap(), "checkpoint holds samples {s}..{e}");
    assert!(checkpoint.meta.moment && checkpoint.meta.seed == 3);

    // Resuming with another seed is refused, naming the seed.
    let mut wrong = render_args(part.to_str().unwrap(), "4");
    wrong.extend(["--resume", part.to_str().unwrap()]);
    let o = run(&wrong);
    assert!(!o.status.success() && String::from_utf8_lossy(&o.stderr).contains("seed"));

    let mut resume = render_args(part.to_str().unwrap(), "3");
    resume.extend(["--resume", part.to_str().unwrap()]);
    let o = run(&resume);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let resumed = snee::merge::Part::read(&part).unwrap();
    assert_eq!(resumed.meta.range, (0, SPP.parse().unwrap()));
    let (a, b) = (read_image(&full, false).unwrap(), read_image(&part, false).unwrap());
    let d = common::max_rel_diff(&a, &b, &[]);
    eprintln!("resumed vs uninterrupted: max relative difference {d:e}");
    assert!(d <= REL_TOL, "max relative difference {d:e}");
    let _ = std::fs::remove_dir_all(&dir);
}

/// Renders killed at many moments, including while writing, never leave a truncated output: the
/// file is always the previous complete image or the new complete one.
#[test]
fn killed_renders_never_leave_a_truncated_output() {
    let dir = folder("atomic");
    let out = dir.join("img.exr");
    let mut args = vec!["render", SCENE, "-o", out.to_str().unwrap(), "--spp", "1", "-q"];
    args.extend(["-D", "width=512", "-D", "height=512", "--seed", "1"]);
    let t0 = Instant::now();
    assert!(run(&args).status.success());
    let lifetime = t0.elapsed();
    let previous = std::fs::read(&out).unwrap();
    let mut replaced = 0;
    for k in 1..=12u32 {
        let seed = (k + 1).to_string();
        let mut a = args.clone();
        *a.last_mut().unwrap() = &seed;
        let mut child = Command::new(SNEE).args(&a).current_dir(env!("CARGO_MANIFEST_DIR")).spawn().unwrap();
        // From half a run to 1.6 runs: some kills land before, some while, some after writing.
        std::thread::sleep(lifetime.mul_f64(0.4 + k as f64 / 10.0));
        let _ = child.kill();
        child.wait().unwrap();
        let now = std::fs::read(&out).unwrap();
        if now != previous {
            replaced += 1;
        }
        let img = read_image(&out, false).unwrap_or_else(|e| panic!("after kill {k}: {e}"));
        assert_eq!((img.width, img.height), (512, 512));
    }
    eprintln!("12 killed renders: {replaced} had replaced the output, all outputs complete");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn output_extension_decides_the_format() {
    let dir = folder("ext");
    let png = dir.join("x.png");
    let mut args = vec!["render", SCENE, "-o", png.to_str().unwrap(), "--spp", "2"];
    args.extend(FILM);
    let o = run(&args);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(String::from_utf8_lossy(&o.stderr).contains("PNG"));
    let bytes = std::fs::read(&png).unwrap();
    assert!(bytes.starts_with(b"\x89PNG\r\n\x1a\n"), "not a PNG");
    assert_eq!(read_image(&png, false).unwrap().width, 32);
    for bad in ["x.jpg", "x"] {
        let p = dir.join(bad);
        let mut args = vec!["render", SCENE, "-o", p.to_str().unwrap(), "--spp", "2"];
        args.extend(FILM);
        let o = run(&args);
        assert!(!o.status.success() && String::from_utf8_lossy(&o.stderr).contains("-o"));
        assert!(!Path::new(&p).exists());
    }
    let mut args = vec!["render", SCENE, "-o", png.to_str().unwrap(), "--spp", "2", "--moment"];
    args.extend(FILM);
    assert!(!run(&args).status.success());
    let _ = std::fs::remove_dir_all(&dir);
}

/// `--resume` continues any prefix of the samples to render — here a `--sample-range 3..9` part
/// continued to `3..21` — and equals the direct render of `3..21`; a part that is not a prefix
/// (`5..9`) is refused.
#[test]
fn resume_continues_a_prefix_of_a_sample_range() {
    let dir = folder("range");
    let path = |n: &str| dir.join(n).to_str().unwrap().to_string();
    let (prefix, resumed, direct) = (path("prefix.exr"), path("resumed.exr"), path("direct.exr"));
    let base = |out: &str| {
        let mut a: Vec<String> =
            ["render", SCENE, "-o", out, "--spp", "21", "--seed", "5", "--moment", "-q"].map(String::from).to_vec();
        a.extend(FILM.map(String::from));
        a
    };
    let go = |mut a: Vec<String>, extra: &[&str]| {
        a.extend(extra.iter().map(|s| s.to_string()));
        let refs: Vec<&str> = a.iter().map(|s| s.as_str()).collect();
        run(&refs)
    };
    assert!(go(base(&prefix), &["--sample-range", "3..9"]).status.success());
    let o = go(base(&resumed), &["--sample-range", "3..21", "--resume", &prefix]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(go(base(&direct), &["--sample-range", "3..21"]).status.success());
    let part = snee::merge::Part::read(Path::new(&resumed)).unwrap();
    assert_eq!(part.meta.range, (3, 21));
    let d = common::max_rel_diff(
        &read_image(Path::new(&direct), false).unwrap(),
        &read_image(Path::new(&resumed), false).unwrap(),
        &[],
    );
    eprintln!("range resumed vs direct: max relative difference {d:e}");
    assert!(d <= REL_TOL, "max relative difference {d:e}");
    let o = go(base(&resumed), &["--sample-range", "5..21", "--resume", &prefix]);
    assert!(!o.status.success() && String::from_utf8_lossy(&o.stderr).contains("3..9"));
    let _ = std::fs::remove_dir_all(&dir);
}
