//! `snee` command line: `info`, `render`, `compare`, `merge`. All work happens in the library; this file
//! parses arguments, calls it, and prints errors as `file:line:col: message`.

use anyhow::{anyhow, Context};
use clap::{Parser, Subcommand};
use snee::scene::build::load_scene;
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;

/// The scene rendered when `render` is given no scene file.
const DEFAULT_SCENE: &str = "scenes/default.xml";

#[derive(Parser)]
#[command(
    name = "snee",
    version,
    about = "Renders Mitsuba 3 scenes: translucent objects with Subdivision Next-Event Estimation"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Print a summary of a scene: plugins, triangles, bounds, media, emitters, film and samples.
    Info {
        scene: PathBuf,
        /// Override a <default> parameter (like Mitsuba's -D name=value).
        #[arg(short = 'D', value_name = "NAME=VALUE")]
        define: Vec<String>,
        /// Print JSON instead of text.
        #[arg(long)]
        json: bool,
    },
    /// Render a scene to an EXR file.
    Render {
        /// Scene file (default: scenes/default.xml).
        scene: Option<PathBuf>,
        /// Output EXR (default: the scene name with .exr in the working directory).
        #[arg(short, long)]
        output: Option<PathBuf>,
        #[arg(short = 'D', value_name = "NAME=VALUE")]
        define: Vec<String>,
        /// Samples per pixel (default: the scene's sampler sample_count).
        #[arg(long, allow_negative_numbers = true, value_parser = positive_spp)]
        spp: Option<u32>,
        #[arg(long, default_value_t = 0)]
        seed: u64,
        /// Worker threads (default: all cores).
        #[arg(long)]
        threads: Option<usize>,
        /// Time budget in seconds: stop then and write the samples done.
        #[arg(long, value_name = "SECONDS")]
        time: Option<f64>,
        /// Write render statistics as JSON.
        #[arg(long, value_name = "FILE.json")]
        stats: Option<PathBuf>,
        /// Also write an sRGB PNG preview beside the EXR.
        #[arg(long)]
        png: bool,
        /// No progress bar.
        #[arg(long, short)]
        quiet: bool,
        /// Also write the per-pixel second moment (channels m2.R, m2.G, m2.B), as Mitsuba's `moment`.
        #[arg(long)]
        moment: bool,
        /// Also write the image split by transport class (channels `<class>.R/G/B`, with --moment
        /// also `<class>.m2.R/G/B`; classes in docs/classes.md).
        #[arg(long)]
        classes: bool,
        /// Reference image for --convergence.
        #[arg(long, value_name = "REF.exr", requires = "convergence")]
        reference: Option<PathBuf>,
        /// Write (seconds, spp, relMSE against --reference) at doubling sample counts as CSV.
        #[arg(long, value_name = "FILE.csv", requires = "reference")]
        convergence: Option<PathBuf>,
        /// Render only samples START..END-1 of every pixel (of the spp the scene or --spp sets, same
        /// seed): a part of the full run, with weights and metadata, for `snee merge`.
        #[arg(long, value_name = "START..END")]
        sample_range: Option<String>,
        /// Every SECONDS (at the end of a pass), write the image so far to the output, with its
        /// sample range and weights, so that `--resume` can continue it after a crash.
        #[arg(long, value_name = "SECONDS")]
        checkpoint: Option<f64>,
        /// Continue a checkpoint or partial render of the same scene, seed and spp (output
        /// default: the same file); the result equals an uninterrupted run.
        #[arg(long, value_name = "PARTIAL.exr")]
        resume: Option<PathBuf>,
    },
    /// Merge partial renders of one run (--sample-range, --checkpoint) into one image.
    Merge {
        /// Partial EXRs of the same scene, seed and spp, with disjoint sample ranges.
        #[arg(required = true)]
        parts: Vec<PathBuf>,
        /// Output EXR (a part itself: it can be merged again).
        #[arg(short, long)]
        output: PathBuf,
        /// Accept parts covering one contiguous range short of the whole run.
        #[arg(long)]
        partial: bool,
        #[arg(long, short)]
        quiet: bool,
    },
    /// Compare two EXR images: MSE, relMSE, mean ratio, and a per-pixel Z-test when variances are present.
    Compare {
        a: PathBuf,
        b: PathBuf,
        #[arg(long)]
        json: bool,
        /// Samples per pixel of A (default: "spp" from A.json beside A.exr), for the Z-test.
        #[arg(long)]
        spp_a: Option<f64>,
        /// Samples per pixel of B (default: "spp" from B.json beside B.exr).
        #[arg(long)]
        spp_b: Option<f64>,
    },
}

fn parse_defines(defs: &[String]) -> anyhow::Result<Vec<(String, String)>> {
    defs.iter()
        .map(|d| {
            let (k, v) = d.split_once('=').ok_or_else(|| anyhow!("-D expects NAME=VALUE, got \"{}\"", d))?;
            if k.is_empty() {
                return Err(anyhow!("-D expects NAME=VALUE, got \"{}\"", d));
            }
            Ok((k.to_string(), v.to_string()))
        })
        .collect()
}

/// `--spp`: a whole number of samples per pixel, at least 1 (0 would write a black image).
fn positive_spp(s: &str) -> Result<u32, String> {
    match s.trim().parse::<i64>() {
        Ok(n) if (1..=u32::MAX as i64).contains(&n) => Ok(n as u32),
        Ok(n) => Err(format!("--spp must be between 1 and {}, got {n}", u32::MAX)),
        Err(_) => Err(format!("--spp expects a whole number of samples per pixel, got \"{s}\"")),
    }
}

/// Restore the default action of SIGPIPE (end the process quietly), as C programs have it: Rust
/// ignores the signal, so printing into a closed pipe (`snee compare A B | head -1`) would panic.
#[cfg(unix)]
fn default_sigpipe() {
    extern "C" {
        fn signal(signum: i32, handler: usize) -> usize;
    }
    const SIGPIPE: i32 = 13;
    const SIG_DFL: usize = 0;
    // SAFETY: `signal` from the C library with a valid signal number and the default handler.
    unsafe {
        signal(SIGPIPE, SIG_DFL);
    }
}

fn main() -> ExitCode {
    #[cfg(unix)]
    default_sigpipe();
    let cli = Cli::parse();
    match run(cli) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            // Scene errors already read `file:line:col: message`.
            match e.downcast_ref::<snee::scene::Error>() {
                Some(se) if se.pos.is_some() => eprintln!("{}", se),
                _ => eprintln!("error: {:#}", e),
            }
            ExitCode::FAILURE
        }
    }
}

fn run(cli: Cli) -> anyhow::Result<()> {
    match cli.command {
        Command::Info { scene, define, json } => {
            let defines = parse_defines(&define)?;
            let parsed = snee::scene::xml::parse_file(&scene, &defines)?;
            let built = snee::scene::build::build_scene(&parsed)?;
            let summary = snee::info::summary(&parsed, &built);
            if json {
                println!("{}", serde_json::to_string_pretty(&summary.to_json())?);
            } else {
                print!("{}", summary.to_text());
            }
            Ok(())
        }
        Command::Render {
            scene,
            output,
            define,
            spp,
            seed,
            threads,
            time,
            stats,
            png,
            quiet,
            moment,
            classes,
            reference,
            convergence,
            sample_range,
            checkpoint,
            resume,
        } => {
            // Before loading: building the BVH already starts rayon's global pool.
            if let Some(t) = threads {
                rayon::ThreadPoolBuilder::new().num_threads(t.max(1)).build_global().context("setting up threads")?;
            }
            let scene_path = scene.unwrap_or_else(|| PathBuf::from(DEFAULT_SCENE));
            let defines = parse_defines(&define)?;
            // Output format and part options are checked before any work starts.
            let output = output.or_else(|| resume.clone());
            let output_png = match &output {
                Some(o) => output_is_png(o)?,
                None => false,
            };
            let part_mode = sample_range.is_some() || checkpoint.is_some() || resume.is_some();
            if output_png && (part_mode || moment || classes) {
                return Err(anyhow!(
                    "-o {}: --moment, --classes, --sample-range, --checkpoint and --resume need an .exr output (PNG holds 8-bit colour only)",
                    output.as_deref().unwrap_or(Path::new("")).display()
                ));
            }
            let sample_range = sample_range.as_deref().map(parse_sample_range).transpose()?;
            if let Some(c) = checkpoint {
                if !(c >= 0.0 && c.is_finite()) {
                    return Err(anyhow!("--checkpoint expects a number of seconds >= 0, got {c}"));
                }
            }
            let mut loaded = load_scene(&scene_path, &defines)?;
            loaded.integrator.moment |= moment;
            loaded.integrator.classes |= classes;
            if let Some(t) = time {
                if !(t > 0.0 && t.is_finite()) {
                    return Err(anyhow!("--time expects a positive number of seconds"));
                }
            }
            let output = output.unwrap_or_else(|| {
                PathBuf::from(scene_path.file_stem().map(|s| s.to_os_string()).unwrap_or_else(|| "render".into()))
                    .with_extension("exr")
            });
            let cancel = Arc::new(AtomicBool::new(false));
            {
                let c = cancel.clone();
                // A second Ctrl-C while writing is ignored; the first stops the render and writes what is done.
                let _ = ctrlc::set_handler(move || c.store(true, Ordering::Relaxed));
            }
            let opts = snee::render::RenderOptions { spp, seed, time_budget: time, progress: !quiet };
            let part = if part_mode {
                Some(snee::merge::PartRender::new(
                    &scene_path,
                    &defines,
                    &loaded,
                    &opts,
                    sample_range,
                    resume.as_deref(),
                )?)
            } else {
                None
            };
            let reference = match &reference {
                Some(r) => Some(
                    snee::compare::rgb_of(&snee::io::read::read_image(r, false)?)
                        .map_err(|e| anyhow!("{}: {}", r.display(), e))?,
                ),
                None => None,
            };
            let mut rows: Vec<(f64, u32, f64)> = Vec::new();
            let mut record = |t: f64, spp: u32, data: &[f32]| {
                if let Some(r) = &reference {
                    let n = data.len() / r.len().max(1);
                    let img: Vec<[f32; 3]> = data.chunks(n.max(3)).map(|p| [p[0], p[1], p[2]]).collect();
                    if img.len() == r.len() {
                        rows.push((t, spp, snee::compare::rel_mse(&img, r)));
                    }
                }
            };
            let mut last_checkpoint = std::time::Instant::now();
            let mut on_pass = |state: &snee::render::PassState| {
                if reference.is_some() && state.samples.1.is_power_of_two() {
                    record(state.seconds, state.samples.1, &state.develop());
                }
                if let (Some(every), Some(run)) = (checkpoint, &part) {
                    if last_checkpoint.elapsed().as_secs_f64() >= every && state.samples.1 < run.range.1 {
                        if let Err(e) = run.write_checkpoint(&output, state) {
                            eprintln!("warning: checkpoint not written: {e:#}");
                        }
                        last_checkpoint = std::time::Instant::now();
                    }
                }
            };
            let wants_passes = reference.is_some() || checkpoint.is_some();
            let out = snee::render::render_range(
                &loaded,
                &opts,
                part.as_ref().map(|p| (p.next_sample(), p.range.1)),
                &cancel,
                if wants_passes { Some(&mut on_pass as snee::render::ProgressCallback) } else { None },
            );
            if let (Some(r), Some(path)) = (&reference, &convergence) {
                if r.len() != out.width * out.height {
                    return Err(anyhow!("--reference is {} pixels, the render {}x{}", r.len(), out.width, out.height));
                }
                let mut csv = String::from("seconds,spp,rel_mse\n");
                for (t, spp, e) in &rows {
                    csv += &format!("{t:.6},{spp},{e:.6e}\n");
                }
                snee::io::atomic::write_bytes(path, csv.as_bytes())?;
            }
            match &part {
                Some(run) => run.write_final(&output, &out, png)?,
                None if output_png => write_png_output(&output, &out)?,
                None => write_output(&output, &out, png)?,
            }
            let st = out.stats.to_json();
            if let Some(p) = stats {
                snee::io::atomic::write_bytes(&p, serde_json::to_string_pretty(&st)?.as_bytes())?;
            }
            if !quiet {
                if output_png {
                    eprintln!("note: {} is an 8-bit sRGB PNG; name the output .exr for float data", output.display());
                }
                eprintln!(
                    "wrote {} ({}x{}, {} spp, {:.2} s, {:.3} Msamples/s, {} rejected samples)",
                    output.display(),
                    out.width,
                    out.height,
                    out.stats.spp,
                    out.stats.seconds,
                    out.stats.samples as f64 / out.stats.seconds.max(1e-9) / 1e6,
                    out.stats.rejected_samples
                );
            }
            Ok(())
        }
        Command::Merge { parts, output, partial, quiet } => {
            if output_is_png(&output)? {
                return Err(anyhow!("-o {}: merge writes an .exr (a part that can be merged again)", output.display()));
            }
            let parts = parts.iter().map(|p| snee::merge::Part::read(p)).collect::<anyhow::Result<Vec<_>>>()?;
            let merged = snee::merge::merge(&parts, partial)?;
            ensure_parent(&output)?;
            merged.write(&output)?;
            if !quiet {
                eprintln!(
                    "wrote {} ({} parts, samples {}..{} of {} spp)",
                    output.display(),
                    parts.len(),
                    merged.meta.range.0,
                    merged.meta.range.1,
                    merged.meta.spp
                );
            }
            Ok(())
        }
        Command::Compare { a, b, json, spp_a, spp_b } => {
            let ia = snee::io::read::read_image(&a, false)?;
            let ib = snee::io::read::read_image(&b, false)?;
            let r = snee::compare::compare(&ia, &ib).map_err(|e| anyhow!(e))?;
            let spp = |given: Option<f64>, path: &Path| {
                given.or_else(|| {
                    let text = std::fs::read_to_string(path.with_extension("json")).ok()?;
                    serde_json::from_str::<serde_json::Value>(&text).ok()?["spp"].as_f64()
                })
            };
            // Per-pixel Z-test when both images carry a per-sample variance and a sample count.
            let z = match (
                snee::compare::variance_of_mean(&ia, spp(spp_a, &a)),
                snee::compare::variance_of_mean(&ib, spp(spp_b, &b)),
            ) {
                (Some(va), Some(vb)) => {
                    let (ma, mb) = (
                        snee::compare::rgb_of(&ia).map_err(|e| anyhow!(e))?,
                        snee::compare::rgb_of(&ib).map_err(|e| anyhow!(e))?,
                    );
                    Some(snee::compare::z_test(&ma, &va, &mb, &vb, 0.01))
                }
                _ => None,
            };
            if json {
                let mut v = r.to_json();
                if let Some(z) = &z {
                    v["z_test"] = z.to_json();
                }
                println!("{}", serde_json::to_string_pretty(&v)?);
            } else {
                print!("{}", r.to_text());
                match &z {
                    Some(z) => print!("{}", z.to_text()),
                    None => println!("Z-test: skipped (needs var.* or m2.* channels and the spp of both images)"),
                }
            }
            Ok(())
        }
    }
}

fn write_output(path: &Path, out: &snee::render::RenderOutput, png: bool) -> anyhow::Result<()> {
    ensure_parent(path)?;
    let names: Vec<&str> = out.channels.iter().map(|s| s.as_str()).collect();
    snee::io::write::write_exr(path, out.width, out.height, &names, &out.data)?;
    if png {
        let n = out.channels.len();
        let rgb: Vec<f32> = out.data.chunks(n).flat_map(|p| [p[0], p[1], p[2]]).collect();
        let png_path = path.with_extension("png");
        snee::io::write::write_png(&png_path, out.width, out.height, &rgb)?;
    }
    Ok(())
}

fn ensure_parent(path: &Path) -> anyhow::Result<()> {
    if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir).with_context(|| format!("creating the folder {}", dir.display()))?;
    }
    Ok(())
}

/// Whether `-o` names a PNG (`true`) or an EXR (`false`); an error for any other extension.
fn output_is_png(path: &Path) -> anyhow::Result<bool> {
    match path.extension().and_then(|e| e.to_str()).map(|e| e.to_ascii_lowercase()).as_deref() {
        Some("exr") => Ok(false),
        Some("png") => Ok(true),
        other => Err(anyhow!(
            "-o {}: snee writes OpenEXR (.exr) or 8-bit PNG (.png), not {}",
            path.display(),
            other.map(|e| format!("\".{e}\"")).unwrap_or_else(|| "a file without extension".into())
        )),
    }
}

/// `-o NAME.png`: the colour channels as an 8-bit sRGB PNG, nothing else.
fn write_png_output(path: &Path, out: &snee::render::RenderOutput) -> anyhow::Result<()> {
    ensure_parent(path)?;
    let n = out.channels.len();
    let rgb: Vec<f32> = out.data.chunks(n).flat_map(|p| [p[0], p[1], p[2]]).collect();
    snee::io::write::write_png(path, out.width, out.height, &rgb)
}

/// `--sample-range START..END` with START < END.
fn parse_sample_range(text: &str) -> anyhow::Result<(u32, u32)> {
    let bad = || anyhow!("--sample-range expects START..END with integers 0 <= START < END, got \"{text}\"");
    let (a, b) = text.split_once("..").ok_or_else(bad)?;
    let (a, b): (u32, u32) = (a.trim().parse().map_err(|_| bad())?, b.trim().parse().map_err(|_| bad())?);
    if a >= b {
        return Err(bad());
    }
    Ok((a, b))
}
