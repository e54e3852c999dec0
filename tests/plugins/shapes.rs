//! Chi-square tests of the area-light sampling routines of shapes: `Shape::sample_direction`
//! (sphere: uniform cone from outside, by area from inside; meshes and disks: by area converted
//! to solid angle) against `Shape::pdf_direction`, and the scene's emitter sampling against
//! `Scene::pdf_emitter_direction`.

use snee::interaction::DirectionSample;
use snee::math::{Mat4, Ray, Vec3};
use snee::scene::build::build_scene;
use snee::scene::xml::parse_str;
use snee::shape::accel::Accel;
use snee::shape::rectangle::rectangle_data;
use snee::shape::{Disk, Geometry, Mesh, Shape, Sphere};
use snee::testing::chi2::chi2_sphere;

fn shape(geometry: Geometry) -> Shape {
    Shape { geometry, plugin: "test".into(), id: None, bsdf: 0, emitter: None, interior: None, exterior: None }
}

/// Solid-angle density of the first hit along `d` (the shapes here are hit at most once per ray
/// from the reference point, except the sphere seen from outside whose density is per direction).
fn pdf_of_direction(shapes: &[Shape], accel: &Accel, ref_p: Vec3, d: Vec3) -> f32 {
    let Some(hit) = accel.intersect(shapes, &Ray::new(ref_p, d)) else { return 0.0 };
    let s = &shapes[hit.shape as usize];
    let si = s.interaction(hit.prim, hit.b1, hit.b2, hit.t, &Ray::new(ref_p, d));
    let ds = DirectionSample { p: si.p, n: si.n, uv: si.uv, d, dist: hit.t, pdf: 0.0, delta: false, emitter: 0 };
    s.pdf_direction(ref_p, &ds)
}

fn check(name: &str, s: Shape, ref_p: Vec3) {
    let shapes = vec![s];
    let accel = Accel::build(&shapes);
    let r = chi2_sphere(
        |_, u| {
            let ds = shapes[0].sample_direction(ref_p, u);
            (ds.pdf > 0.0).then_some(ds.d)
        },
        |d| pdf_of_direction(&shapes, &accel, ref_p, d),
        48,
        96,
        400_000,
        0.01,
        11,
    );
    assert!(r.passed, "{}: {}", name, r.report);
    assert!((r.pdf_integral - 1.0).abs() < 5e-3, "{}: ∫pdf = {}", name, r.pdf_integral);
}

#[test]
fn sphere_from_outside_cone_sampling() {
    check("sphere outside", shape(Geometry::Sphere(Sphere::new(Vec3::new(0.3, 0.2, 2.0), 1.0, false))), Vec3::ZERO);
}

#[test]
fn sphere_from_inside_area_sampling() {
    check("sphere inside", shape(Geometry::Sphere(Sphere::new(Vec3::new(0.3, 0.2, 0.1), 1.0, false))), Vec3::ZERO);
}

#[test]
fn rectangle_area_sampling() {
    let m = Mat4::from_translation(Vec3::new(0.2, -0.1, 0.8))
        * Mat4::from_rotation_x(0.4)
        * Mat4::from_scale(Vec3::new(1.5, 0.7, 1.0));
    check("rectangle", shape(Geometry::Mesh(Mesh::new(rectangle_data(), &m, false, false))), Vec3::ZERO);
}

/// Triangles of unequal areas (alias-table selection, per-triangle sampling data, uvs present):
/// a planar fan at z = 1, so that every ray from the origin meets it at most once.
#[test]
fn mesh_of_unequal_triangles_area_sampling() {
    use snee::math::Vec2;
    use snee::shape::mesh_data::MeshData;
    let positions = vec![
        Vec3::new(0.0, 0.0, 1.0),
        Vec3::new(1.2, -0.1, 1.0),
        Vec3::new(0.9, 0.6, 1.0),
        Vec3::new(-0.2, 0.8, 1.0),
        Vec3::new(-0.9, 0.1, 1.0),
        Vec3::new(-0.3, -0.9, 1.0),
    ];
    let uvs = positions.iter().map(|p| Vec2::new(p.x, p.y)).collect();
    let indices = vec![[0, 1, 2], [0, 2, 3], [0, 3, 4], [0, 4, 5], [0, 5, 1]];
    let data = MeshData { positions, normals: Vec::new(), uvs, indices };
    let m = Mat4::from_translation(Vec3::new(0.1, 0.0, 0.3)) * Mat4::from_rotation_y(0.3);
    check("mesh fan", shape(Geometry::Mesh(Mesh::new(data, &m, false, true))), Vec3::ZERO);
}

#[test]
fn disk_area_sampling() {
    let m = Mat4::from_translation(Vec3::new(-0.3, 0.4, 1.0))
        * Mat4::from_rotation_y(0.6)
        * Mat4::from_scale(Vec3::new(1.2, 0.8, 1.0));
    check("disk", shape(Geometry::Disk(Disk::new(m, false))), Vec3::ZERO);
}

#[test]
fn scene_emitter_sampling_pdf_matches() {
    // Two area lights (one-sided) and an environment: the sampled pdf must equal the evaluated one.
    let xml = r#"<scene version="3.0.0">
        <emitter type="constant"><rgb name="radiance" value="0.5, 0.5, 0.5"/></emitter>
        <shape type="sphere"><point name="center" value="0, 0, 3"/><emitter type="area"><rgb name="radiance" value="3, 3, 3"/></emitter></shape>
        <shape type="rectangle"><transform name="to_world"><rotate x="1" angle="90"/><translate y="2"/></transform>
            <emitter type="area"><rgb name="radiance" value="1, 2, 3"/></emitter></shape>
        <sensor type="perspective"><film type="hdrfilm"><integer name="width" value="4"/><integer name="height" value="4"/></film></sensor>
    </scene>"#;
    let parsed = parse_str(xml, "t.xml", std::path::Path::new("."), &[]).unwrap();
    let scene = build_scene(&parsed).unwrap();
    let mut sampler = snee::sampler::Sampler::new(5, 0);
    let ref_p = Vec3::new(0.1, 0.2, 0.3);
    let mut checked = 0;
    for _ in 0..20_000 {
        let (ds, w) = scene.sample_emitter_direction(ref_p, None, sampler.next_2d(), false);
        if ds.pdf == 0.0 {
            continue;
        }
        let pdf = scene.pdf_emitter_direction(ref_p, &ds);
        assert!((pdf - ds.pdf).abs() <= 1e-3 * ds.pdf, "sampled pdf {} vs evaluated {}", ds.pdf, pdf);
        assert!(w.is_finite() && w.min_element() >= 0.0);
        checked += 1;
    }
    assert!(checked > 15_000);
}
