//! AFL++ target: one input file holds a whole scene folder — `scene.xml`, `mesh.ply`, `mesh.obj`,
//! `mesh.serialized`, `tex.png`, `tex.exr`, `env.exr`, in that order, separated by the line
//! `--snee-file--` — which is written to a scratch folder and run through parse → build → a few
//! samples of render, and the EXR reader of `snee compare` (the checks of
//! `tests/fuzz_pipeline.rs`). A panic, an error without a position or a non-finite colour
//! aborts, which AFL++ records as a crash.
//!
//! Usage: `fuzz/afl.sh` (builds with sanitizer coverage and starts `afl-fuzz`), or by hand:
//! `pipeline INPUT` runs one input; `pipeline --pack FOLDER OUT` packs a scene folder into one input.

use std::path::{Path, PathBuf};
use std::sync::atomic::AtomicBool;

const FILES: [&str; 7] = ["scene.xml", "mesh.ply", "mesh.obj", "mesh.serialized", "tex.png", "tex.exr", "env.exr"];
const SEPARATOR: &[u8] = b"\n--snee-file--\n";

fn split(input: &[u8]) -> Vec<&[u8]> {
    let mut parts = Vec::new();
    let mut rest = input;
    while let Some(i) = rest.windows(SEPARATOR.len()).position(|w| w == SEPARATOR) {
        parts.push(&rest[..i]);
        rest = &rest[i + SEPARATOR.len()..];
    }
    parts.push(rest);
    parts
}

fn fail(msg: String) -> ! {
    eprintln!("{msg}");
    std::process::abort()
}

fn run(dir: &Path) {
    for exr in ["tex.exr", "env.exr"] {
        match snee::io::read::read_image(&dir.join(exr), false) {
            Ok(img) => {
                let _ = snee::compare::compare(&img, &img);
            }
            Err(e) if e.pos.is_none() => fail(format!("image error without a file: {e}")),
            Err(_) => {}
        }
    }
    let parsed = match snee::scene::xml::parse_file(&dir.join("scene.xml"), &[]) {
        Ok(p) => p,
        Err(e) if e.pos.is_some() => return,
        Err(e) => fail(format!("parse error without a position: {e}")),
    };
    let scene = match snee::scene::build::build_scene(&parsed) {
        Ok(s) => s,
        Err(e) if e.pos.is_some() => return,
        Err(e) => fail(format!("build error without a position: {e}")),
    };
    let _ = snee::info::summary(&parsed, &scene);
    let opts = snee::render::RenderOptions {
        spp: Some(scene.sampler.sample_count.min(2)),
        seed: 1,
        time_budget: Some(0.2),
        progress: false,
    };
    let out = snee::render::render(&scene, &opts, &AtomicBool::new(false));
    let nch = out.channels.len().max(1);
    if let Some(i) = out.data.iter().position(|v| !v.is_finite()) {
        fail(format!("non-finite value {} in channel {}", out.data[i], out.channels[i % nch]));
    }
}

fn main() {
    std::panic::set_hook(Box::new(|info| fail(format!("panic: {info}"))));
    // Stay within memory that AFL's limit allows: the resource checks refuse larger inputs.
    if std::env::var_os(snee::scene::limits::MEMORY_ENV).is_none() {
        std::env::set_var(snee::scene::limits::MEMORY_ENV, "512M");
    }
    let args: Vec<String> = std::env::args().collect();
    if args.len() == 4 && args[1] == "--pack" {
        let mut out = Vec::new();
        for (k, name) in FILES.iter().enumerate() {
            if k > 0 {
                out.extend_from_slice(SEPARATOR);
            }
            out.extend(std::fs::read(Path::new(&args[2]).join(name)).unwrap_or_default());
        }
        std::fs::write(&args[3], out).expect("writing the packed input");
        return;
    }
    let input = match args.get(1) {
        Some(p) => std::fs::read(p).expect("reading the input"),
        None => {
            let mut v = Vec::new();
            std::io::Read::read_to_end(&mut std::io::stdin(), &mut v).expect("reading stdin");
            v
        }
    };
    let base = std::env::var_os("SNEE_FUZZ_DIR").map(PathBuf::from).unwrap_or_else(std::env::temp_dir);
    let dir = base.join(format!("snee-afl-{}", std::process::id()));
    let _ = std::fs::create_dir_all(&dir);
    let parts = split(&input);
    for (k, name) in FILES.iter().enumerate() {
        let _ = std::fs::write(dir.join(name), parts.get(k).copied().unwrap_or(&[]));
    }
    run(&dir);
    let _ = std::fs::remove_dir_all(&dir);
}
