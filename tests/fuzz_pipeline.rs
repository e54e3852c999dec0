//! Hostile input through the whole pipeline: scene folders (XML plus PLY, OBJ and `.serialized`
//! meshes, PNG and EXR textures and an EXR environment map) are mutated and run through parse →
//! build → a few samples of render, and the EXR reader behind `snee compare`. Every case must end
//! in an `Err` carrying a position (`file:line:col`, or the file for mesh and image data) or in a
//! finite image; never a panic, an abort or a hang (each case runs on its own thread with a time
//! limit).
//!
//! Mutations (shrunk by proptest when a case fails): bit flips, byte writes, insertions,
//! deletions, truncation, duplicated ranges, and replacement of the token under a position with
//! one of a list of hostile values (`nan`, `-1`, `1e38`, `65536`), plugin and tag names, and file
//! names, so that mutated XML stays close enough to valid to reach scene building and rendering.
//!
//! A failing case is saved as a folder under `target/fuzz-failures/`; copy it into
//! `tests/data/fuzz_regressions/` where `fuzz_regressions_stay_fixed` replays it on every run.
//!
//! `SNEE_FUZZ_CASES` sets the number of cases (default 400, about 10 s); a long run:
//! `SNEE_FUZZ_CASES=1000000 nice -n 19 cargo test --release --test fuzz_pipeline -- --nocapture`.

use proptest::prelude::*;
use proptest::sample::Index;
use proptest::test_runner::{Config, TestCaseError, TestRunner};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::{mpsc, Arc};
use std::time::{Duration, Instant};

/// A case (parse, build, render) taking longer than this is a hang.
const CASE_LIMIT: Duration = Duration::from_secs(60);
/// The render of a case is cancelled after this long (it keeps the samples done).
const RENDER_BUDGET: Duration = Duration::from_millis(300);

fn cases() -> u32 {
    std::env::var("SNEE_FUZZ_CASES").ok().and_then(|s| s.parse().ok()).unwrap_or(400)
}

fn data(p: &str) -> Vec<u8> {
    std::fs::read(Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data").join(p)).unwrap()
}

/// The files of a scene folder, by name.
const FILES: [&str; 7] = ["scene.xml", "mesh.ply", "mesh.obj", "mesh.serialized", "tex.png", "tex.exr", "env.exr"];

/// Valid base scenes, together covering every integrator, shape, BSDF, medium, texture and
/// emitter plugin, with tiny films so that a case renders in milliseconds.
const BASES: [&str; 3] = [
    r#"<scene version="3.0.0">
    <default name="spp" value="2"/>
    <integrator type="volpath_snee"><integer name="max_depth" value="8"/><float name="snee_rate" value="0.5"/></integrator>
    <sensor type="perspective">
        <float name="fov" value="40"/>
        <transform name="to_world"><lookat origin="0, 0.5, 4" target="0, 0, 0" up="0, 1, 0"/></transform>
        <film type="hdrfilm"><integer name="width" value="8"/><integer name="height" value="6"/><rfilter type="gaussian"/></film>
        <sampler type="independent"><integer name="sample_count" value="$spp"/></sampler>
    </sensor>
    <shape type="ply">
        <string name="filename" value="mesh.ply"/>
        <bsdf type="dielectric"><string name="int_ior" value="bk7"/></bsdf>
        <medium type="homogeneous" name="interior">
            <rgb name="albedo" value="0.9, 0.8, 0.7"/><float name="sigma_t" value="2"/>
            <phase type="hg"><float name="g" value="0.5"/></phase>
        </medium>
    </shape>
    <shape type="obj">
        <string name="filename" value="mesh.obj"/>
        <transform name="to_world"><translate x="1.5"/><rotate y="1" angle="30"/></transform>
        <bsdf type="roughdielectric"><float name="alpha" value="0.1"/><string name="distribution" value="beckmann"/></bsdf>
    </shape>
    <shape type="serialized">
        <string name="filename" value="mesh.serialized"/><integer name="shape_index" value="1"/>
        <transform name="to_world"><translate x="-1.5"/></transform>
        <bsdf type="diffuse"><texture type="bitmap" name="reflectance"><string name="filename" value="tex.png"/></texture></bsdf>
    </shape>
    <emitter type="envmap"><string name="filename" value="env.exr"/><float name="scale" value="0.5"/></emitter>
    <emitter type="directional"><vector name="direction" value="0, -1, -1"/><rgb name="irradiance" value="2"/></emitter>
</scene>
"#,
    r#"<scene version="3.0.0">
    <integrator type="path"><integer name="max_depth" value="6"/><integer name="rr_depth" value="2"/></integrator>
    <sensor type="perspective">
        <float name="fov" value="50"/>
        <transform name="to_world"><lookat origin="0, 1, 5" target="0, 0, 0" up="0, 1, 0"/></transform>
        <film type="hdrfilm"><integer name="width" value="7"/><integer name="height" value="5"/>
            <string name="pixel_format" value="rgba"/><boolean name="sample_border" value="true"/><rfilter type="tent"/></film>
        <sampler type="stratified"><integer name="sample_count" value="2"/></sampler>
    </sensor>
    <bsdf type="twosided" id="checker">
        <bsdf type="diffuse"><texture type="checkerboard" name="reflectance">
            <rgb name="color0" value="0.2"/><rgb name="color1" value="0.8"/></texture></bsdf>
    </bsdf>
    <shape type="rectangle"><transform name="to_world"><scale value="3"/><rotate x="1" angle="-90"/></transform><ref id="checker"/></shape>
    <shape type="cube"><transform name="to_world"><scale value="0.5"/></transform>
        <bsdf type="diffuse"><texture type="bitmap" name="reflectance"><string name="filename" value="tex.exr"/>
            <string name="wrap_mode" value="mirror"/><string name="filter_type" value="nearest"/></texture></bsdf></shape>
    <shape type="sphere"><point name="center" x="1" y="1" z="0"/><float name="radius" value="0.3"/>
        <emitter type="area"><rgb name="radiance" value="5"/></emitter></shape>
    <shape type="disk"><transform name="to_world"><translate y="2"/></transform><boolean name="flip_normals" value="true"/>
        <emitter type="area"><rgb name="radiance" value="1, 2, 3"/></emitter></shape>
    <emitter type="point"><point name="position" x="0" y="3" z="1"/><rgb name="intensity" value="10"/></emitter>
    <emitter type="spot"><transform name="to_world"><lookat origin="2, 2, 2" target="0, 0, 0"/></transform>
        <float name="cutoff_angle" value="30"/><float name="beam_width" value="20"/><rgb name="intensity" value="20"/></emitter>
    <emitter type="constant"><rgb name="radiance" value="0.1"/></emitter>
</scene>
"#,
    r#"<scene version="3.0.0">
    <integrator type="moment"><integrator type="volpathmis"><integer name="max_depth" value="10"/></integrator></integrator>
    <medium type="homogeneous" id="haze"><float name="sigma_t" value="0.3"/><float name="albedo" value="0.9"/></medium>
    <sensor type="perspective">
        <float name="fov" value="45"/>
        <transform name="to_world"><lookat origin="0, 0, 3" target="0, 0, 0" up="0, 1, 0"/></transform>
        <ref name="medium" id="haze"/>
        <film type="hdrfilm"><integer name="width" value="6"/><integer name="height" value="6"/>
            <integer name="crop_offset_x" value="1"/><integer name="crop_width" value="4"/><rfilter type="box"/></film>
        <sampler type="multijitter"><integer name="sample_count" value="2"/></sampler>
    </sensor>
    <shape type="sphere"><float name="radius" value="10"/><bsdf type="null"/><ref name="interior" id="haze"/></shape>
    <shape type="ply"><string name="filename" value="mesh.ply"/><boolean name="face_normals" value="true"/>
        <bsdf type="thindielectric"/><ref name="exterior" id="haze"/>
        <medium type="homogeneous" name="interior"><rgb name="sigma_t" value="0.3, 0.6, 0.9"/><float name="scale" value="3"/><float name="albedo" value="0.5"/></medium></shape>
    <shape type="rectangle"><transform name="to_world"><translate z="-1"/></transform><ref name="exterior" id="haze"/>
        <emitter type="area"><rgb name="radiance" value="3"/></emitter></shape>
    <shape type="sphere"><point name="center" x="0" y="-1" z="0"/><float name="radius" value="0.2"/><ref name="exterior" id="haze"/>
        <bsdf type="diffuse"/></shape>
    <emitter type="envmap"><string name="filename" value="env.exr"/></emitter>
</scene>
"#,
];

/// Tokens swapped in at a position: hostile numbers, names of tags, plugins, parameters and
/// files, and PLY/OBJ keywords.
const TOKENS: &[&str] = &[
    "0",
    "-1",
    "1",
    "2",
    "-0",
    "0.5",
    "1e38",
    "-1e38",
    "1e-45",
    "nan",
    "inf",
    "-inf",
    "65536",
    "65535",
    "16777217",
    "4294967295",
    "4294967296",
    "9223372036854775807",
    "18446744073709551616",
    "3.4e39",
    "$spp",
    "$x",
    "",
    " ",
    ",",
    "scene",
    "shape",
    "bsdf",
    "medium",
    "emitter",
    "texture",
    "sensor",
    "film",
    "sampler",
    "integrator",
    "phase",
    "rfilter",
    "ref",
    "include",
    "path",
    "default",
    "alias",
    "float",
    "integer",
    "string",
    "boolean",
    "rgb",
    "spectrum",
    "point",
    "vector",
    "transform",
    "lookat",
    "matrix",
    "scale",
    "rotate",
    "translate",
    "ply",
    "obj",
    "serialized",
    "sphere",
    "cube",
    "rectangle",
    "disk",
    "dielectric",
    "roughdielectric",
    "thindielectric",
    "null",
    "twosided",
    "diffuse",
    "homogeneous",
    "hg",
    "isotropic",
    "area",
    "envmap",
    "spot",
    "constant",
    "directional",
    "checkerboard",
    "bitmap",
    "path",
    "volpath",
    "volpathmis",
    "volpath_snee",
    "moment",
    "perspective",
    "irradiancemeter",
    "hdrfilm",
    "independent",
    "gaussian",
    "box",
    "tent",
    "interior",
    "exterior",
    "true",
    "false",
    "id",
    "name",
    "value",
    "type",
    "filename",
    "width",
    "height",
    "radius",
    "sigma_t",
    "albedo",
    "alpha",
    "max_depth",
    "sample_count",
    "to_world",
    "mesh.ply",
    "mesh.obj",
    "mesh.serialized",
    "tex.png",
    "tex.exr",
    "env.exr",
    "scene.xml",
    "/",
    "..",
    "ascii",
    "binary_little_endian",
    "binary_big_endian",
    "uchar",
    "int",
    "uint",
    "double",
    "list",
    "vertex",
    "face",
    "element",
    "property",
    "vertex_indices",
    "end_header",
    "v",
    "vt",
    "vn",
    "f",
    "//",
    "1/1/1",
    "-7",
];

#[derive(Clone, Debug)]
enum Mutation {
    Flip { at: Index, bit: u8 },
    Set { at: Index, byte: u8 },
    Insert { at: Index, bytes: Vec<u8> },
    Delete { at: Index, len: usize },
    Truncate { at: Index },
    Duplicate { from: Index, len: usize, to: Index },
    Token { at: Index, token: usize },
}

fn mutation() -> impl Strategy<Value = Mutation> {
    prop_oneof![
        2 => (any::<Index>(), 0u8..8).prop_map(|(at, bit)| Mutation::Flip { at, bit }),
        1 => (any::<Index>(), prop_oneof![Just(0u8), Just(0xff), Just(b'<'), Just(b'"'), Just(b'-'), Just(b'9'), any::<u8>()])
            .prop_map(|(at, byte)| Mutation::Set { at, byte }),
        1 => (any::<Index>(), prop::collection::vec(any::<u8>(), 1..8)).prop_map(|(at, bytes)| Mutation::Insert { at, bytes }),
        1 => (any::<Index>(), 1usize..64).prop_map(|(at, len)| Mutation::Delete { at, len }),
        1 => any::<Index>().prop_map(|at| Mutation::Truncate { at }),
        1 => (any::<Index>(), 1usize..200, any::<Index>()).prop_map(|(from, len, to)| Mutation::Duplicate { from, len, to }),
        5 => (any::<Index>(), 0..TOKENS.len()).prop_map(|(at, token)| Mutation::Token { at, token }),
    ]
}

fn is_token_byte(b: u8) -> bool {
    b.is_ascii_alphanumeric() || b"._-+$".contains(&b)
}

fn apply(m: &Mutation, f: &mut Vec<u8>) {
    let n = f.len();
    let pos = |i: &Index| if n == 0 { 0 } else { i.index(n) };
    match m {
        Mutation::Flip { at, bit } if n > 0 => f[pos(at)] ^= 1 << bit,
        Mutation::Set { at, byte } if n > 0 => f[pos(at)] = *byte,
        Mutation::Insert { at, bytes } => {
            let p = pos(at);
            f.splice(p..p, bytes.iter().copied());
        }
        Mutation::Delete { at, len } => {
            let p = pos(at);
            f.drain(p..(p + len).min(n));
        }
        Mutation::Truncate { at } => f.truncate(pos(at)),
        Mutation::Duplicate { from, len, to } if n > 0 => {
            let a = pos(from);
            let chunk = f[a..(a + len).min(n)].to_vec();
            let b = pos(to);
            f.splice(b..b, chunk);
        }
        Mutation::Token { at, token } if n > 0 => {
            let p = pos(at);
            let (mut a, mut b) = (p, p);
            while a > 0 && is_token_byte(f[a - 1]) {
                a -= 1;
            }
            while b < n && is_token_byte(f[b]) {
                b += 1;
            }
            f.splice(a..b, TOKENS[*token].bytes());
        }
        _ => {}
    }
}

/// One fuzz case: a base scene, the variant of each asset, and mutations of chosen files.
#[derive(Clone, Debug)]
struct Case {
    base: usize,
    ply: usize,
    serialized: usize,
    tex: usize,
    mutations: Vec<(usize, Mutation)>,
}

fn case() -> impl Strategy<Value = Case> {
    // The XML gets about half of the mutations; each other file the rest.
    let file = prop_oneof![6 => Just(0usize), 6 => 1usize..FILES.len()];
    (0..BASES.len(), 0usize..3, 0usize..2, 0usize..2, prop::collection::vec((file, mutation()), 0..6))
        .prop_map(|(base, ply, serialized, tex, mutations)| Case { base, ply, serialized, tex, mutations })
}

/// The files of a case, in the order of [`FILES`].
fn files(c: &Case) -> Vec<Vec<u8>> {
    let mut out = vec![
        BASES[c.base].as_bytes().to_vec(),
        data(["meshes/mitsuba_le.ply", "meshes/mitsuba_be.ply", "meshes/mitsuba_ascii.ply"][c.ply]),
        data("meshes/mitsuba_dedup.obj"),
        data(["meshes/two_meshes_v4.serialized", "meshes/two_meshes_v3.serialized"][c.serialized]),
        data("tex_rgb8.png"),
        data(["tex_rgba_float.exr", "tex_y_float.exr"][c.tex]),
        data("envmap_half_piz.exr"),
    ];
    for (k, m) in &c.mutations {
        apply(m, &mut out[*k]);
    }
    out
}

static NEXT_DIR: AtomicU64 = AtomicU64::new(0);
/// Cases whose scene built and rendered (the others stopped at an error).
static RENDERED: AtomicU64 = AtomicU64::new(0);

fn write_folder(dir: &Path, files: &[Vec<u8>]) {
    std::fs::create_dir_all(dir).unwrap();
    for (name, bytes) in FILES.iter().zip(files) {
        std::fs::write(dir.join(name), bytes).unwrap();
    }
}

/// Parse, build and render the scene folder `dir` (and read its EXR files as `compare` does).
/// `Err` describes a violation: an error without a position, or a non-finite pixel.
fn run_folder(dir: &Path) -> Result<(), String> {
    let xml = dir.join("scene.xml");
    for exr in ["tex.exr", "env.exr"] {
        let p = dir.join(exr);
        match snee::io::read::read_image(&p, false) {
            Ok(img) => {
                let _ = snee::compare::compare(&img, &img);
                let _ = snee::compare::rgb_of(&img);
            }
            Err(e) if e.pos.is_none() => return Err(format!("image error without a file: {e}")),
            Err(_) => {}
        }
    }
    let parsed = match snee::scene::xml::parse_file(&xml, &[]) {
        Ok(p) => p,
        Err(e) if e.pos.is_some() => return Ok(()),
        Err(e) => return Err(format!("parse error without a position: {e}")),
    };
    let scene = match snee::scene::build::build_scene(&parsed) {
        Ok(s) => s,
        Err(e) if e.pos.is_some() => return Ok(()),
        Err(e) => return Err(format!("build error without a position: {e}")),
    };
    let _ = snee::info::summary(&parsed, &scene);
    RENDERED.fetch_add(1, Ordering::Relaxed);
    let cancel = Arc::new(AtomicBool::new(false));
    let c = cancel.clone();
    let done = Arc::new(AtomicBool::new(false));
    let d = done.clone();
    std::thread::spawn(move || {
        let start = Instant::now();
        while !d.load(Ordering::Relaxed) && start.elapsed() < RENDER_BUDGET {
            std::thread::sleep(Duration::from_millis(5));
        }
        c.store(true, Ordering::Relaxed);
    });
    let opts = snee::render::RenderOptions {
        spp: Some(scene.sampler.sample_count.min(4)),
        seed: 1,
        time_budget: Some(RENDER_BUDGET.as_secs_f64()),
        progress: false,
    };
    let out = snee::render::render(&scene, &opts, &cancel);
    done.store(true, Ordering::Relaxed);
    let nch = out.channels.len().max(1);
    if let Some(i) = out.data.iter().position(|v| !v.is_finite()) {
        let channel = &out.channels[i % nch];
        return Err(format!("non-finite value {} in channel {channel} of pixel {}", out.data[i], i / nch));
    }
    Ok(())
}

/// Run a case folder on its own thread: a panic or a case over [`CASE_LIMIT`] is a violation.
fn run_guarded(dir: &Path) -> Result<(), String> {
    let (tx, rx) = mpsc::channel();
    let d = dir.to_path_buf();
    std::thread::spawn(move || {
        let r = std::panic::catch_unwind(|| run_folder(&d));
        let _ = tx.send(r);
    });
    match rx.recv_timeout(CASE_LIMIT) {
        Ok(Ok(r)) => r,
        Ok(Err(p)) => Err(format!(
            "panic: {}",
            p.downcast_ref::<String>()
                .cloned()
                .or_else(|| p.downcast_ref::<&str>().map(|s| s.to_string()))
                .unwrap_or_default()
        )),
        Err(_) => Err(format!("hang: no result after {} s", CASE_LIMIT.as_secs())),
    }
}

/// Where case folders are written: `SNEE_FUZZ_DIR` (a RAM disk such as `/dev/shm/...` for long
/// runs), else `target/fuzz-pipeline`.
fn scratch(name: &str) -> PathBuf {
    match std::env::var_os("SNEE_FUZZ_DIR") {
        Some(d) => PathBuf::from(d).join(name),
        None => Path::new(env!("CARGO_MANIFEST_DIR")).join("target/fuzz-pipeline").join(name),
    }
}

#[test]
fn base_scenes_render_finite_images() {
    limit_memory();
    for base in 0..BASES.len() {
        let c = Case { base, ply: base % 3, serialized: 0, tex: 0, mutations: Vec::new() };
        let dir = scratch(&format!("base{base}"));
        write_folder(&dir, &files(&c));
        // Unmutated, each base must build (else the fuzzing would stop at the first error).
        let parsed = snee::scene::xml::parse_file(&dir.join("scene.xml"), &[]).unwrap();
        if let Err(e) = snee::scene::build::build_scene(&parsed) {
            panic!("base {base}: {e}");
        }
        run_guarded(&dir).unwrap();
    }
}

/// Resource checks refuse what needs more than this, so that a case cannot take the machine's
/// memory (a mutated header declaring 10^9 pixels is refused, not allocated).
fn limit_memory() {
    if std::env::var_os(snee::scene::limits::MEMORY_ENV).is_none() {
        std::env::set_var(snee::scene::limits::MEMORY_ENV, "512M");
    }
}

#[test]
fn mutated_scene_folders_fail_cleanly_or_render_finite() {
    limit_memory();
    let n = cases();
    let tried = AtomicU64::new(0);
    let mut runner =
        TestRunner::new(Config { cases: n, failure_persistence: None, max_shrink_iters: 2000, ..Config::default() });
    let result = runner.run(&case(), |c| {
        tried.fetch_add(1, Ordering::Relaxed);
        let dir = scratch(&format!("case{}", NEXT_DIR.fetch_add(1, Ordering::Relaxed) % 4));
        let f = files(&c);
        write_folder(&dir, &f);
        // The folder being run, for a post-mortem when the process dies.
        let _ = std::fs::write(scratch("current"), dir.to_string_lossy().as_bytes());
        run_guarded(&dir).map_err(|msg| {
            let keep = Path::new(env!("CARGO_MANIFEST_DIR"))
                .join("target/fuzz-failures")
                .join(format!("case{}", NEXT_DIR.fetch_add(1, Ordering::Relaxed)));
            write_folder(&keep, &f);
            TestCaseError::fail(format!("{msg}\n  input saved in {}", keep.display()))
        })
    });
    eprintln!(
        "fuzz_pipeline: {} cases run ({} built and rendered)",
        tried.load(Ordering::Relaxed),
        RENDERED.load(Ordering::Relaxed)
    );
    if let Err(e) = result {
        panic!("{e}");
    }
}

/// Every scene folder under `tests/data/fuzz_regressions/` once failed; each must now fail
/// cleanly or render a finite image.
#[test]
fn fuzz_regressions_stay_fixed() {
    limit_memory();
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/fuzz_regressions");
    let Ok(entries) = std::fs::read_dir(&root) else { return };
    let mut dirs: Vec<PathBuf> = entries.flatten().map(|e| e.path()).filter(|p| p.join("scene.xml").exists()).collect();
    dirs.sort();
    for dir in dirs {
        if let Err(msg) = run_guarded(&dir) {
            panic!("{}: {msg}", dir.display());
        }
    }
}
