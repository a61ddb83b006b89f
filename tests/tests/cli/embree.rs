//! `--accel embree` through the command line: with the `embree` feature,
//! Embree is measured beside our structures and verified as a peer whose
//! differences are not failures; without it, naming it is a clean error
//! that says how to enable it.

use super::{path_str, rtgi};
use rtgi_tests::scratch_dir;

#[cfg(feature = "embree")]
#[test]
fn bench_shows_embree_beside_our_structures() {
    let run = rtgi(&[
        "bench",
        "--accel",
        "sah,embree",
        "--width",
        "16",
        "--height",
        "16",
        "--rays",
        "500",
        "--repeats",
        "1",
        "--leak-rays",
        "1000",
    ]);
    assert!(run.success, "{run:?}");
    let row = |name: &str| run.stdout.lines().find(|l| l.split_whitespace().next() == Some(name));
    assert!(row("sah").is_some(), "{}", run.stdout);
    let embree = row("embree").unwrap_or_else(|| panic!("no embree row in\n{}", run.stdout));
    // Throughput is measured; node counts are not reported by Embree.
    assert!(embree.contains(" - "), "{embree}");
    assert!(run.stdout.contains("a peer"), "{}", run.stdout);
}

#[cfg(feature = "embree")]
#[test]
fn all_includes_embree_in_bench() {
    let run =
        rtgi(&["bench", "--width", "8", "--height", "8", "--rays", "200", "--repeats", "1", "--leak-rays", "100"]);
    assert!(run.success, "{run:?}");
    for name in ["linear", "sah", "embree"] {
        assert!(run.stdout.lines().any(|l| l.split_whitespace().next() == Some(name)), "{name}:\n{}", run.stdout);
    }
}

#[cfg(feature = "embree")]
#[test]
fn verify_reports_embree_as_a_peer_and_succeeds() {
    let dir = scratch_dir("verify-embree");
    let json = dir.join("verify.json");
    let run = rtgi(&["verify", "--accel", "all", "--rays", "20000", "--json", path_str(&json)]);
    assert!(run.success, "a peer's differences must not fail the run: {run:?}");
    assert!(run.stdout.contains("embree (peer)"), "{}", run.stdout);
    assert!(run.stdout.contains("peer: differences are not failures"), "{}", run.stdout);
    let report: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    let structures = report["structures"].as_array().expect("structures");
    let embree = structures.iter().find(|s| s["structure"] == "embree (peer)").expect("an embree row");
    assert_eq!(embree["peer"], true);
    // Our structures are still held to the contract, and pass it.
    for ours in structures.iter().filter(|s| s["peer"] == false) {
        assert_eq!(ours["tally"]["closest_disagreements"], 0, "{ours}");
    }
}

#[cfg(feature = "embree")]
#[test]
fn render_and_trace_run_on_embree() {
    let dir = scratch_dir("render-embree");
    let image = dir.join("box.png");
    let run =
        rtgi(&["render", "--accel", "embree", "-o", path_str(&image), "--width", "16", "--height", "16", "--spp", "1"]);
    assert!(run.success && image.exists(), "{run:?}");
}

#[cfg(not(feature = "embree"))]
#[test]
fn naming_embree_without_the_feature_says_how_to_enable_it() {
    // The Embree tests above are not in this build: a skip, which fails
    // where RTGI_REQUIRE_EMBREE asks for them (CI's Embree step).
    rtgi_tests::skip_without(
        rtgi_tests::Requirement::Embree,
        "the Embree tests are not built (cargo test --features embree, with libembree-dev installed)",
    );
    let dir = scratch_dir("no-embree");
    let out = dir.join("out.png");
    for args in [
        vec!["render", "--accel", "embree", "-o", path_str(&out)],
        vec!["bench", "--accel", "sah,embree"],
        vec!["verify", "--accel", "embree"],
        vec!["trace", "scenes/cornell-box.toml", "--rays", "r.bin", "--out", "h.bin", "--accel", "embree"],
    ] {
        let run = rtgi(&args);
        assert!(!run.success, "{args:?}: {run:?}");
        assert!(run.code.is_some_and(|c| c != 101), "{args:?}: exit {:?} (101 is a panic)", run.code);
        assert!(!run.stderr.contains("panicked"), "{args:?}: {}", run.stderr);
        assert!(run.stderr.contains("--features embree"), "{args:?}: {}", run.stderr);
        assert!(run.stderr.contains("apt install libembree-dev"), "{args:?}: {}", run.stderr);
        assert_eq!(run.stderr.trim().lines().count(), 1, "one line: {}", run.stderr);
    }
    assert!(!out.exists());
}

#[cfg(feature = "embree")]
#[test]
fn the_accel_and_scaling_experiments_measure_embree_beside_ours() {
    let dir = scratch_dir("embree-experiments");
    for knob in ["accel", "scaling"] {
        let out = dir.join(knob);
        let run = rtgi(&["experiment", knob, "--quick", "--repeats", "1", "--out", path_str(&out)]);
        assert!(run.success, "{run:?}");
        let json: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(out.join(format!("{knob}.json"))).unwrap()).unwrap();
        let series = json["series"].as_array().unwrap();
        let embree = series.iter().find(|s| s["name"] == "embree").unwrap_or_else(|| panic!("{knob}: no embree"));
        for point in embree["points"].as_array().unwrap() {
            let bytes = point["values"]["bytes_per_triangle"].as_f64().unwrap();
            assert!(bytes > 0.0, "{knob}: Embree's memory per triangle {bytes}");
        }
    }
    let accel = std::fs::read_to_string(dir.join("accel/accel.md")).unwrap();
    assert!(accel.contains("embree (a peer, outside the exactness contract)"), "{accel}");
    // Each structure that builds slower and traces faster than the next
    // cheaper one gets a break-even, or the verdict that one run each
    // cannot resolve the differences it would rest on.
    assert!(
        accel.contains("accel-total.svg")
            && (accel.contains("pays for it from") || accel.contains("no break-even is claimed")),
        "{accel}"
    );
}
