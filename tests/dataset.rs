//! `forkbench dataset` end to end: a labelled set written deterministically (bag, labels, NumPy), scored by `detect --labels` with the curve and the clutter table, and bad specs refused naming the field.

use crate::common::{forkbench, s, text, tmp_in};

fn json(o: &std::process::Output) -> serde_json::Value {
    serde_json::from_slice(&o.stdout).unwrap_or_else(|e| panic!("{e}: {}", text(o)))
}

#[test]
fn a_set_is_written_by_seed_and_scored_with_its_labels() {
    let dir = tmp_in("dataset-e2e", "set");
    let twin = tmp_in("dataset-e2e", "twin");
    for d in [&dir, &twin] {
        let o = forkbench(&[
            "dataset",
            "--out",
            s(d),
            "--scans",
            "400",
            "--seed",
            "5",
            "--npy",
        ]);
        assert!(o.status.success(), "{}", text(&o));
    }
    for f in ["scans.mcap", "labels.json", "scans.npy", "labels.npy"] {
        let (a, b) = (
            std::fs::read(dir.join(f)).expect("written"),
            std::fs::read(twin.join(f)).expect("written"),
        );
        assert!(a == b, "{f} differs between two runs of one seed");
    }
    let npy = std::fs::read(dir.join("scans.npy")).expect("npy");
    let header = String::from_utf8_lossy(&npy[10..128]);
    assert!(header.contains("'shape': (400, 819)"), "{header}");
    assert_eq!((npy.len() - 128) % 4, 0);
    let labels: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.join("labels.json")).expect("labels"))
            .expect("json");
    let scans = labels["scans"].as_array().expect("scans");
    assert_eq!(scans.len(), 400);
    let present = scans.iter().filter(|l| l["present"] == true).count();
    assert!(
        (140..=260).contains(&present),
        "{present} of 400 with a pallet"
    );
    // The detector on its own labels: few false detections at the default threshold, the
    // clear faces found, and the curve and the clutter table given.
    let o = forkbench(&[
        "detect",
        s(&dir.join("scans.mcap")),
        "--labels",
        s(&dir.join("labels.json")),
        "--json",
    ]);
    assert!(o.status.success(), "{}", text(&o));
    let v = json(&o);
    assert_eq!(
        v["label_warnings"],
        serde_json::json!([]),
        "its own labels fit"
    );
    // Every wrong scan is listed with its label; a detection off its face is both a
    // false detection and a miss in the scores, so the list accounts for their errors.
    let sc = &v["scores"];
    let errors: u64 = ["false_positives", "false_negatives"]
        .iter()
        .map(|k| sc[k].as_u64().expect("count"))
        .sum();
    let wrong = v["wrong_scans"].as_array().expect("wrong scans");
    let far = wrong.iter().filter(|w| w["why"] == "off the face").count();
    assert_eq!(v["wrong_total"].as_u64(), Some(wrong.len() as u64));
    assert_eq!((wrong.len() + far) as u64, errors, "{sc}");
    for w in wrong {
        let i = w["index"].as_u64().expect("index") as usize;
        let face = labels["scans"][i].get("face").cloned().unwrap_or_default();
        assert_eq!(w["label"], face, "{w}");
    }
    assert!(sc["precision"].as_f64().expect("p") >= 0.95, "{sc}");
    assert!(sc["recall"].as_f64().expect("r") >= 0.75, "{sc}");
    let at = v["curve"]
        .as_array()
        .expect("curve")
        .iter()
        .find(|p| (p["threshold"].as_f64().expect("t") - 0.85).abs() < 1e-9)
        .expect("the default threshold on the curve");
    assert!(
        at["false_positive_rate"].as_f64().expect("fpr") <= 0.03,
        "{at}"
    );
    let kinds: Vec<&str> = v["by_clutter"]
        .as_array()
        .expect("by clutter")
        .iter()
        .map(|k| k["kind"].as_str().expect("kind"))
        .collect();
    assert!(
        kinds.contains(&"upright") && kinds.contains(&"person"),
        "{kinds:?}"
    );
    // Without the evidence every located face counts: far more false detections.
    let o = forkbench(&[
        "detect",
        s(&dir.join("scans.mcap")),
        "--labels",
        s(&dir.join("labels.json")),
        "--min-score",
        "0",
        "--json",
    ]);
    let loose = json(&o)["scores"]["false_positives"].as_u64().expect("fp");
    assert!(
        loose > 3 * sc["false_positives"].as_u64().expect("fp").max(1),
        "{loose}"
    );
    let other = tmp_in("dataset-e2e", "other");
    let o = forkbench(&[
        "dataset",
        "--out",
        s(&other),
        "--scans",
        "400",
        "--seed",
        "6",
    ]);
    assert!(o.status.success(), "{}", text(&o));
    assert!(
        std::fs::read(other.join("labels.json")).expect("labels")
            != std::fs::read(dir.join("labels.json")).expect("labels")
    );
}

#[test]
fn bad_specs_and_outputs_are_refused_naming_why() {
    let spec = tmp_in("dataset-bad", "spec.toml");
    let out = tmp_in("dataset-bad", "out");
    for (body, says) in [
        ("scans = 0\n", "scans"),
        ("[clutter]\nkinds = [\"ghost\"]\n", "clutter.kinds"),
        ("range_m = [5.0, 2.0]\n", "range_m"),
        ("colour = 1\n", "colour"),
        ("present_fraction = 1.5\n", "present_fraction"),
        ("prior_error_m = -0.1\n", "prior_error_m"),
        ("prior_error_deg = 90\n", "prior_error_deg"),
        ("scanner = \"velodyne\"\n", "velodyne"),
    ] {
        std::fs::write(&spec, body).expect("spec");
        let o = forkbench(&["dataset", s(&spec), "--out", s(&out)]);
        assert_eq!(o.status.code(), Some(1), "{body}: {}", text(&o));
        assert!(text(&o).contains(says), "{body}: {}", text(&o));
        assert!(
            text(&o).contains("spec.toml") || says == "velodyne",
            "{}",
            text(&o)
        );
    }
    let file = tmp_in("dataset-bad", "a-file");
    std::fs::write(&file, "mine").expect("file");
    let o = forkbench(&["dataset", "--out", s(&file), "--scans", "10"]);
    assert_eq!(o.status.code(), Some(1), "{}", text(&o));
    assert!(text(&o).contains("not a directory"), "{}", text(&o));
    assert_eq!(std::fs::read_to_string(&file).expect("kept"), "mine");
}

#[test]
fn a_trials_min_score_acts_and_is_range_checked() {
    let base =
        std::fs::read_to_string(crate::common::repo_root().join("scenarios/field-test.toml"))
            .expect("field test");
    let with = |extra: &str| {
        let f = tmp_in("dataset-trial", &format!("f{}.toml", extra.len()));
        let text = base.replace(
            "kind = \"tim561+kinect2\"",
            &format!("kind = \"tim561+kinect2\"\n{extra}"),
        );
        assert_ne!(text, base);
        std::fs::write(&f, text).expect("scenario");
        f
    };
    // The check chooses another face among the detector's than its own first one, which
    // the default (0) takes: the estimate the replanning pick ends on moves.
    let est = |f: &std::path::Path| {
        let v = json(&forkbench(&["trial", s(f), "--replan", "--json"]));
        assert_eq!(v["estimates_missed"], 0, "{v}");
        v["estimate_lateral_error_m"].as_f64().expect("estimate")
    };
    let strict = with("min_score = 1.0");
    let base_file = with("min_score = 0");
    assert!((est(&strict) - est(&base_file)).abs() > 1e-4);
    let o = forkbench(&["check", s(&with("min_score = 0.85"))]);
    assert!(o.status.success(), "{}", text(&o));
    assert!(text(&o).contains("evidence ≥ 0.85"), "{}", text(&o));
    let o = forkbench(&["check", s(&with("min_score = 1.5"))]);
    assert_eq!(o.status.code(), Some(1), "{}", text(&o));
    assert!(
        text(&o).contains("sensors.pallet.min_score"),
        "{}",
        text(&o)
    );
}

#[test]
fn a_worlds_clutter_is_seen_and_checked() {
    let root = crate::common::repo_root();
    let base = std::fs::read_to_string(root.join("scenarios/field-test.toml")).expect("field test");
    let scenario = tmp_in("dataset-clutter", "field.toml");
    let world = tmp_in("dataset-clutter", "clutter.toml");
    std::fs::write(&scenario, format!("world = \"clutter.toml\"\n{base}")).expect("scenario");
    let run = |clutter: &str| {
        std::fs::write(&world, format!("name = \"clutter\"\n{clutter}")).expect("world");
        forkbench(&["trial", s(&scenario), "--json"])
    };
    // A person and a box off the way: the pick is as without them.
    let aside = "[[clutter]]\nkind = \"person\"\nx_m = -2.0\ny_m = 9.0\n\
                 [[clutter]]\nkind = \"box\"\nx_m = 4.0\ny_m = 10.0\nheading_deg = 30.0\n";
    let o = run(aside);
    assert_eq!(json(&o)["success"], true, "{}", text(&o));
    let o = forkbench(&["check", s(&scenario)]);
    assert!(text(&o).contains("2 clutter items"), "{}", text(&o));
    // A wall 1.5 m before the pallet's face hides it from the truck.
    let hiding = "[[clutter]]\nkind = \"wall\"\nx_m = 2.165\ny_m = 13.455\nheading_deg = 192.8\n";
    let v = json(&run(hiding));
    assert_eq!(v["success"], false, "{v}");
    for (bad, says) in [
        (
            "[[clutter]]\nkind = \"ghost\"\nx_m = 0.0\ny_m = 0.0\n",
            "clutter[0].kind",
        ),
        (
            "[[clutter]]\nkind = \"person\"\nx_m = 0.0\ny_m = 0.0\nlength_m = 2.0\n",
            "clutter[0].length_m",
        ),
        (
            "[[clutter]]\nkind = \"box\"\nx_m = 1e300\ny_m = 0.0\n",
            "clutter[0].x_m",
        ),
    ] {
        let o = run(bad);
        assert_eq!(o.status.code(), Some(1), "{bad}: {}", text(&o));
        assert!(text(&o).contains(says), "{bad}: {}", text(&o));
    }
}

/// A folder is the set's: a folder with files but no set of forkbench's is refused, its
/// files kept; a rerun into a set's folder replaces the set, and one that would leave the
/// earlier set's arrays beside new labels is refused; nothing is left half-written.
#[test]
fn a_folder_holds_one_whole_set() {
    let mine = tmp_in("dataset-folder", "mine");
    std::fs::create_dir_all(&mine).expect("dir");
    std::fs::write(mine.join("labels.json"), "my labels").expect("mine");
    let o = forkbench(&["dataset", "--out", s(&mine), "--scans", "10"]);
    assert_eq!(o.status.code(), Some(1), "{}", text(&o));
    assert!(
        text(&o).contains("no dataset forkbench wrote"),
        "{}",
        text(&o)
    );
    assert_eq!(
        std::fs::read_to_string(mine.join("labels.json")).expect("kept"),
        "my labels"
    );
    let set = tmp_in("dataset-folder", "set");
    let _ = std::fs::remove_dir_all(&set);
    let run = |extra: &[&str]| {
        let mut args = vec!["dataset", "--out", s(&set), "--scans", "20"];
        args.extend_from_slice(extra);
        forkbench(&args)
    };
    assert!(run(&["--npy", "--seed", "1"]).status.success());
    let npy = std::fs::read(set.join("scans.npy")).expect("npy");
    let o = run(&["--seed", "2"]);
    assert_eq!(o.status.code(), Some(1), "{}", text(&o));
    assert!(
        text(&o).contains("scans.npy and labels.npy of an earlier set"),
        "{}",
        text(&o)
    );
    assert_eq!(std::fs::read(set.join("scans.npy")).expect("kept"), npy);
    let o = run(&["--npy", "--seed", "2"]);
    assert!(o.status.success(), "{}", text(&o));
    assert_ne!(std::fs::read(set.join("scans.npy")).expect("replaced"), npy);
    let labels: serde_json::Value =
        serde_json::from_slice(&std::fs::read(set.join("labels.json")).expect("labels"))
            .expect("the streamed labels are JSON");
    assert_eq!(labels["scans"].as_array().expect("scans").len(), 20);
    assert_eq!(labels["dataset"]["seed"], 2);
    assert_eq!(
        crate::common::names_in(&set),
        [
            "labels.json",
            "labels.npy",
            "metadata.yaml",
            "scans.mcap",
            "scans.npy"
        ]
    );
    // The folder is a rosbag2 directory: its metadata names the bag and the scan count.
    let meta = std::fs::read_to_string(set.join("metadata.yaml")).expect("metadata");
    for part in [
        "storage_identifier: mcap",
        "- scans.mcap",
        "type: sensor_msgs/msg/LaserScan",
        "message_count: 20",
    ] {
        assert!(meta.contains(part), "{part} missing from\n{meta}");
    }
}

/// A label says "present" only for a pallet the scanner can see: with a short, narrow
/// scanner the faces are drawn within its reach and view (and the note says so); a spec
/// whose ranges lie wholly outside it is refused naming the field.
#[test]
fn present_means_in_the_scanners_view() {
    let dir = tmp_in("dataset-view", "set");
    let _ = std::fs::remove_dir_all(&dir);
    let spec = tmp_in("dataset-view", "kinect.toml");
    std::fs::write(&spec, "scanner = \"kinect2\"\nscans = 200\n").expect("spec");
    let o = forkbench(&["dataset", s(&spec), "--out", s(&dir)]);
    assert!(o.status.success(), "{}", text(&o));
    assert!(text(&o).contains("faces drawn only where"), "{}", text(&o));
    let labels: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.join("labels.json")).expect("labels"))
            .expect("json");
    let mut present = 0;
    for l in labels["scans"].as_array().expect("scans") {
        if l["present"] == true {
            present += 1;
            let (x, y) = (
                l["face"]["x_m"].as_f64().expect("x"),
                l["face"]["y_m"].as_f64().expect("y"),
            );
            assert!(x.hypot(y) <= 4.5, "{l}");
            assert!(y.atan2(x).to_degrees().abs() <= 35.0, "{l}");
        }
    }
    assert!(present > 50, "{present}");
    std::fs::write(&spec, "scanner = \"kinect2\"\nrange_m = [6.0, 8.0]\n").expect("spec");
    let o = forkbench(&[
        "dataset",
        s(&spec),
        "--out",
        s(&tmp_in("dataset-view", "none")),
    ]);
    assert_eq!(o.status.code(), Some(1), "{}", text(&o));
    assert!(
        text(&o).contains("range_m") && text(&o).contains("reach"),
        "{}",
        text(&o)
    );
}

#[test]
fn labels_the_scores_cannot_use_are_warned_of() {
    let dir = tmp_in("dataset-labels", "set");
    let o = forkbench(&["dataset", "--out", s(&dir), "--scans", "40", "--seed", "3"]);
    assert!(o.status.success(), "{}", text(&o));
    let mut labels: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.join("labels.json")).expect("labels"))
            .expect("json");
    let scans = labels["scans"].as_array_mut().expect("scans");
    let k = scans
        .iter()
        .position(|l| l["present"] == true)
        .expect("a pallet in 40 scans");
    scans[k].as_object_mut().expect("label").remove("face");
    scans.push(serde_json::json!({"index": 40, "present": false}));
    let edited = dir.with_file_name("edited.json");
    std::fs::write(&edited, labels.to_string()).expect("write");
    let o = forkbench(&[
        "detect",
        s(&dir.join("scans.mcap")),
        "--labels",
        s(&edited),
        "--json",
    ]);
    assert!(o.status.success(), "{}", text(&o));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        err.contains("warning: 1 labels name scans the bag does not have (it has 40; scans 40)"),
        "{err}"
    );
    assert!(
        err.contains(&format!("without its face (scans {k})")),
        "{err}"
    );
    assert_eq!(
        json(&o)["label_warnings"]
            .as_array()
            .expect("warnings")
            .len(),
        2
    );
    let _ = std::fs::remove_dir_all(dir.parent().expect("folder"));
}

/// Each scan's label carries the prior the set was drawn with (near the face, or where a
/// pallet would stand), and `detect --labels` hands it to the detector: the RANSAC
/// example, which fits best near its prior, finds many more faces with the labels' priors
/// than without; `--prior` beside them is refused.
#[test]
fn a_sets_priors_reach_the_detector() {
    let dir = tmp_in("dataset-prior", "set");
    let o = forkbench(&["dataset", "--out", s(&dir), "--scans", "60", "--seed", "2"]);
    assert!(o.status.success(), "{}", text(&o));
    let labels: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.join("labels.json")).expect("labels"))
            .expect("json");
    let mut bare = labels.clone();
    for l in labels["scans"].as_array().expect("scans") {
        let p = &l["prior"];
        assert!(p["x_m"].is_f64() && p["heading_deg"].is_f64(), "{l}");
        if l["present"] == true {
            let off = (p["x_m"].as_f64().expect("x") - l["face"]["x_m"].as_f64().expect("x"))
                .hypot(p["y_m"].as_f64().expect("y") - l["face"]["y_m"].as_f64().expect("y"));
            assert!(off < 0.6, "a prior 6 σ off its face: {l}");
        }
    }
    for l in bare["scans"].as_array_mut().expect("scans") {
        l.as_object_mut().expect("object").remove("prior");
    }
    let bare_file = dir.join("bare.json");
    std::fs::write(&bare_file, bare.to_string()).expect("write");
    let components = dir.join("components.toml");
    let ransac =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/detectors/ransac.py");
    std::fs::write(
        &components,
        format!(
            "[[detector]]\nname = \"ransac\"\nkind = \"external\"\ncommand = [\"python3\", {:?}]\ntimeout_s = 10.0\n",
            ransac.display().to_string()
        ),
    )
    .expect("components");
    let recall = |labels: &std::path::Path| {
        let o = forkbench(&[
            "detect",
            s(&dir.join("scans.mcap")),
            "--labels",
            s(labels),
            "--components",
            s(&components),
            "--detector",
            "ransac",
            "--json",
        ]);
        assert!(o.status.success(), "{}", text(&o));
        json(&o)["scores"]["recall"].as_f64().expect("recall")
    };
    let (with, without) = (recall(&dir.join("labels.json")), recall(&bare_file));
    assert!(
        with > 0.3 && without < 0.1,
        "recall {with} with priors, {without} without"
    );
    let o = forkbench(&[
        "detect",
        s(&dir.join("scans.mcap")),
        "--labels",
        s(&dir.join("labels.json")),
        "--prior",
        "5,0,180",
    ]);
    assert_eq!(o.status.code(), Some(1), "{}", text(&o));
    assert!(text(&o).contains("each scan its own"), "{}", text(&o));
}
