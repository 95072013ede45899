//! Inputs the fuzzers found that once crashed flicker, kept in
//! tests/fuzz_regressions/: each must now be refused with an error.

use std::path::Path;

use flicker::scene::Registry;

fn regression(name: &str) -> String {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/fuzz_regressions")
        .join(name);
    String::from_utf8_lossy(&std::fs::read(path).unwrap()).into_owned()
}

#[test]
fn a_sweep_axis_with_a_huge_count_is_refused_before_allocating() {
    // count 100997777777777798 made the sweep parser allocate exabytes.
    let text = regression("sweep_huge_count.json");
    let error = flicker::analysis::sweep::parse_text(
        &text,
        Path::new("/nonexistent"),
        &Registry::builtin(),
    )
    .unwrap_err();
    assert!(error.to_string().contains("count"), "{error}");
}
