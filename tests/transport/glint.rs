//! Glints from the camera (`manifold/glint.rs`) on the paper's statue and on a glass ball.

use crate::common;
use crate::manifold_curved_statue::statue;
use glam::DVec2;
use snee::integrator::manifold::glint::{self, CameraMap, Chain, Region, SceneGlint};
use snee::integrator::stats::LocalStats;
use snee::math::DVec3;
use snee::sensor::Camera;

/// On the statue (96 × 128): per chain, the smallest angle between `o(u)` and `omega_l` over a
/// 4×4 grid per pixel (printed), and the glints Newton finds from 4 seeds in every pixel, each
/// verified with the renderer's rays. The outer reflection makes glints (over 50 converged
/// solves, all verified values finite and the sum positive); the light is in front of the statue,
/// so no ray through the statue without an internal reflection reaches it (`Through`: none).
#[test]
fn statue_glints_are_found_and_finite() {
    let _ = common::root();
    let scene = statue("2");
    let Camera::Perspective(p) = &scene.camera else { panic!() };
    let cam = CameraMap::new(p, scene.film.width, scene.film.height);
    let omega_l = DVec3::new(0.286788, 0.819152, 0.496732).normalize();
    for chain in [Chain::Reflect, Chain::Through] {
        let mut locate = SceneGlint { scene: &scene, rays: 0 };
        let mut best = (f64::MAX, DVec2::ZERO);
        let mut on = 0;
        let (w, h) = (scene.film.width, scene.film.height);
        for y in 0..h * 4 {
            for x in 0..w * 4 {
                let u = DVec2::new(x as f64 + 0.5, y as f64 + 0.5) / 4.0;
                let Some((_, m)) = glint::locate_at(&mut locate, &cam, chain, u) else { continue };
                on += 1;
                let a = m.o.dot(omega_l).clamp(-1.0, 1.0).acos();
                if a < best.0 {
                    best = (a, u);
                }
            }
        }
        let whole = Region { lo: DVec2::new(-1e3, -1e3), hi: DVec2::new(1e4, 1e4) };
        let (r, it) = glint::solve(&mut locate, &cam, chain, omega_l, whole, best.1);
        eprintln!("from the best grid point: {:?} after {it}", r.map(|s| (s.u, s.map.cos_1, s.du_do)));
        let mut found = 0;
        let mut energy = 0.0;
        let mut stats = LocalStats::default();
        for y in 0..h {
            for x in 0..w {
                let region = Region::pixel(DVec2::new(x as f64, y as f64));
                for k in 0..4 {
                    let seed = region.at(0.125 + 0.25 * k as f64, 0.125 + 0.25 * ((k * 3) % 4) as f64);
                    if let (Some(s), _) = glint::solve(&mut locate, &cam, chain, omega_l, region, seed) {
                        found += 1;
                        let v = glint::verify(&scene, &cam, &s, omega_l, &mut stats);
                        assert!(v.is_finite(), "{chain:?}: non-finite glint {v:?} at {:?}", s.u);
                        energy += v.to_array()[0] as f64 / 4.0;
                    }
                }
            }
        }
        eprintln!("{chain:?}: {on} grid points on the boundary, min angle {best:?}, {found} solves converged, energy {energy}");
        match chain {
            Chain::Reflect => assert!(found > 50 && energy > 0.0, "{found} glints, energy {energy}"),
            Chain::Through => assert_eq!(found, 0),
            Chain::Inside => unreachable!("not in this test's chains"),
        }
    }
}
