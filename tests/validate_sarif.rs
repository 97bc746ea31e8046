//! `bumpbake validate --format sarif` beyond what every validate test already checks (the log
//! passes the SARIF 2.1.0 schema and carries the JSON report's findings, see
//! `validate_support::validate`): the rules table, unusable inputs, relative paths, levels.

mod common;
mod validate_support;
use common::*;
use serde_json::Value;
use validate_support::*;

fn flipped(dir: &std::path::Path) -> std::path::PathBuf {
    let mut p = grid_prim();
    p.tan = Some(vec![[1.0, 0.0, 0.0, -1.0]; p.pos.len()]);
    write_prim(dir, "flipped", &p, true)
}

#[test]
fn the_schema_rejects_what_sarif_forbids() {
    // The validator is live: a log the command wrote passes, the same log with a level SARIF does
    // not have, or without its version, fails.
    let d = scratch_dir("sarif_schema_live");
    let (_, mut log) = validate_as("sarif", &[s(&flipped(&d))]);
    assert!(sarif_schema().is_valid(&log));
    log["runs"][0]["results"][0]["level"] = "info".into();
    assert!(!sarif_schema().is_valid(&log));
    log["runs"][0]["results"][0]["level"] = "error".into();
    log.as_object_mut().unwrap().remove("version");
    assert!(!sarif_schema().is_valid(&log));
}

#[test]
fn rules_describe_every_check_code() {
    let d = scratch_dir("sarif_rules");
    let (_, log) = validate_as("sarif", &[s(&flipped(&d))]);
    let driver = &log["runs"][0]["tool"]["driver"];
    assert_eq!(driver["name"], "bumpbake");
    let codes = run_ok(&["validate", "--list-codes"]);
    let listed: Vec<(String, String)> = String::from_utf8_lossy(&codes.stdout)
        .lines()
        .map(|l| {
            let mut w = l.split_whitespace();
            (w.next().unwrap().to_string(), w.next().unwrap().to_string())
        })
        .collect();
    let rules = driver["rules"].as_array().unwrap();
    assert_eq!(rules.len(), listed.len());
    for (rule, (code, severity)) in rules.iter().zip(&listed) {
        assert_eq!(rule["id"], code.as_str());
        assert_eq!(rule["defaultConfiguration"]["level"], sarif_level(severity));
        assert!(rule["shortDescription"]["text"].as_str().unwrap().len() > 20, "{rule}");
        assert!(!rule["help"]["text"].as_str().unwrap().is_empty(), "{rule}");
    }
}

#[test]
fn levels_follow_deny_allow_and_strict_sets_the_exit_code() {
    let d = scratch_dir("sarif_levels");
    let path = flipped(&d);
    let (code, log) = validate_as("sarif", &[s(&path), "--allow", "TANGENT_W_MISMATCH_UV"]);
    let res = &log["runs"][0]["results"][0];
    assert_eq!((code, res["level"].as_str(), res["properties"]["fails"].as_bool()), (0, Some("note"), Some(false)));
    assert_eq!(log["runs"][0]["invocations"][0]["exitCode"], 0);
    // A warning stays a warning under --strict; it fails the run.
    let mut p = grid_prim();
    p.tan = None;
    let missing = write_prim(&d, "missing", &p, true);
    let (code, log) = validate_as("sarif", &[s(&missing), "--strict"]);
    let res = &log["runs"][0]["results"][0];
    assert_eq!((code, res["ruleId"].as_str(), res["level"].as_str()), (1, Some("TANGENT_MISSING"), Some("warning")));
    assert_eq!(res["properties"]["fails"], true);
    assert_eq!(log["runs"][0]["invocations"][0]["exitCode"], 1);
    assert_sarif_valid(&log);
}

#[test]
fn unusable_inputs_are_notifications_and_images_have_no_logical_location() {
    let d = scratch_dir("sarif_unusable");
    let path = flipped(&d);
    let garbage = d.join("garbage.glb");
    std::fs::write(&garbage, b"glTF\x02\0\0\0").unwrap();
    let img = d.join("flat.png");
    image::RgbImage::from_pixel(16, 16, image::Rgb([128, 128, 255])).save(&img).unwrap();
    let (code, log) = validate_as("sarif", &[s(&path), s(&garbage), s(&img)]);
    assert_eq!(code, 2);
    assert_sarif_valid(&log);
    let inv = &log["runs"][0]["invocations"][0];
    assert_eq!((inv["executionSuccessful"].as_bool(), inv["exitCode"].as_u64()), (Some(false), Some(2)));
    let notes = inv["toolExecutionNotifications"].as_array().unwrap();
    assert_eq!(notes.len(), 1);
    assert_eq!(notes[0]["level"], "error");
    assert!(notes[0]["message"]["text"].as_str().unwrap().contains("garbage.glb"), "{inv:#}");
    let results = log["runs"][0]["results"].as_array().unwrap();
    let ids: Vec<&str> = results.iter().map(|r| r["ruleId"].as_str().unwrap()).collect();
    assert_eq!(ids, ["TANGENT_W_MISMATCH_UV", "NORMALMAP_FLAT"]);
    let logical = |r: &Value| r["locations"][0].get("logicalLocations").cloned();
    assert_eq!(logical(&results[0]).unwrap()[0]["fullyQualifiedName"], "meshes/0/primitives/0");
    assert_eq!(logical(&results[1]), None, "an image given directly is the whole file");
    assert_eq!(log["runs"][0]["artifacts"].as_array().unwrap().len(), 2);
}

#[test]
fn relative_paths_stay_relative_uris() {
    let d = scratch_dir("sarif relative");
    flipped(&d);
    let out = bin().current_dir(&d).args(["validate", "--format", "sarif", "-q", "flipped.glb"]).output().unwrap();
    assert_eq!(out.status.code(), Some(1));
    let log: Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_sarif_valid(&log);
    let loc = &log["runs"][0]["results"][0]["locations"][0]["physicalLocation"]["artifactLocation"];
    assert_eq!(loc["uri"], "flipped.glb");
    // A space in an absolute path is escaped.
    let (_, log) = validate_as("sarif", &[s(&d.join("flipped.glb"))]);
    let uri = log["runs"][0]["artifacts"][0]["location"]["uri"].as_str().unwrap();
    assert!(uri.starts_with("file:///") && uri.ends_with("/sarif%20relative/flipped.glb"), "{uri}");
}
