//! Property-based contract testing of the whole HTTP API against its own `/openapi.json` with
//! Schemathesis (PyPI, `tests/contract/requirements.txt`, installed by `.ci/run`): a bounded,
//! seeded run over every operation (coverage, fuzzing and stateful phases) must find no 5xx, no
//! undocumented status, and every answer conforming to the documented schema, content type and
//! headers. Requests the schema allows but a texture refuses (a zoom beyond its native one, say)
//! are legitimately 4xx, so the check that every schema-valid request is accepted is left out.

mod common;

use std::process::Command;

use common::Server;

#[test]
fn the_api_keeps_its_openapi_contract() {
    let st = Command::new("st").arg("--version").output();
    if !st.is_ok_and(|o| o.status.success()) {
        return common::skip(
            "the_api_keeps_its_openapi_contract",
            "Schemathesis is not installed (pip install -r tests/contract/requirements.txt)",
        );
    }
    // With an admin token configured (and not given to Schemathesis), so the admin routes exist
    // and their refusals are held to the contract too.
    let data = tempfile::tempdir().expect("temp dir");
    let s =
        Server::builder().data_dir(data.path()).env("TEXTILE_ADMIN_TOKEN", "contract-test-token-0123456789").start();
    // Schemathesis keeps a cache in its working directory: give it a temporary one.
    let scratch = tempfile::tempdir().expect("temp dir");
    let config = format!("{}/../tests/contract/schemathesis.toml", env!("CARGO_MANIFEST_DIR"));
    let out = Command::new("st")
        .args(["--config-file", &config, "run", &s.url("/openapi.json")])
        .args(["--max-examples", "30", "--seed", "1", "--checks", "all"])
        .args(["--exclude-checks", "positive_data_acceptance", "--request-timeout", "60"])
        .env("NO_COLOR", "1")
        .current_dir(scratch.path())
        .output()
        .expect("run schemathesis");
    let text = format!("{}{}", String::from_utf8_lossy(&out.stdout), String::from_utf8_lossy(&out.stderr));
    assert!(out.status.success(), "Schemathesis found contract violations:\n{text}");
    assert!(text.contains("passed") && !text.contains("failures"), "{text}");
}
