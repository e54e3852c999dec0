use super::triangle::{TriPacket4, WatertightRay};
use super::*;
use crate::math::{warp, Vec3};
use crate::sampler::Sampler;

fn soup(seed: u64, count: u32, spread: f32) -> Vec<Shape> {
    let mut s = Sampler::new(seed, 0);
    let mut data = crate::shape::mesh_data::MeshData::default();
    for i in 0..count {
        let c = Vec3::new(s.next_1d(), s.next_1d(), s.next_1d()) * spread;
        for _ in 0..3 {
            data.positions.push(c + Vec3::new(s.next_1d(), s.next_1d(), s.next_1d()) * 0.5);
        }
        data.indices.push([3 * i, 3 * i + 1, 3 * i + 2]);
    }
    let mesh = crate::shape::Mesh::new(data, &crate::math::Mat4::IDENTITY, true, false);
    vec![Shape::from_mesh(mesh)]
}

fn random_ray(s: &mut Sampler, i: usize, spread: f32) -> Ray {
    let o = Vec3::new(s.next_1d(), s.next_1d(), s.next_1d()) * (spread + 4.0) - 2.0;
    let mut d = warp::square_to_uniform_sphere(s.next_2d());
    match i % 6 {
        0 => d = Vec3::new(d.x, 0.0, d.z).normalize(),
        1 => d = Vec3::new(-0.0, d.y.signum(), -0.0),
        _ => {}
    }
    Ray { o, d, tmax: if i.is_multiple_of(3) { f32::INFINITY } else { 1.0 + spread * s.next_1d() } }
}

/// Nearest hit over all triangles, one at a time.
fn brute_force(shapes: &[Shape], ray: &Ray) -> Option<(u32, f32)> {
    let Geometry::Mesh(m) = &shapes[0].geometry else { unreachable!() };
    let wt = WatertightRay::new(ray.o, ray.d);
    let mut best: Option<(u32, f32)> = None;
    for p in 0..m.triangle_count() as u32 {
        let mut packet = TriPacket4::EMPTY;
        packet.set(0, m.vertices(p));
        if let Some((_, t, _, _)) = wt.nearest4(&packet, best.map_or(ray.tmax, |b| b.1)) {
            best = Some((p, t));
        }
    }
    best
}

/// The ISAs this CPU runs, lowest first.
fn isas() -> Vec<Isa> {
    [Isa::Portable, Isa::Avx2, Isa::Avx512].into_iter().filter(|&i| i <= Isa::detect()).collect()
}

/// Every node test the CPU runs gives the portable one's masks and entry distances on every node.
#[cfg(target_arch = "x86_64")]
#[test]
fn simd_node_tests_equal_portable() {
    let shapes = soup(11, 3000, 10.0);
    let accel = Accel::build(&shapes);
    let bvh = accel.bvh.as_ref().unwrap();
    assert!(bvh.nodes.len() > 50);
    let mut s = Sampler::new(12, 0);
    for i in 0..300 {
        let r = random_ray(&mut s, i, 10.0);
        let nr = traverse::NodeRay::new(r.o, r.d);
        for node in &bvh.nodes {
            let mut a = [0.0; 8];
            let ma = traverse::node_test_portable(node, &nr, r.tmax, &mut a);
            let check = |mb: u32, b: [f32; 8]| {
                assert_eq!(ma, mb);
                for k in 0..8 {
                    if ma & (1 << k) != 0 {
                        assert_eq!(a[k].to_bits(), b[k].to_bits());
                    }
                }
            };
            if Isa::detect() >= Isa::Avx2 {
                let mut b = [0.0; 8];
                // SAFETY: AVX2 support checked.
                check(unsafe { traverse::node_test_avx(node, &nr, r.tmax, &mut b) }, b);
            }
            if Isa::detect() >= Isa::Avx512 {
                let mut b = [0.0; 8];
                // SAFETY: AVX-512 support checked.
                check(unsafe { traverse::node_test_avx512(node, &nr, r.tmax, &mut b) }, b);
            }
        }
    }
}

/// The traversals of every ISA the CPU runs find the same hit bit for bit (lane, t, b1, b2) and
/// the same occlusion, on rays through dense and sparse soups (many nodes with three or more hit
/// children, so every ordering path runs), rays aimed at vertices and edges, and a deep tree's
/// heap stack path (the closed sphere in `tests/accel.rs` covers watertightness).
#[test]
fn traversals_of_every_isa_agree() {
    for (seed, count, spread) in [(31, 4000, 6.0), (32, 1500, 30.0), (33, 20, 2.0)] {
        let shapes = soup(seed, count, spread);
        let accels: Vec<Accel> = isas().into_iter().map(|isa| Accel::build_with(&shapes, isa)).collect();
        let Geometry::Mesh(m) = &shapes[0].geometry else { unreachable!() };
        let mut s = Sampler::new(seed + 7, 0);
        let mut hits = 0;
        for i in 0..6000 {
            let mut r = random_ray(&mut s, i, spread);
            if i % 3 == 0 {
                let v = m.vertices(((s.next_1d() * count as f32) as u32).min(count - 1));
                let target = if i % 2 == 0 { v[(i / 6) % 3] } else { v[0] + (v[1] - v[0]) * s.next_1d() };
                r.d = (target - r.o).normalize();
            }
            let key = |h: Option<Hit>| h.map(|h| (h.shape, h.prim, h.t.to_bits(), h.b1.to_bits(), h.b2.to_bits()));
            let want = key(accels[0].intersect(&shapes, &r));
            let occluded = accels[0].occluded(&shapes, &r);
            hits += want.is_some() as u32;
            for a in &accels[1..] {
                assert_eq!(key(a.intersect(&shapes, &r)), want, "{:?} ray {r:?}", a.isa);
                assert_eq!(a.occluded(&shapes, &r), occluded, "{:?} ray {r:?}", a.isa);
                let bvh = a.bvh.as_ref().unwrap();
                // The heap-stack traversals (trees too deep for the fixed stack) are the same code.
                let tmax = r.tmax;
                let ra = r.to_a();
                let (f, g) = (closest_deep(bvh, &ra, tmax, a.isa), a.closest(bvh, &ra, tmax));
                assert_eq!((f.lane, f.t.to_bits(), f.b1.to_bits()), (g.lane, g.t.to_bits(), g.b1.to_bits()));
                assert_eq!(any_deep(bvh, &ra, a.isa), occluded);
            }
        }
        assert!(hits > 500, "only {hits} hits");
    }
}

/// `Isa::selected` never exceeds what the CPU runs, and `build_with` caps a request at it.
#[test]
fn isa_is_capped_at_the_cpu() {
    assert!(Isa::selected() <= Isa::detect());
    let shapes = soup(1, 10, 1.0);
    assert_eq!(Accel::build_with(&shapes, Isa::Avx512).isa, Isa::detect());
    assert_eq!(Accel::build_with(&shapes, Isa::Portable).isa, Isa::Portable);
}

/// Closest hit and occlusion through the BVH equal brute force over all triangles (same
/// distance bit for bit), with either node test, for dense and sparse soups and a tiny mesh.
#[test]
fn traversal_equals_brute_force() {
    for (seed, count, spread) in [(1, 2000, 10.0), (2, 500, 40.0), (3, 3, 1.0), (4, 40, 3.0)] {
        let shapes = soup(seed, count, spread);
        for isa in isas() {
            let accel = Accel::build_with(&shapes, isa);
            let mut s = Sampler::new(seed + 100, 0);
            let mut hits = 0;
            for i in 0..3000 {
                let mut r = random_ray(&mut s, i, spread);
                if i % 2 == 0 {
                    // Aim at a vertex, an edge point or an interior point of a random triangle.
                    let Geometry::Mesh(m) = &shapes[0].geometry else { unreachable!() };
                    let v = m.vertices(((s.next_1d() * count as f32) as u32).min(count - 1));
                    let target = match i % 6 {
                        0 => v[(i / 6) % 3],
                        2 => v[0] + (v[1] - v[0]) * s.next_1d(),
                        _ => v[0] * 0.2 + v[1] * 0.3 + v[2] * 0.5,
                    };
                    r.d = (target - r.o).normalize();
                    r.tmax = f32::INFINITY;
                }
                let want = brute_force(&shapes, &r);
                let got = accel.intersect(&shapes, &r);
                assert_eq!(got.map(|h| h.t), want.map(|w| w.1), "ray {r:?}");
                if let (Some(g), Some(w)) = (got, want) {
                    // Same triangle unless two are hit at exactly the same distance.
                    if g.prim != w.0 {
                        let Geometry::Mesh(m) = &shapes[0].geometry else { unreachable!() };
                        let mut p = TriPacket4::EMPTY;
                        p.set(0, m.vertices(g.prim));
                        let t = WatertightRay::new(r.o, r.d).nearest4(&p, f32::INFINITY).map(|x| x.1);
                        assert_eq!(t, Some(w.1));
                    }
                    hits += 1;
                }
                assert_eq!(accel.occluded(&shapes, &r), want.is_some(), "ray {r:?}");
            }
            assert!(hits > 100, "only {hits} hits");
        }
    }
}

/// Rays with NaN or infinite origin or direction (e.g. from a zero-length segment) neither panic
/// nor hit: `intersect` finds nothing and `occluded` calls them blocked.
#[test]
fn non_finite_rays_do_not_panic() {
    let shapes = soup(5, 500, 10.0);
    for isa in isas() {
        let accel = Accel::build_with(&shapes, isa);
        let bad = [
            Ray { o: Vec3::splat(5.0), d: Vec3::splat(f32::NAN), tmax: f32::INFINITY },
            Ray { o: Vec3::new(f32::NAN, 5.0, 5.0), d: Vec3::X, tmax: 1.0 },
            Ray { o: Vec3::splat(5.0), d: Vec3::new(f32::INFINITY, 0.0, 0.0), tmax: f32::INFINITY },
            Ray { o: Vec3::new(f32::NEG_INFINITY, 5.0, 5.0), d: Vec3::X, tmax: f32::INFINITY },
        ];
        for r in &bad {
            assert!(accel.intersect(&shapes, r).is_none(), "ray {r:?}");
            assert!(accel.occluded(&shapes, r), "ray {r:?}");
        }
    }
}

/// The branch-free per-ray setup (one division for both tests) gives the scalar setup's values bit
/// for bit: `shear_axes`'s axes and shear, and the node test's clamped inverse and octant rows, on
/// random, axis-aligned, signed-zero and tied directions.
#[test]
fn trace_ray_setup_equals_scalar() {
    let mut s = Sampler::new(21, 0);
    let mut dirs = vec![Vec3::X, -Vec3::Y, Vec3::Z, Vec3::new(-0.0, 0.0, -1.0), Vec3::new(1.0, 1.0, 1.0)];
    dirs.extend([Vec3::new(-1.0, 1.0, 0.5), Vec3::new(0.5, -1.0, -1.0), Vec3::new(-0.0, -0.0, 2.0)]);
    for i in 0..20_000 {
        let d = warp::square_to_uniform_sphere(s.next_2d());
        dirs.push(match i % 4 {
            0 => Vec3::new(d.x, -0.0, d.z),
            1 => Vec3::new(d.x, d.x, d.z),
            _ => d,
        });
    }
    for d in dirs {
        let o = Vec3::new(s.next_1d(), s.next_1d(), s.next_1d());
        let tr = traverse::TraceRay::new(o, d);
        // The scalar setup.
        let d0 = d + Vec3::ZERO;
        let inv = |x: f32| if (1.0 / x).is_finite() { 1.0 / x } else { f32::MAX.copysign(x) };
        let want_inv = [inv(d0.x), inv(d0.y), inv(d0.z)].map(f32::to_bits);
        assert_eq!(tr.node.inv_d.map(f32::to_bits), want_inv, "{d:?}");
        for a in 0..3 {
            let neg = (d0[a] < 0.0) as usize;
            assert_eq!((tr.node.near[a], tr.node.far[a]), (8 * (2 * a + neg), 8 * (2 * a + 1 - neg)), "{d:?}");
        }
        let (k, sh) = triangle::shear_axes(d);
        let want = WatertightRay::from_parts(k, sh, o);
        assert_eq!(format!("{:?}", tr.wt), format!("{want:?}"), "{d:?}");
    }
}

/// A closed unit cube of 12 triangles (shared edges and vertices), as one mesh.
fn unit_cube() -> Vec<Shape> {
    let mut data = crate::shape::mesh_data::MeshData::default();
    for i in 0..8u32 {
        data.positions.push(Vec3::new((i & 1) as f32, ((i >> 1) & 1) as f32, ((i >> 2) & 1) as f32) * 2.0 - 1.0);
    }
    // Two triangles per face, outward winding.
    let quads = [[0, 2, 3, 1], [4, 5, 7, 6], [0, 1, 5, 4], [2, 6, 7, 3], [0, 4, 6, 2], [1, 3, 7, 5]];
    for q in quads {
        data.indices.push([q[0], q[1], q[2]]);
        data.indices.push([q[0], q[2], q[3]]);
    }
    let mesh = crate::shape::Mesh::new(data, &crate::math::Mat4::IDENTITY, true, false);
    vec![Shape::from_mesh(mesh)]
}

/// Brute force (`brute.rs`, trees of at most `brute::MAX_TRIANGLES` triangles, AVX2 and AVX-512)
/// finds what the tree's traversal finds: the same distance, barycentrics and triangle bit for bit
/// (the triangle may differ only where two are hit at exactly the same distance), and the same
/// occlusion, on soups of 1 to 16 triangles and on a closed cube from inside and outside with
/// rays aimed at its vertices, edges and diagonals; from inside the cube every ray hits it.
#[test]
fn brute_force_equals_the_tree() {
    let mut cases: Vec<(Vec<Shape>, f32)> = [(41, 1, 1.0), (45, 4, 1.0), (42, 5, 2.0), (43, 16, 3.0), (44, 12, 1.0)]
        .into_iter()
        .map(|(seed, count, spread)| (soup(seed, count, spread), spread))
        .collect();
    cases.push((unit_cube(), 2.0));
    let mut checked = 0;
    for (case, (shapes, spread)) in cases.iter().enumerate() {
        let Geometry::Mesh(m) = &shapes[0].geometry else { unreachable!() };
        let n = m.triangle_count() as u32;
        for isa in isas().into_iter().filter(|&i| i >= Isa::Avx2) {
            let tree = Accel::build_opts(shapes, isa, false);
            let brute = Accel::build_opts(shapes, isa, true);
            // A tree of one packet (at most four triangles) is its own leaf test.
            let want = if n as usize > bvh8::LEAF_SIZE { n as usize } else { 0 };
            assert_eq!((tree.brute_triangles(), brute.brute_triangles()), (0, want), "{isa:?}");
            let mut s = Sampler::new(case as u64 + 50, 0);
            let mut hits = 0;
            for i in 0..20_000 {
                let mut r = random_ray(&mut s, i, *spread);
                if case == 5 && i % 2 == 0 {
                    // From inside the cube towards a vertex, an edge point or a face diagonal.
                    r.o = Vec3::new(s.next_1d(), s.next_1d(), s.next_1d()) * 1.8 - 0.9;
                    let v = m.vertices(((s.next_1d() * n as f32) as u32).min(n - 1));
                    let target = match i % 6 {
                        0 => v[(i / 6) % 3],
                        2 => v[0] + (v[1] - v[0]) * s.next_1d(),
                        _ => v[0] + (v[2] - v[0]) * s.next_1d(),
                    };
                    r.d = (target - r.o).normalize();
                    r.tmax = f32::INFINITY;
                } else if i % 3 == 0 {
                    let v = m.vertices(((s.next_1d() * n as f32) as u32).min(n - 1));
                    r.d = (v[(i / 3) % 3] - r.o).normalize();
                }
                let (want, got) = (tree.intersect(shapes, &r), brute.intersect(shapes, &r));
                let key = |h: Option<Hit>| h.map(|h| (h.t.to_bits(), h.shape));
                assert_eq!(key(got), key(want), "{isa:?} ray {r:?}");
                if let (Some(g), Some(w)) = (got, want) {
                    if g.prim == w.prim {
                        assert_eq!((g.b1.to_bits(), g.b2.to_bits(), g.lane), (w.b1.to_bits(), w.b2.to_bits(), w.lane));
                    }
                    hits += 1;
                } else if case == 5 && i % 2 == 0 {
                    panic!("a ray from inside the cube escaped: {r:?}");
                }
                assert_eq!(brute.occluded(shapes, &r), tree.occluded(shapes, &r), "{isa:?} ray {r:?}");
                checked += 1;
            }
            assert!(hits > 1000, "only {hits} hits");
        }
    }
    if Isa::detect() >= Isa::Avx2 {
        assert!(checked > 0);
    }
}
