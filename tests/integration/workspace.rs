//! The workspace wiring: every crate links together.
#[test]
fn crates_link() {
    let _ = integration_tests::shared_dir();
}
