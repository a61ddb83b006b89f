//! `rtgi experiment --quick`, run as a user would: every knob writes its
//! table, its JSON with the promised fields, and SVG plots with its curves.

use std::path::Path;

use rtgi_tests::{Run, run_cli, scratch_dir};

const RTGI: &str = env!("CARGO_BIN_EXE_rtgi-under-test");

fn rtgi(args: &[&str]) -> Run {
    run_cli(RTGI, args)
}

fn path_str(p: &Path) -> &str {
    p.to_str().expect("scratch paths are UTF-8")
}

/// The plot's SVG is a whole document with a drawn line and a legend entry for each curve named.
fn check_svg(path: &Path, labels: &[&str]) {
    let svg = std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    assert!(svg.trim_start().starts_with("<svg") && svg.trim_end().ends_with("</svg>"), "{}", path.display());
    assert!(svg.matches("<polyline").count() >= labels.len(), "{}: too few lines", path.display());
    for label in labels {
        assert!(svg.contains(label), "{}: no curve '{label}'", path.display());
    }
}

#[test]
fn every_knob_writes_its_table_json_and_plots() {
    let dir = scratch_dir("experiment-all");
    let run = rtgi(&["experiment", "all", "--quick", "--repeats", "2", "--out", path_str(&dir)]);
    assert!(run.success, "{run:?}");
    let mut commits = std::collections::BTreeSet::new();
    // Every knob of the registry: a new knob is tested as soon as it is listed.
    for knob in rtgi_experiment::KNOBS.iter().map(|k| k.name()) {
        let folder = dir.join(knob);
        let md = std::fs::read_to_string(folder.join(format!("{knob}.md"))).expect("the table");
        assert!(md.contains(&format!("# `{knob}`")) && md.contains("|---|"), "{md}");
        let json: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(folder.join(format!("{knob}.json"))).expect("the JSON"))
                .expect("valid JSON");
        assert_eq!(json["knob"], knob);
        assert!(json["machine"]["cpu"].as_str().is_some_and(|c| !c.is_empty()), "{json}");
        assert!(json["machine"]["cores"].as_u64().is_some_and(|c| c >= 1));
        assert!(json["machine"]["threads"].as_u64().is_some_and(|c| c >= 1));
        // Provenance: the commit (and whether the tree was dirty), the compiler, profile and date.
        let build = &json["build"];
        assert!(build["commit"].as_str().is_some_and(|c| c.len() >= 7), "{json}");
        assert!(build["rustc"].as_str().is_some_and(|c| c.starts_with("rustc")), "{build}");
        assert!(build["profile"].as_str().is_some_and(|p| !p.is_empty()), "{build}");
        // Clean, or dirty with the 16 hex digits of the difference's hash.
        let dirty_hash = |d: &str| d.len() == 16 && d.bytes().all(|b| b.is_ascii_hexdigit());
        assert!(build["dirty"].is_null() || build["dirty"].as_str().is_some_and(dirty_hash), "{build}");
        assert!(json["date"].as_str().is_some_and(|d| d.starts_with("20") && d.ends_with('Z')), "{}", json["date"]);
        commits.insert(build["commit"].as_str().unwrap().to_owned());
        assert!(json["command"].as_str().is_some_and(|c| c.contains("experiment all")), "{}", json["command"]);
        assert_eq!(json["repeats"], 2);
        let series = json["series"].as_array().expect("series");
        assert!(!series.is_empty());
        for s in series {
            for point in s["points"].as_array().expect("points") {
                let time = &point["time"];
                // The analytic knob times each estimator over its own seeds, more than the repeats.
                if knob != "analytic" {
                    assert_eq!(time["runs"], 2, "{point}");
                }
                let (min, median, max) = (
                    time["min_ms"].as_f64().unwrap(),
                    time["median_ms"].as_f64().unwrap(),
                    time["max_ms"].as_f64().unwrap(),
                );
                assert!(min <= median && median <= max && min > 0.0, "{point}");
                // Rendered points split their error into bias and variance and give the efficiency.
                if let Some(error) = point["error"].as_object() {
                    for field in ["rmse", "relative_mse", "bias2", "variance", "bias_resolution"] {
                        assert!(error[field].as_f64().is_some_and(f64::is_finite), "{knob}: {field} in {point}");
                    }
                    assert_eq!(error["seeds"], 2, "{point}");
                    // Each seed's error is kept for the rank test, and each run's time.
                    assert_eq!(error["seed_mse"].as_array().map(Vec::len), Some(2), "{point}");
                    assert_eq!(time["runs_ms"].as_array().map(Vec::len), Some(2), "{point}");
                    // An efficiency only where the bias is not resolved.
                    let biased = point["values"]["biased"].as_f64().expect("whether it is biased");
                    let efficiency = point["values"]["efficiency"].as_f64();
                    if biased == 1.0 {
                        assert!(efficiency.is_none(), "{knob}: a biased point with an efficiency: {point}");
                    } else {
                        assert!(efficiency.is_some_and(|e| e > 0.0), "{knob}: {point}");
                    }
                }
            }
        }
        let plots = json["plots"].as_array().expect("plots");
        assert!(!plots.is_empty());
        for plot in plots {
            let file = plot["file"].as_str().expect("plot file name");
            assert!(plot["title"].as_str().is_some_and(|t| !t.is_empty()), "{plot}");
            assert!(md.contains(&format!("]({file})")), "{knob}.md does not show {file}");
            check_svg(&folder.join(file), &[]);
        }
    }
    assert_eq!(commits.len(), 1, "every report names the same commit: {commits:?}");
    // Against the furnace's exact radiance, no estimator shows a bias beyond 4 standard errors, and the
    // control clamped on purpose does.
    let analytic: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("analytic/analytic.json")).unwrap()).unwrap();
    for furnace in analytic["series"].as_array().unwrap() {
        for point in furnace["points"].as_array().unwrap() {
            let z = point["values"]["bias_in_standard_errors"].as_f64().unwrap();
            let control = point["label"].as_str().unwrap().starts_with("control");
            assert!(if control { z.abs() > 4.0 } else { z.abs() <= 4.0 }, "{}: {point}", furnace["name"]);
        }
    }
    // The robust traversal and the packets change no answer.
    for (knob, series) in [("traversal", "sah, robust"), ("packets", "bvh8, camera rays")] {
        let json: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(dir.join(knob).join(format!("{knob}.json"))).unwrap())
                .unwrap();
        let found = json["series"].as_array().unwrap().iter().find(|s| s["name"] == series).expect(series);
        for point in found["points"].as_array().unwrap() {
            assert_eq!(point["values"]["differing"], 0.0, "{knob}, {series}: {point}");
        }
    }
    // The equal-time panels: PNGs listed in the JSON, their captions among the findings.
    for (knob, panel) in [
        ("spp", "spp-equal-time.png"),
        ("depth", "depth-equal-time.png"),
        ("clamp", "clamp-equal-time.png"),
        ("filter-glossy", "filter-glossy-equal-time.png"),
        ("adaptive", "adaptive-equal-time.png"),
        ("direct", "direct-small-light-equal-time.png"),
    ] {
        let json: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(dir.join(knob).join(format!("{knob}.json"))).unwrap())
                .unwrap();
        assert!(json["panels"].as_array().unwrap().iter().any(|p| p["file"] == panel), "{knob}: {}", json["panels"]);
        assert!(json["findings"].to_string().contains(panel), "{knob}: no caption for {panel}");
        let png = image::open(dir.join(knob).join(panel)).unwrap_or_else(|e| panic!("{knob}/{panel}: {e}"));
        assert!(png.width() > png.height(), "{knob}/{panel}: a row of tiles");
        // And its labelled SVG: the PNG embedded, each column's label, the error scale; the report shows the SVG.
        let labelled = panel.replace(".png", ".svg");
        let svg = std::fs::read_to_string(dir.join(knob).join(&labelled)).unwrap();
        assert!(
            svg.contains("data:image/png;base64,") && svg.contains(">reference<") && svg.contains("RMSE "),
            "{labelled}"
        );
        let md = std::fs::read_to_string(dir.join(knob).join(format!("{knob}.md"))).unwrap();
        assert!(md.contains(&format!("]({labelled})")), "{knob}.md does not show {labelled}");
    }
    // Every knob has an error-against-time plot, the exact ones on log axes with their bound.
    for (knob, plot) in [
        ("scaling", "scaling-error-time.svg"),
        ("analytic", "analytic-error-time-1.svg"),
        ("accel", "accel-error-time.svg"),
        ("traversal", "traversal.svg"),
        ("packets", "packets.svg"),
    ] {
        check_svg(&dir.join(knob).join(plot), &[]);
    }
    check_svg(&dir.join("accel/accel-error-time.svg"), &["95% bound 3/N"]);
    // The direct knob's scenes have fronts of their own.
    for scene in ["small-light", "large-light", "glossy"] {
        check_svg(&dir.join(format!("pareto/direct-knob-{scene}.svg")), &["Pareto front", "direct ("]);
    }
    // The scene's Pareto plot, from every knob measured on it.
    check_svg(&dir.join("pareto/built-in-cornell-box.svg"), &["Pareto front", "spp (", "depth (", "clamp ("]);
    // The curves that the knobs promise.
    check_svg(
        &dir.join("spp/spp-error.svg"),
        &["uniform (slope", "stratified (slope", "low-discrepancy (slope", "spp^-1/2"],
    );
    check_svg(&dir.join("spp/spp-time.svg"), &["uniform", "stratified", "low-discrepancy"]);
    check_svg(&dir.join("depth/depth-energy.svg"), &["roulette on", "roulette off"]);
    check_svg(&dir.join("scaling/scaling.svg"), &["linear (n^", "sah (n^", "bvh8 (n^"]);
    check_svg(&dir.join("accel/accel-incoherent.svg"), &["linear", "sah", "bvh4", "bvh8"]);
    let intersectors = ["watertight", "moller-trumbore", "watertight-f64"];
    for plot in ["intersector-speed.svg", "intersector-self-hits.svg", "intersector-leaks.svg"] {
        check_svg(&dir.join("intersector").join(plot), &intersectors);
    }
    for plot in
        ["precision-far-t.svg", "precision-far-barycentrics.svg", "precision-sliver-t.svg", "precision-time.svg"]
    {
        check_svg(&dir.join("precision").join(plot), &intersectors);
    }

    for scene in ["small-light", "large-light", "glossy"] {
        check_svg(&dir.join(format!("direct/direct-{scene}.svg")), &["light", "bsdf", "mis", "reference noise"]);
    }
    check_svg(&dir.join("effects/effects.svg"), &["-emission", "-indirect", "+glossy", "+textures"]);

    // Sampling points on a small light beats sampling the BSDF towards it, at equal time, by far.
    let direct: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("direct/direct.json")).unwrap()).unwrap();
    let at_equal_time = |name: &str| {
        let series = direct["series"].as_array().unwrap().iter().find(|s| s["name"] == name).expect(name);
        let last = series["points"].as_array().unwrap().last().unwrap();
        last["values"]["rmse_at_equal_time"].as_f64().unwrap_or_else(|| panic!("{name}: {last}"))
    };
    let (light, bsdf) = (at_equal_time("small-light, light"), at_equal_time("small-light, bsdf"));
    assert!(light > 0.0 && light * 2.0 < bsdf, "small light: light sampling {light}, BSDF sampling {bsdf}");
    // Every strategy converges to the same image: the means agree with the MIS reference.
    for s in direct["series"].as_array().unwrap() {
        let last = s["points"].as_array().unwrap().last().unwrap();
        let (mean, reference) =
            (last["error"]["mean"].as_f64().unwrap(), last["error"]["reference_mean"].as_f64().unwrap());
        assert!((mean / reference - 1.0).abs() < 0.15, "{}: mean {mean} against {reference}", s["name"]);
    }

    // Effects: forcing on what the Cornell box does not call for changes no error (the same paths);
    // forcing off what it calls for shows.
    let effects: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("effects/effects.json")).unwrap()).unwrap();
    let points = effects["series"][0]["points"].as_array().unwrap();
    let value = |label: &str, name: &str| {
        let point = points.iter().find(|p| p["label"] == label).unwrap_or_else(|| panic!("no {label}"));
        point["values"][name].as_f64().unwrap_or_else(|| panic!("{label}: no {name}"))
    };
    let forced_on: Vec<&serde_json::Value> = points.iter().filter(|p| p["values"]["planned"] == 0.0).collect();
    assert!(forced_on.len() >= 4, "{forced_on:?}");
    for p in forced_on {
        let ratio = p["values"]["rmse_ratio"].as_f64().unwrap();
        assert!((ratio - 1.0).abs() < 1e-3, "{}: RMSE ×{ratio}", p["label"]);
    }
    assert!(value("-emission", "energy_ratio") < 0.05, "without emission the box is dark");
    assert!(value("-emission", "rmse_ratio") > 1.5);
    assert!(value("-indirect", "energy_ratio") < 0.9, "without bounces light is missing");
    // Without light sampling the emitter is still found by the BSDF's rays: no energy lost, more noise.
    assert!((value("-direct-light", "energy_ratio") - 1.0).abs() < 0.2);
    assert!(value("-direct-light", "rmse_ratio") > 1.2);

    // Errors are measured against a reference, with its noise.
    let spp: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("spp/spp.json")).unwrap()).unwrap();
    assert!(spp["reference"]["noise_rmse"].as_f64().is_some_and(|n| n > 0.0), "{}", spp["reference"]);
    // The reference is checked by an independent estimator, and no bias shows between them.
    let check = &spp["reference"]["check"];
    assert!(check["estimator"].as_str().is_some_and(|e| e.contains("uniform")), "{check}");
    let ratio = check["difference_rmse"].as_f64().unwrap() / check["expected_rmse"].as_f64().unwrap();
    assert!(ratio > 0.5 && ratio < 1.5, "reference and independent estimator differ by {ratio}× their noise: {check}");
    // Slopes are numbers with their standard errors and ranges.
    let fits = spp["fits"].as_array().expect("fits");
    assert!(fits.iter().any(|f| f["quantity"].as_str().is_some_and(|q| q.starts_with("RMSE against spp"))), "{fits:?}");
    for fit in fits {
        assert!(fit["law"]["exponent"].as_f64().is_some_and(|e| e < 0.0), "{fit}");
        assert!(fit["law"]["standard_error"].as_f64().is_some_and(|e| e >= 0.0), "{fit}");
        assert!(fit["law"]["x_min"].as_f64() < fit["law"]["x_max"].as_f64(), "{fit}");
    }
    // The clamp trades bias for variance: the harshest clamp loses energy and has less variance than no
    // clamp. (At 32², 4 spp and 2 seeds the per-pixel bias² is not resolved; the mean shows the bias.)
    let clamp: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("clamp/clamp.json")).unwrap()).unwrap();
    let clamp_points = clamp["series"][0]["points"].as_array().unwrap();
    let (none, harsh) = (&clamp_points[0]["error"], &clamp_points[1]["error"]);
    assert!(harsh["variance"].as_f64() < none["variance"].as_f64(), "{none} {harsh}");
    assert!(harsh["mean"].as_f64().unwrap() < 0.9 * harsh["reference_mean"].as_f64().unwrap(), "{harsh}");
    let first = &spp["series"][0]["points"][0]["error"];
    assert!(first["rmse"].as_f64().is_some_and(|e| e > 0.0) && first["relative_mse"].as_f64().is_some(), "{first}");
    // More samples, less error, for every sampler.
    for s in spp["series"].as_array().unwrap() {
        let errors: Vec<f64> =
            s["points"].as_array().unwrap().iter().map(|p| p["error"]["rmse"].as_f64().unwrap()).collect();
        assert!(errors.windows(2).all(|w| w[1] < w[0]), "{}: {errors:?}", s["name"]);
    }
    // No structure changes an answer.
    let accel: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("accel/accel.json")).unwrap()).unwrap();
    for s in accel["series"].as_array().unwrap() {
        let point = &s["points"][0]["values"];
        assert_eq!(point["camera_disagreements"], 0.0, "{}", s["name"]);
        assert_eq!(point["incoherent_disagreements"], 0.0, "{}", s["name"]);
    }
    // The watertight tests let no ray through a shared edge or out of a
    // closed mesh, nor hit the surface a spawned ray leaves, at any
    // distance; Möller-Trumbore loses some of the rays through shared edges.
    let intersector: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("intersector/intersector.json")).unwrap()).unwrap();
    let values = |name: &str| -> Vec<serde_json::Value> {
        let series = intersector["series"].as_array().unwrap().iter().find(|s| s["name"] == name);
        series.unwrap_or_else(|| panic!("no series {name}"))["points"]
            .as_array()
            .unwrap()
            .iter()
            .map(|p| p["values"].clone())
            .collect()
    };
    for name in ["watertight", "watertight-f64"] {
        let scene = &values(name)[0];
        assert!(scene["shared_edge_rays"].as_f64().unwrap() > 0.0, "{scene}");
        assert_eq!(scene["shared_edge_leaks"], 0.0, "{name}: {scene}");
        assert_eq!(scene["closed_mesh_leaks"], 0.0, "{name}: {scene}");
        let by_distance = values(&format!("{name} by distance"));
        assert!(by_distance.len() >= 3, "{name}: {by_distance:?}");
        for point in by_distance {
            assert!(point["secondary_rays"].as_f64().unwrap() > 0.0, "{point}");
            assert_eq!(point["self_hits"], 0.0, "{name}: {point}");
            assert!(point["escaping_rays"].as_f64().unwrap() > 0.0, "{point}");
            assert_eq!(point["escaped"], 0.0, "{name}: {point}");
        }
    }
    let moller = &values("moller-trumbore")[0];
    assert!(moller["shared_edge_leaks"].as_f64().unwrap() > 0.0, "{moller}");
    // Double precision is at least as close to the exact answer as single
    // precision far from the origin, and its barycentrics much closer at 2^24.
    let precision: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("precision/precision.json")).unwrap()).unwrap();
    let far = |name: &str, value: &str| -> Vec<(f64, f64)> {
        let series = precision["series"].as_array().unwrap().iter().find(|s| s["name"] == name).expect(name);
        series["points"]
            .as_array()
            .unwrap()
            .iter()
            .map(|p| (p["x"].as_f64().unwrap(), p["values"][value].as_f64().unwrap()))
            .collect()
    };
    let t_error = "t_relative_error_max";
    let (single, double) = (far("watertight far", t_error), far("watertight-f64 far", t_error));
    assert_eq!(single.len(), double.len());
    for ((x, e32), (_, e64)) in single.iter().zip(&double) {
        assert!(e64 <= e32, "at {x}: f64 error {e64} above f32 error {e32}");
        // Rounded to f32 at the end: within a little over half an ulp.
        assert!(*e64 <= 1.01 * 2f64.powi(-24), "at {x}: f64 error {e64}");
    }
    let barycentric_error = "barycentric_error_max";
    let (single, double) = (far("watertight far", barycentric_error), far("watertight-f64 far", barycentric_error));
    let (far_x, far_e32) = *single.last().unwrap();
    assert!(far_x >= 2f64.powi(24) && far_e32 > 100.0 * double.last().unwrap().1, "{single:?} {double:?}");

    // The second run reads the references from the cache.
    let again = rtgi(&[
        "experiment",
        "depth",
        "--quick",
        "--repeats",
        "1",
        "--out",
        path_str(&dir.join("again")),
        "--cache",
        path_str(&dir.join(".references")),
    ]);
    assert!(again.success, "{again:?}");
    assert!(!again.stderr.contains("rendering a reference"), "{}", again.stderr);
}

#[test]
fn unknown_knobs_and_unsuitable_subjects_are_refused_clearly() {
    let run = rtgi(&["experiment", "bounces", "--quick"]);
    assert!(!run.success);
    assert!(run.stderr.contains("spp") && run.stderr.contains("scaling"), "{}", run.stderr);
    let dir = scratch_dir("experiment-unsuitable");
    let run = rtgi(&["experiment", "depth", "--quick", "--integrator", "primary", "--out", path_str(&dir)]);
    assert!(!run.success);
    assert!(run.stderr.contains("needs the path integrator"), "{}", run.stderr);
    assert!(!run.stderr.contains("panicked"), "{}", run.stderr);
    assert!(!dir.join("depth.json").exists());
}

#[test]
fn all_writes_an_index_of_every_plot_with_its_findings() {
    let dir = scratch_dir("experiment-index");
    let run = rtgi(&["experiment", "all", "--quick", "--repeats", "1", "--out", path_str(&dir)]);
    assert!(run.success, "{run:?}");
    let index = std::fs::read_to_string(dir.join("index.md")).expect("index.md");
    assert!(index.contains("cargo run --release -p rtgi -- experiment all --quick"), "{index}");
    let mut plots = 0;
    for line in index.lines().filter(|l| l.starts_with("![")) {
        let file = line.rsplit_once("](").and_then(|(_, f)| f.strip_suffix(')')).expect("an image link");
        assert!(dir.join(file).is_file(), "index.md links {file}, which does not exist");
        plots += 1;
    }
    assert!(plots >= 8, "{index}");
    // Findings are sentences with measured figures, under their knob.
    assert!(index.contains("## `scaling`") && index.contains("time per ray ∝ n^"), "{index}");
}
