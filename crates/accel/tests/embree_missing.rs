//! Without the `embree` feature, naming Embree is an error that says how
//! to get it, never a panic.

#![cfg(not(feature = "embree"))]

use rtgi_accel::AccelKind;

#[test]
fn naming_embree_says_how_to_enable_it() {
    let error = "embree".parse::<AccelKind>().expect_err("the feature is off");
    assert!(error.contains("--features embree"), "{error}");
    assert!(error.contains("apt install libembree-dev"), "{error}");
    assert!(AccelKind::PEERS.is_empty());
    let unknown = "embre".parse::<AccelKind>().expect_err("a typo");
    assert!(unknown.starts_with("unknown acceleration structure 'embre'"), "{unknown}");
}
