//! Watertightness of the ray/triangle test on a closed, finely tessellated sphere: rays from
//! interior points (including rays aimed exactly at vertices and edges) must all hit the mesh.

use snee::math::{Mat4, Ray, Vec2, Vec3};
use snee::sampler::Sampler;
use snee::shape::accel::Accel;
use snee::shape::mesh_data::MeshData;
use snee::shape::{Mesh, Shape};

/// Icosphere with `level` subdivisions (20·4^level triangles), shared vertices.
fn icosphere(level: u32) -> MeshData {
    let t = (1.0 + 5f32.sqrt()) / 2.0;
    let mut v: Vec<Vec3> = [
        (-1.0, t, 0.0),
        (1.0, t, 0.0),
        (-1.0, -t, 0.0),
        (1.0, -t, 0.0),
        (0.0, -1.0, t),
        (0.0, 1.0, t),
        (0.0, -1.0, -t),
        (0.0, 1.0, -t),
        (t, 0.0, -1.0),
        (t, 0.0, 1.0),
        (-t, 0.0, -1.0),
        (-t, 0.0, 1.0),
    ]
    .iter()
    .map(|&(x, y, z)| Vec3::new(x, y, z).normalize())
    .collect();
    let mut f: Vec<[u32; 3]> = vec![
        [0, 11, 5],
        [0, 5, 1],
        [0, 1, 7],
        [0, 7, 10],
        [0, 10, 11],
        [1, 5, 9],
        [5, 11, 4],
        [11, 10, 2],
        [10, 7, 6],
        [7, 1, 8],
        [3, 9, 4],
        [3, 4, 2],
        [3, 2, 6],
        [3, 6, 8],
        [3, 8, 9],
        [4, 9, 5],
        [2, 4, 11],
        [6, 2, 10],
        [8, 6, 7],
        [9, 8, 1],
    ];
    for _ in 0..level {
        let mut cache = std::collections::HashMap::new();
        let mut mid = |a: u32, b: u32, v: &mut Vec<Vec3>| -> u32 {
            let key = (a.min(b), a.max(b));
            *cache.entry(key).or_insert_with(|| {
                v.push(((v[a as usize] + v[b as usize]) * 0.5).normalize());
                (v.len() - 1) as u32
            })
        };
        let mut nf = Vec::with_capacity(f.len() * 4);
        for [a, b, c] in f {
            let ab = mid(a, b, &mut v);
            let bc = mid(b, c, &mut v);
            let ca = mid(c, a, &mut v);
            nf.extend([[a, ab, ca], [b, bc, ab], [c, ca, bc], [ab, bc, ca]]);
        }
        f = nf;
    }
    MeshData { positions: v, normals: Vec::new(), uvs: Vec::new(), indices: f }
}

fn shape(data: MeshData, to_world: Mat4) -> Shape {
    Shape::from_mesh(Mesh::new(data, &to_world, true, false))
}

#[test]
fn closed_mesh_does_not_leak() {
    // 20·4^7 = 327,680 triangles by default; `SNEE_LEAK_LEVEL=8` gives 1,310,720 (the README's number).
    let level = std::env::var("SNEE_LEAK_LEVEL").ok().and_then(|v| v.parse().ok()).unwrap_or(7);
    let data = icosphere(level);
    let verts = data.positions.clone();
    let to_world = Mat4::from_translation(Vec3::new(0.3, -0.2, 5.0)) * Mat4::from_scale(Vec3::splat(2.0));
    let shapes = vec![shape(data, to_world)];
    let accel = Accel::build(&shapes);
    let mut sampler = Sampler::new(1, 0);
    let mut leaks = 0;
    let mut rays = 0;
    let center = to_world.transform_point3(Vec3::ZERO);
    // Random interior origins, random directions.
    for _ in 0..100_000 {
        let o = center + snee::math::warp::square_to_uniform_sphere(sampler.next_2d()) * 1.9 * sampler.next_1d().cbrt();
        let d = snee::math::warp::square_to_uniform_sphere(sampler.next_2d());
        rays += 1;
        if accel.intersect(&shapes, &Ray::new(o, d)).is_none() {
            eprintln!("random leak: o {:?} d {:?}", o, d);
            leaks += 1;
        }
    }
    // From the centre exactly through every vertex and an edge midpoint next to it: the hardest cases.
    for (i, v) in verts.iter().enumerate() {
        let target = to_world.transform_point3(*v);
        rays += 1;
        if accel.intersect(&shapes, &Ray::new(center, (target - center).normalize())).is_none() {
            eprintln!("vertex leak {:?}", (target - center).normalize());
            leaks += 1;
        }
        let w = to_world.transform_point3(verts[(i + 1) % verts.len()]);
        let m = 0.5 * (target + w);
        rays += 1;
        if accel.intersect(&shapes, &Ray::new(center, (m - center).normalize())).is_none() {
            eprintln!("edge leak {:?}", (m - center).normalize());
            leaks += 1;
        }
    }
    eprintln!("{} triangles: {} of {} rays leaked", 20 * 4u64.pow(level), leaks, rays);
    assert_eq!(leaks, 0, "{} of {} rays leaked through the closed mesh", leaks, rays);
}

#[test]
fn closest_hit_and_occlusion_agree() {
    let shapes = vec![shape(icosphere(3), Mat4::IDENTITY)];
    let accel = Accel::build(&shapes);
    let mut sampler = Sampler::new(2, 0);
    for _ in 0..2000 {
        let o = Vec3::new(0.0, 0.0, -3.0) + Vec3::new(sampler.next_1d() - 0.5, sampler.next_1d() - 0.5, 0.0) * 3.0;
        let ray = Ray::new(o, Vec3::Z);
        let hit = accel.intersect(&shapes, &ray);
        assert_eq!(hit.is_some(), accel.occluded(&shapes, &ray));
        if let Some(h) = hit {
            let p = o + Vec3::Z * h.t;
            // Hits lie on the tessellated unit sphere (within the chord error of level 3).
            assert!((p.length() - 1.0).abs() < 0.01, "hit at radius {}", p.length());
            assert!(h.b1 >= 0.0 && h.b2 >= 0.0 && h.b1 + h.b2 <= 1.0 + 1e-5);
        }
    }
    let _ = Vec2::ZERO;
}

#[test]
fn negative_zero_directions_hit() {
    // Axis-aligned rays often carry −0.0 components (e.g. after negating a vector).
    let shapes = vec![shape(icosphere(2), Mat4::IDENTITY)];
    let accel = Accel::build(&shapes);
    for d in
        [Vec3::new(-0.0, -0.0, 1.0), Vec3::new(0.0, -0.0, -1.0), Vec3::new(-1.0, -0.0, 0.0), Vec3::new(0.0, 1.0, -0.0)]
    {
        let inside = Ray::new(Vec3::new(0.1, 0.05, -0.02), d);
        assert!(accel.intersect(&shapes, &inside).is_some(), "ray along {:?} leaked", d);
        assert!(accel.occluded(&shapes, &inside), "shadow ray along {:?} leaked", d);
    }
}

/// Shadow-ray transmittance by one any-hit query (scenes where every surface blocks shadow rays)
/// equals the full segment walk bit for bit, with the same samples drawn, on rays between random
/// points inside and around the rough-glass sphere of `media_rough_glass.xml` (in and out of its
/// medium, towards finite and infinitely distant points).
#[test]
fn opaque_shadow_rays_equal_the_walk() {
    use snee::integrator::stats::LocalStats;
    use snee::integrator::volpath::shadow_transmittance;
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/media_rough_glass.xml");
    let mut scene = snee::scene::build::load_scene(&path, &[]).unwrap();
    assert!(scene.surfaces_block_shadow_rays && !scene.media.is_empty());
    let (center, radius) = {
        let b = scene.bounds;
        ((b.min + b.max) * 0.5, (b.max - b.min).length() * 0.5)
    };
    let mut s = Sampler::new(17, 0);
    let (mut nonzero, mut zero) = (0, 0);
    for i in 0..20_000 {
        let p = |s: &mut Sampler| center + (Vec3::new(s.next_1d(), s.next_1d(), s.next_1d()) - 0.5) * radius;
        let (o, q) = (p(&mut s), p(&mut s));
        let ray = if i % 4 == 0 {
            Ray::new(o, (q - o).normalize())
        } else {
            Ray { o, d: (q - o).normalize(), tmax: (q - o).length() }
        };
        let medium = if i % 2 == 0 { Some(0) } else { None };
        let channel = i % 3;
        let mut results = Vec::new();
        for opaque in [true, false] {
            scene.surfaces_block_shadow_rays = opaque;
            let (mut sampler, mut stats) = (Sampler::new(5, i as u64), LocalStats::default());
            let tr = shadow_transmittance(&scene, ray.to_a(), medium, channel, &mut sampler, &mut stats);
            results.push((tr.to_array().map(f32::to_bits), sampler.next_1d().to_bits(), stats.rays));
        }
        assert_eq!(results[0], results[1], "ray {ray:?} medium {medium:?}");
        if results[0].0 == [0; 3] {
            zero += 1;
        } else {
            nonzero += 1;
        }
    }
    assert!(zero > 1000 && nonzero > 1000, "{zero} blocked, {nonzero} passed");
}
