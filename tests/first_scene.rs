//! The README's first command renders `scenes/first.xml`: it must render a finite image quickly and
//! actually use the technique it is there to show (`connection = complete`: manifold NEE through the
//! glass cube's flat faces finds solutions; `docs/manifold.md`).

use std::path::PathBuf;
use std::process::Command;

#[test]
fn first_scene_uses_the_complete_connection() {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("target/test-output/first_scene");
    std::fs::create_dir_all(&dir).unwrap();
    let exr = dir.join("first.exr");
    let stats = dir.join("first.json");
    let o = Command::new(env!("CARGO_BIN_EXE_snee"))
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .args(["render", "scenes/first.xml", "-D", "width=48", "-D", "height=36", "--spp", "2", "--seed", "3"])
        .arg("-o")
        .arg(&exr)
        .arg("--stats")
        .arg(&stats)
        .arg("-q")
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let st: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&stats).unwrap()).unwrap();
    assert_eq!(st["connection"], "complete", "{st}");
    assert!(st["manifold_solutions"].as_u64().unwrap() > 0, "no manifold connection found: {st}");
    assert_eq!(st["rejected_samples"].as_u64().unwrap(), 0, "{st}");
}
