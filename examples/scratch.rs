fn main() {
    let s = snee::scene::build::load_scene(std::path::Path::new("scenes/directional_area.xml"), &[]).unwrap();
    for sh in &s.shapes {
        if let snee::shape::Geometry::Disk(d) = &sh.geometry {
            println!("{:?}\n{:?} area {}", d.to_world, d.n, d.surface_area());
        }
    }
}
