//! The official Khronos glTF validator (npm `gltf-validator`, `tests/gltf/validate.mjs`) on a
//! tile `.glb`, tile `.gltf` documents (their images fetched through their relative URIs) and a
//! patch, from the real binary; any error or warning fails. Needs node; the test runs `npm ci`
//! in `tests/gltf` itself when its packages are missing. Without node it says on the terminal
//! that it skipped, and why; under CI it fails instead.

mod common;

use std::path::PathBuf;
use std::process::Command;

use common::Server;

fn dir_of_validator() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../tests/gltf")
}

#[test]
fn khronos_validator_accepts_every_gltf_answer() {
    let dir = dir_of_validator();
    if let Err(why) = common::npm_ready(&dir, "gltf-validator") {
        return common::skip("khronos_validator_accepts_every_gltf_answer", &why);
    }
    let s = Server::builder().start();
    let out = Command::new("node")
        .arg("validate.mjs")
        .arg(&s.base)
        .args([
            "/gltf/gravel/7/-3/2.glb?seed=4",
            "/gltf/gravel/7/-3/2.gltf?seed=4",
            "/gltf/grass/7/0/0.gltf",
            "/gltf/brick/5/-1/0.gltf?mode=mosaic&world=2",
            "/gltf/brick/6/-2147483648/2147483647.glb",
            "/gltf/gravel/patch.glb?z=7&x=-1&y=-1&tiles=3",
            "/3dtiles/gravel/tiles/3/2/5.glb?seed=4",
            "/3dtiles/gravel/tiles/18/131075/131070.glb?seed=4",
            "/gltf/flagstones/8/3/-2.glb?seed=2",
            "/gltf/flagstones/6/0/1.glb?mode=mosaic",
            "/3dtiles/flagstones/tiles/2/1/1.glb",
            "/3dtiles/flagstones/tiles/16/32770/32765.glb?relief=8",
            "/gltf/flagstones/7/-1/3.glb?relief=8&seed=5",
            "/gltf/flagstones/8/3/-2.gltf?seed=2",
            "/gltf/meadow/8/3/4.glb?relief=8&seed=3",
            "/gltf/meadow/8/3/4.gltf",
            "/gltf/meadow/patch.glb?z=8&x=3&y=4&tiles=2",
            "/3dtiles/meadow/tiles/19/262147/262139.glb?relief=8",
        ])
        .current_dir(&dir)
        .output()
        .expect("run node");
    let report = String::from_utf8_lossy(&out.stdout);
    eprintln!("{report}{}", String::from_utf8_lossy(&out.stderr));
    assert!(out.status.success(), "the validator reported errors or warnings");
    assert_eq!(report.matches("0 errors, 0 warnings").count(), 18, "{report}");
    // A material with roughness and metallic maps (packed into metallicRoughnessTexture).
    let dir = tempfile::tempdir().unwrap();
    let cfg = common::rough_metal_config(dir.path());
    let s = Server::builder().args(&["--config", cfg.to_str().unwrap()]).start();
    let out = Command::new("node")
        .arg("validate.mjs")
        .arg(&s.base)
        .arg("/gltf/rough/8/-2/5.glb?seed=4")
        .arg("/gltf/rough/8/-2/5.gltf?seed=4")
        .current_dir(dir_of_validator())
        .output()
        .expect("run node");
    let report = String::from_utf8_lossy(&out.stdout);
    eprintln!("{report}{}", String::from_utf8_lossy(&out.stderr));
    assert!(out.status.success() && report.matches("0 errors, 0 warnings").count() == 2, "{report}");
}
