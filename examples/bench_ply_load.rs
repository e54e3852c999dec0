//! Benchmark of the PLY loader: writes a binary little-endian PLY grid with about 1M triangles to
//! a temporary file, times `load_ply` (best of 3) and prints the time and the bytes per triangle of
//! the file and of the resulting `MeshData`. With `--compare`, also times ply-rs-bw's generic
//! parser on the same file once (why the loader has its own body decoder). For the xyz file it
//! also times the world-space mesh and the BVH build, with the BVH's bytes per triangle.
//!
//! ```text
//! cargo run --release --example bench_ply_load [-- --triangles 1000000] [--compare]
//! ```

use std::io::BufReader;
use std::path::Path;
use std::time::Instant;

use snee::shape::ply::load_ply;

/// A `columns × rows` grid of quads (2 triangles each) as a binary little-endian PLY.
fn grid_ply(columns: usize, rows: usize, normals_and_uvs: bool) -> Vec<u8> {
    let nv = (columns + 1) * (rows + 1);
    let nf = 2 * columns * rows;
    let extra = if normals_and_uvs {
        "property float nx\nproperty float ny\nproperty float nz\nproperty float u\nproperty float v\n"
    } else {
        ""
    };
    let mut b = format!(
        "ply\nformat binary_little_endian 1.0\nelement vertex {nv}\nproperty float x\nproperty float y\n\
         property float z\n{extra}element face {nf}\nproperty list uchar int vertex_indices\nend_header\n"
    )
    .into_bytes();
    b.reserve(nv * if normals_and_uvs { 32 } else { 12 } + nf * 13);
    for j in 0..=rows {
        for i in 0..=columns {
            let (u, v) = (i as f32 / columns as f32, j as f32 / rows as f32);
            let z = 0.1 * (6.0 * u).sin() * (4.0 * v).cos();
            let mut vals = vec![u, v, z];
            if normals_and_uvs {
                vals.extend([0.0, 0.0, 1.0, u, v]);
            }
            vals.iter().for_each(|x| b.extend(x.to_le_bytes()));
        }
    }
    let id = |i: usize, j: usize| (j * (columns + 1) + i) as i32;
    for j in 0..rows {
        for i in 0..columns {
            for t in [[id(i, j), id(i + 1, j), id(i + 1, j + 1)], [id(i, j), id(i + 1, j + 1), id(i, j + 1)]] {
                b.push(3);
                t.iter().for_each(|x| b.extend(x.to_le_bytes()));
            }
        }
    }
    b
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let triangles: usize = args
        .iter()
        .position(|a| a == "--triangles")
        .and_then(|i| args.get(i + 1))
        .and_then(|s| s.parse().ok())
        .unwrap_or(1_000_000);
    let compare = args.iter().any(|a| a == "--compare");
    let columns = 1000;
    let rows = triangles.div_ceil(2 * columns).max(1);

    for normals_and_uvs in [false, true] {
        let label = if normals_and_uvs { "xyz + normals + uv" } else { "xyz" };
        let bytes = grid_ply(columns, rows, normals_and_uvs);
        let path = std::env::temp_dir().join(format!("snee_bench_{}_{normals_and_uvs}.ply", std::process::id()));
        std::fs::write(&path, &bytes).expect("write the temporary PLY file");

        let mut best = f64::INFINITY;
        let mut mesh = None;
        for _ in 0..3 {
            let t0 = Instant::now();
            let m = load_ply(&path).unwrap_or_else(|e| panic!("{e}"));
            best = best.min(t0.elapsed().as_secs_f64());
            mesh = Some(m);
        }
        let Some(m) = mesh else { return };
        let nt = m.triangle_count() as f64;
        println!(
            "{label:>20}: {} triangles, {} vertices: load_ply best of 3 = {:.1} ms ({:.1} M triangles/s); \
             file {:.1} B/triangle, MeshData {:.1} B/triangle",
            m.triangle_count(),
            m.vertex_count(),
            best * 1e3,
            nt / best / 1e6,
            bytes.len() as f64 / nt,
            m.heap_bytes() as f64 / nt,
        );
        if compare {
            compare_ply_rs(&path);
        }
        if !normals_and_uvs {
            bvh_build(m);
        }
        std::fs::remove_file(&path).ok();
    }
}

/// Time the scene-side work for the mesh: world-space mesh (area table, normals) and the BVH.
fn bvh_build(m: snee::shape::mesh_data::MeshData) {
    use snee::shape::{accel::Accel, Mesh, Shape};
    let t0 = Instant::now();
    let mesh = Mesh::new(m, &snee::math::Mat4::IDENTITY, false, false);
    let t1 = Instant::now();
    let shape = Shape::from_mesh(mesh);
    let shapes = [shape];
    let accel = Accel::build(&shapes);
    let t2 = Instant::now();
    let (nodes, packets, depth) = accel.stats();
    let nt = shapes[0].triangle_count() as f64;
    println!(
        "{:>20}  Mesh::new {:.1} ms, BVH build {:.1} ms ({nodes} nodes, {packets} leaf packets, depth {depth}, \
         {:.1} B/triangle)",
        "",
        (t1 - t0).as_secs_f64() * 1e3,
        (t2 - t1).as_secs_f64() * 1e3,
        accel.memory_bytes() as f64 / nt
    );
}

fn compare_ply_rs(path: &Path) {
    use ply_rs_bw::parser::Parser;
    use ply_rs_bw::ply::DefaultElement;
    let t0 = Instant::now();
    let file = std::fs::File::open(path).expect("open");
    let ply = Parser::<DefaultElement>::new().read_ply(&mut BufReader::new(file)).expect("ply-rs-bw parse");
    let faces = ply.payload.get("face").map_or(0, Vec::len);
    println!(
        "{:>20}  ply-rs-bw generic parser: {:.1} ms ({faces} faces, one run)",
        "",
        t0.elapsed().as_secs_f64() * 1e3
    );
}
