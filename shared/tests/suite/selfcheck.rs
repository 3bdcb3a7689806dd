//! The self-check workload that QEMU runs on a Cortex-M4F passes on the host, and is deterministic.

use ringpod_core::selfcheck::{self, CHECKS};

#[test]
fn every_check_passes_on_the_host() {
    let outcome = selfcheck::run();
    for (name, ok) in CHECKS.iter().zip(outcome.passed) {
        assert!(ok, "{name}");
    }
}

#[test]
fn the_digest_is_deterministic_and_sees_the_outputs() {
    let a = selfcheck::run();
    let b = selfcheck::run();
    assert_eq!(a.digest, b.digest);
    assert_ne!(a.digest, selfcheck::Digest::default().0);
}
