//! The medium emitter-sampling skip (`integrator/enclosure.rs`): which media of the repository's
//! scenes qualify, and that where one does, the full shadow-ray estimate is exactly 0 and consumes
//! exactly the samples the skip draws (so skipping keeps the random-number stream), for `volpath`'s
//! and for `volpathmis`'s shadow-ray estimate.

use snee::integrator::stats::LocalStats;
use snee::integrator::volpath::{sample_emitter, skip_sample_emitter};
use snee::integrator::volpathmis::{sample_emitter as mis_sample_emitter, POverF};
use snee::integrator::walk::RefPoint;
use snee::math::Vec3;
use snee::sampler::Sampler;
use snee::scene::build::build_scene;
use snee::scene::world::Scene;
use snee::scene::xml::parse_file;
use snee::shape::Geometry;
use std::path::Path;

fn load(file: &str) -> Scene {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR"));
    let parsed = parse_file(&dir.join(file), &[]).unwrap_or_else(|e| panic!("{}", e));
    build_scene(&parsed).unwrap_or_else(|e| panic!("{}", e))
}

#[test]
fn qualifying_media_of_the_scenes() {
    // Closed dielectric / roughdielectric boundaries, lights outside: emitter sampling is always 0.
    for f in ["scenes/media_rough_glass.xml", "scenes/media_smooth_glass.xml", "scenes/media_spot.xml"] {
        assert_eq!(load(f).emitters_unreachable, vec![true], "{f}");
    }
    assert_eq!(load("scenes/paper/sphere_smooth_st34.xml").emitters_unreachable, vec![true]);
    assert_eq!(load("scenes/paper/envmap_ggx020_st02.xml").emitters_unreachable, vec![true]);
    // Null / thin-dielectric boundaries pass shadow rays; a light and a cube inside (named as the
    // medium's exterior); the camera inside a null sphere.
    for f in
        ["scenes/media_null.xml", "scenes/media_thin.xml", "scenes/media_inside.xml", "scenes/media_camera_inside.xml"]
    {
        assert_eq!(load(f).emitters_unreachable, vec![false], "{f}");
    }
}

#[test]
fn skip_draws_what_the_shadow_ray_draws() {
    for f in ["scenes/media_rough_glass.xml", "scenes/media_thin.xml"] {
        let scene = load(f);
        let sphere = scene
            .shapes
            .iter()
            .find_map(|s| match (&s.geometry, s.interior) {
                (Geometry::Sphere(sp), Some(0)) => Some(sp.clone()),
                _ => None,
            })
            .expect("a sphere bounding medium 0");
        let mut points = Sampler::new(11, 0);
        let (mut zero, mut nonzero) = (0, 0);
        for i in 0..20_000u64 {
            // A uniform point inside the sphere (rejection from its cube).
            let u = Vec3::new(points.next_1d(), points.next_1d(), points.next_1d()) * 2.0 - Vec3::ONE;
            if u.length() >= 0.999 {
                continue;
            }
            let p = sphere.center + u * sphere.radius;
            let mut full = Sampler::new(5, i);
            let mut skip = full.clone();
            let channel = (i % 3) as usize;
            let mut stats = LocalStats::default();
            let (emitted, _) = sample_emitter(&scene, RefPoint::Medium(p), Some(0), channel, &mut full, &mut stats);
            skip_sample_emitter(&scene, p, &mut skip);
            if emitted == snee::color::Spectrum::ZERO {
                zero += 1;
            } else {
                nonzero += 1;
            }
            // volpathmis's estimator (its own shadow-ray walk) from the same sample stream.
            let mut mis = Sampler::new(5, i);
            let (nee, uni, emitted_mis, _) =
                mis_sample_emitter(&scene, RefPoint::Medium(p), Some(0), &POverF::ONE, channel, &mut mis, &mut stats);
            if scene.emitters_unreachable[0] {
                assert_eq!(emitted, snee::color::Spectrum::ZERO, "{f}: nonzero estimate at {p}");
                assert_eq!(full.next_1d(), skip.next_1d(), "{f}: sample streams diverge at {p}");
                let c = nee.weight_with(&uni) * emitted_mis;
                assert_eq!(c, snee::color::Spectrum::ZERO, "{f}: nonzero volpathmis estimate at {p}");
                let mut skip = Sampler::new(5, i);
                skip_sample_emitter(&scene, p, &mut skip);
                assert_eq!(mis.next_1d(), skip.next_1d(), "{f}: volpathmis sample streams diverge at {p}");
            }
        }
        // The thin-dielectric sphere does not qualify, and there the estimate is often nonzero.
        if !scene.emitters_unreachable[0] {
            assert!(nonzero > 100, "{f}: {nonzero} nonzero of {}", zero + nonzero);
        }
    }
}

/// `skip_sample_emitter` decides without sampling where it can (a constant sphere light seen from
/// outside, `volpath::surely_usable`): it must draw exactly what the emitter sample would make it
/// draw, at points inside the statue, near the light (inside it, on it, just outside) and far away.
#[test]
fn skip_decides_as_the_emitter_sample_does() {
    let scene = load("scenes/paper/sphere_smooth_st34.xml");
    let sphere = scene
        .shapes
        .iter()
        .find_map(|s| match (&s.geometry, s.emitter) {
            (Geometry::Sphere(sp), Some(_)) => Some(sp.clone()),
            _ => None,
        })
        .expect("the sphere light");
    let bounds = scene.shapes.iter().find(|s| s.interior.is_some()).expect("the statue").bounds();
    let mut points = Sampler::new(13, 0);
    let (mut usable, mut unusable) = (0, 0);
    for i in 0..200_000u64 {
        let u = Vec3::new(points.next_1d(), points.next_1d(), points.next_1d());
        let p = match i % 4 {
            // In the statue's box, and in a box 4 radii around the light's centre.
            0 | 1 => bounds.min + u * (bounds.max - bounds.min),
            2 => sphere.center + (u * 2.0 - Vec3::ONE) * (4.0 * sphere.radius),
            // Within a few 1e-4 of the light's surface (both sides) and very far.
            _ if i % 8 == 3 => {
                let d = (u * 2.0 - Vec3::ONE).normalize_or(Vec3::Y);
                sphere.center + d * sphere.radius * (1.0 + (points.next_1d() - 0.5) * 1e-3)
            }
            _ => sphere.center + (u * 2.0 - Vec3::ONE) * 1e5,
        };
        let mut skip = Sampler::new(17, i);
        let mut full = skip.clone();
        skip_sample_emitter(&scene, p, &mut skip);
        let (ds, emitted) = scene.sample_emitter_direction(p, None, full.next_2d(), false);
        if ds.pdf != 0.0 && emitted != snee::color::Spectrum::ZERO {
            let _ = full.next_1d();
            usable += 1;
        } else {
            unusable += 1;
        }
        assert_eq!(skip.next_1d(), full.next_1d(), "sample streams diverge at {p} ({i})");
    }
    // Both outcomes occur (inside the light no sample is usable towards its back).
    assert!(usable > 1000 && unusable > 1000, "{usable} usable, {unusable} not");
}
