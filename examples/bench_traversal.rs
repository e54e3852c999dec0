//! Traversal benchmark: closest-hit and shadow (any-hit) rays through the scene's acceleration
//! structure, in millions of rays per second on one thread.
//!
//! ```sh
//! cargo run --release --example bench_traversal -- [SCENE.xml]... [--rays N] [--reps N] [--json]
//!     [--save-rays DIR] [--groups]
//! ```
//! Default scenes: `scenes/cornell_box.xml` and the paper statue (`scenes/paper/sphere_smooth_st02.xml`).
//! Rays leave random surface points (cosine-distributed about the normal, half of them turned
//! inward), as in path tracing; shadow rays join two random surface points. The ray set depends
//! only on the scene and the seed, so instruction counts (`valgrind --tool=callgrind`, with a small
//! `--rays`) are comparable between builds. `--save-rays DIR` also writes each scene's rays to
//! `DIR/<scene>.rays` (little-endian `f32`, per ray o, d, tmax; the closest rays, then the shadow
//! rays), so that another renderer can trace the same ones (`scripts/embree_rays.py` times Mitsuba
//! 3's Embree on them).
//!
//! The closest rays are also timed by where they start (`--groups`, and always with `--save-rays`,
//! which then writes `DIR/<scene>.groups`, one byte per closest ray): 0 on a mesh, leaving its
//! surface (about the normal), 1 on a mesh, turned into it, 2 and 3 the same on an analytic shape
//! (a sphere light): on the statue the inward rays cross the object and cost the most.
//!
//! Each rate is the best of `--reps` runs, timed both on the wall clock and, on Linux, by the
//! thread's own CPU time (`CLOCK_THREAD_CPUTIME_ID`), which leaves out the time other
//! processes hold the core: on a shared machine it is the steadier of the two. `SNEE_ISA=avx2`
//! (or `portable`) runs a lower traversal path than the CPU supports (see `shape::accel::Isa`).

use snee::interaction::{offset_origin, spawn_ray_between};
use snee::math::{warp, Frame, Ray};
use snee::sampler::Sampler;
use std::time::Instant;

/// Nanoseconds the calling thread has run on a CPU (`clock_gettime(CLOCK_THREAD_CPUTIME_ID)`, from
/// the C library std links), on Linux.
#[cfg(target_os = "linux")]
fn thread_cpu_ns() -> Option<u64> {
    #[repr(C)]
    struct Timespec {
        sec: i64,
        nsec: i64,
    }
    extern "C" {
        fn clock_gettime(clock: i32, ts: *mut Timespec) -> i32;
    }
    const CLOCK_THREAD_CPUTIME_ID: i32 = 3;
    let mut ts = Timespec { sec: 0, nsec: 0 };
    // SAFETY: `ts` is a valid `struct timespec` (64-bit fields on the 64-bit Linux targets).
    (unsafe { clock_gettime(CLOCK_THREAD_CPUTIME_ID, &mut ts) } == 0)
        .then(|| ts.sec as u64 * 1_000_000_000 + ts.nsec as u64)
}

#[cfg(not(target_os = "linux"))]
fn thread_cpu_ns() -> Option<u64> {
    None
}

fn main() {
    let mut scenes = Vec::new();
    let (mut n, mut reps, mut json, mut groups) = (200_000usize, 5usize, false, false);
    let mut save: Option<std::path::PathBuf> = None;
    let mut args = std::env::args().skip(1);
    while let Some(a) = args.next() {
        match a.as_str() {
            "--rays" => n = args.next().and_then(|s| s.parse().ok()).expect("--rays N"),
            "--reps" => reps = args.next().and_then(|s| s.parse().ok()).expect("--reps N"),
            "--json" => json = true,
            "--groups" => groups = true,
            "--save-rays" => save = Some(args.next().expect("--save-rays DIR").into()),
            _ => scenes.push(a),
        }
    }
    if scenes.is_empty() {
        scenes = vec!["scenes/cornell_box.xml".into(), "scenes/paper/sphere_smooth_st02.xml".into()];
    }
    let mut out = Vec::new();
    for path in &scenes {
        let t0 = Instant::now();
        let scene = match snee::scene::build::load_scene(std::path::Path::new(path), &[]) {
            Ok(s) => s,
            Err(e) => {
                eprintln!("{path}: {e}");
                std::process::exit(1);
            }
        };
        let load = t0.elapsed().as_secs_f64();
        let (nodes, packets, depth) = scene.accel.stats();
        let bytes_per_tri = scene.accel.memory_bytes() as f64 / scene.triangle_count().max(1) as f64;
        let brute = scene.accel.brute_triangles();
        eprintln!(
            "{path}: {nodes} nodes, {packets} leaf packets, depth {depth}, {bytes_per_tri:.1} bytes per triangle, \
             {brute} triangles by brute force"
        );
        let shapes = &scene.shapes;
        let mut s = Sampler::new(3, 0);
        let (mut rays, mut shadow) = (Vec::with_capacity(n), Vec::with_capacity(n));
        // Per closest ray: 0 / 1 from a mesh out of / into it, 2 / 3 the same from an analytic shape.
        let mut group: Vec<u8> = Vec::with_capacity(n);
        let pick = |s: &mut Sampler| &shapes[((s.next_1d() * shapes.len() as f32) as usize).min(shapes.len() - 1)];
        for _ in 0..n {
            let shape = pick(&mut s);
            let ps = shape.sample_position(s.next_2d());
            let mut d = Frame::from_normal(ps.n).to_world(warp::square_to_cosine_hemisphere(s.next_2d()));
            let mut g = if matches!(shape.geometry, snee::shape::Geometry::Mesh(_)) { 0 } else { 2 };
            if s.next_1d() < 0.5 {
                d = -d;
                g += 1;
            }
            group.push(g);
            rays.push(Ray::new(offset_origin(ps.p, ps.n, d), d));
            let q = pick(&mut s).sample_position(s.next_2d()).p;
            shadow.push(spawn_ray_between(offset_origin(ps.p, ps.n, q - ps.p), q));
        }
        if let Some(dir) = &save {
            let name = std::path::Path::new(path).file_stem().map_or("scene".into(), |s| s.to_string_lossy());
            let bytes: Vec<u8> = rays
                .iter()
                .chain(&shadow)
                .flat_map(|r| [r.o.x, r.o.y, r.o.z, r.d.x, r.d.y, r.d.z, r.tmax])
                .flat_map(f32::to_le_bytes)
                .collect();
            let file = dir.join(format!("{name}.rays"));
            let groups_file = dir.join(format!("{name}.groups"));
            if let Err(e) = std::fs::create_dir_all(dir)
                .and_then(|_| std::fs::write(&file, bytes))
                .and_then(|_| std::fs::write(&groups_file, &group))
            {
                eprintln!("{}: {e}", file.display());
                std::process::exit(1);
            }
        }
        // (label, rays, hits, M rays/s) per group.
        let mut by_origin: Vec<(&str, usize, usize, f64)> = Vec::new();
        if groups || save.is_some() {
            const NAMES: [&str; 4] = ["mesh outward", "mesh inward", "analytic outward", "analytic inward"];
            for (g, name) in NAMES.iter().enumerate() {
                let sub: Vec<Ray> =
                    rays.iter().zip(&group).filter(|&(_, &k)| k as usize == g).map(|(r, _)| *r).collect();
                if sub.is_empty() {
                    continue;
                }
                let (mut best, mut hits) = (f64::INFINITY, 0);
                for _ in 0..reps {
                    let t0 = Instant::now();
                    hits = sub.iter().filter(|r| scene.accel.intersect(shapes, r).is_some()).count();
                    best = best.min(t0.elapsed().as_secs_f64());
                }
                by_origin.push((name, sub.len(), hits, sub.len() as f64 / best / 1e6));
            }
        }
        let (mut best_c, mut best_s) = (f64::INFINITY, f64::INFINITY);
        let (mut cpu_c, mut cpu_s) = (f64::INFINITY, f64::INFINITY);
        let (mut hits, mut blocked, mut checksum) = (0usize, 0usize, 0.0f64);
        for _ in 0..reps {
            let c0 = thread_cpu_ns();
            let t0 = Instant::now();
            hits = 0;
            checksum = 0.0;
            for r in &rays {
                if let Some(h) = scene.accel.intersect(shapes, r) {
                    hits += 1;
                    checksum += h.t as f64;
                }
            }
            let t1 = Instant::now();
            let c1 = thread_cpu_ns();
            blocked = shadow.iter().filter(|r| scene.accel.occluded(shapes, r)).count();
            let t2 = Instant::now();
            let c2 = thread_cpu_ns();
            best_c = best_c.min((t1 - t0).as_secs_f64());
            best_s = best_s.min((t2 - t1).as_secs_f64());
            if let (Some(c0), Some(c1), Some(c2)) = (c0, c1, c2) {
                cpu_c = cpu_c.min((c1 - c0) as f64 * 1e-9);
                cpu_s = cpu_s.min((c2 - c1) as f64 * 1e-9);
            }
        }
        let (mc, ms) = (n as f64 / best_c / 1e6, n as f64 / best_s / 1e6);
        // CPU-time rates (wall-clock ones where the kernel gives no thread CPU time).
        let (cc, cs) = if cpu_c.is_finite() { (n as f64 / cpu_c / 1e6, n as f64 / cpu_s / 1e6) } else { (mc, ms) };
        if json {
            let origin: Vec<String> = by_origin
                .iter()
                .map(|(name, n, h, m)| format!("{name:?}: {{\"rays\": {n}, \"hits\": {h}, \"closest_mrays\": {m:.3}}}"))
                .collect();
            out.push(format!(
                "{{\"scene\": {path:?}, \"triangles\": {}, \"bytes_per_triangle\": {bytes_per_tri:.1}, \"load_s\": {load:.4}, \"closest_mrays\": {mc:.3}, \"shadow_mrays\": {ms:.3}, \"closest_mrays_cpu\": {cc:.3}, \"shadow_mrays_cpu\": {cs:.3}, \"hits\": {hits}, \"blocked\": {blocked}, \"closest_by_origin\": {{{}}}}}",
                scene.triangle_count(),
                origin.join(", ")
            ));
        } else {
            for (name, n, h, m) in &by_origin {
                println!("{path}: closest from {name}: {n} rays, {h} hits, {m:.2} Mrays/s");
            }
            println!(
                "{path}: {} triangles, load+build {load:.3} s; closest {mc:.2} Mrays/s ({hits} hits, sum t {checksum:.3}), shadow {ms:.2} Mrays/s ({blocked} blocked); by CPU time closest {cc:.2}, shadow {cs:.2} Mrays/s",
                scene.triangle_count()
            );
        }
    }
    if json {
        println!("[{}]", out.join(", "));
    }
}
