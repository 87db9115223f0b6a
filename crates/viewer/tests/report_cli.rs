//! `viewer report`: the JSON interface (its fields exactly), EN 12464-1's grid spacing and
//! point counts for the rooms tested (computed here from the formula), the task's
//! verdicts, the inter-reflections on and off, the files written (PNG, HTML) and the HTML
//! page opened in a real browser (headless Chromium: its screenshot must show the plan's
//! false colours and the tables), and bad input: exit 2, nothing written.

mod common;

use common::{s, tmpdir, viewer};
use std::path::Path;

fn louvre() -> String {
    test_support::test_data("ldt/office_louvre_2x28w.ldt")
        .to_str()
        .unwrap()
        .to_string()
}

/// Eight louvre luminaires in two rows of a 6 × 5 × 2.8 m room.
fn eight_lights() -> Vec<String> {
    eight_lights_in("6x5x2.8")
}

fn eight_lights_in(room: &str) -> Vec<String> {
    let mut a = vec!["--room".to_string(), room.into()];
    for x in [-2.25, -0.75, 0.75, 2.25] {
        for z in [-1.25, 1.25] {
            a.push("--light".into());
            a.push(format!("{}@{x},2.75,{z}", louvre()));
        }
    }
    a
}

fn run(args: &[String]) -> std::process::Output {
    let a: Vec<&str> = args.iter().map(|x| x.as_str()).collect();
    viewer(&a)
}

/// The EN 12464-1 grid of a `a × b` area, from the formula: (cells along a, along b,
/// spacing).
fn en_grid(a: f64, b: f64) -> (usize, usize, f64) {
    let d = a.max(b);
    let p = (0.2 * 5f64.powf(d.log10())).min(10.0);
    let n = (d / p).ceil() as usize;
    let cell = d / n as f64;
    let m = (a.min(b) / cell).ceil() as usize;
    if a >= b {
        (n, m, cell)
    } else {
        (m, n, cell)
    }
}

fn keys(v: &serde_json::Value) -> Vec<String> {
    let mut k: Vec<String> = v.as_object().unwrap().keys().cloned().collect();
    k.sort();
    k
}

#[test]
fn json_fields_grids_and_verdicts() {
    let dir = tmpdir("report", "json");
    let out = dir.join("r.json");
    let mut args = vec!["report".to_string()];
    args.extend(eight_lights());
    args.extend(["--json".into(), s(&out).into()]);
    let o = run(&args);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let v: serde_json::Value = serde_json::from_slice(&std::fs::read(&out).unwrap()).unwrap();
    for k in [
        "areas",
        "task",
        "luminaires",
        "reflectances",
        "indirect",
        "ugr",
    ] {
        assert!(v.get(k).is_some(), "{k} missing: {v}");
    }
    assert_eq!(v["indirect"], true);
    assert_eq!(
        v["reflectances"],
        serde_json::json!({"floor": 0.2, "walls": 0.5, "ceiling": 0.7})
    );
    let areas = v["areas"].as_array().unwrap();
    let names: Vec<&str> = areas.iter().map(|a| a["name"].as_str().unwrap()).collect();
    assert_eq!(
        names,
        [
            "work plane",
            "floor",
            "ceiling",
            "left wall",
            "right wall",
            "back wall",
            "front wall"
        ]
    );
    // Sizes: the work plane without the 0.5 m band, the faces whole.
    let sizes = [
        (5.0, 4.0),
        (6.0, 5.0),
        (6.0, 5.0),
        (5.0, 2.8),
        (5.0, 2.8),
        (6.0, 2.8),
        (6.0, 2.8),
    ];
    for (a, (w, d)) in areas.iter().zip(sizes) {
        let k = keys(a);
        for f in ["name", "area_m2", "grid", "em", "emin", "emax", "u0", "ud"] {
            assert!(k.contains(&f.to_string()), "{f} missing in {a}");
        }
        let (nu, nv, cell) = en_grid(w, d);
        assert_eq!(
            a["grid"]["points"].as_u64().unwrap() as usize,
            nu * nv,
            "{a}"
        );
        assert!(
            (a["grid"]["spacing_m"].as_f64().unwrap() - cell).abs() < 1e-9,
            "{a}"
        );
        assert!((a["area_m2"].as_f64().unwrap() - w * d).abs() < 1e-9, "{a}");
        let (em, emin, emax) = (
            a["em"].as_f64().unwrap(),
            a["emin"].as_f64().unwrap(),
            a["emax"].as_f64().unwrap(),
        );
        assert!(emin <= em && em <= emax && emin > 0.0, "{a}");
        assert!((a["u0"].as_f64().unwrap() - emin / em).abs() < 1e-12);
        assert!((a["ud"].as_f64().unwrap() - emin / emax).abs() < 1e-12);
    }
    // The task's verdict is what its requirements say of the figures.
    let t = &v["task"];
    assert_eq!(t["name"], "office-writing");
    assert_eq!(
        (t["em"].as_f64(), t["u0"].as_f64()),
        (Some(500.0), Some(0.6))
    );
    let wp = &areas[0];
    let wp_pass = wp["em"].as_f64().unwrap() >= 500.0 && wp["u0"].as_f64().unwrap() >= 0.6;
    assert_eq!(wp["pass"], wp_pass);
    let all = areas
        .iter()
        .all(|a| a.get("pass").is_none_or(|p| p == true));
    assert_eq!(t["pass"], all);
    // Luminaires: eight, the flux of the file (3879 lm: 74.6 % of 5200 lm), no nulls.
    let lum = v["luminaires"].as_array().unwrap();
    assert_eq!(lum.len(), 8);
    let f = lum[0]["flux_lm"].as_f64().unwrap();
    assert!((f - 3879.0).abs() < 0.005 * 3879.0, "{f}");
    assert!(!std::fs::read_to_string(&out).unwrap().contains("null"));
    // The text lists every area and the result.
    let text = String::from_utf8_lossy(&o.stdout);
    for n in names {
        assert!(text.contains(n), "{text}");
    }
    assert!(text.contains("result:"), "{text}");
}

#[test]
fn inter_reflections_raise_every_area() {
    let dir = tmpdir("report", "direct");
    let (a, b) = (dir.join("a.json"), dir.join("b.json"));
    let mut base = vec!["report".to_string()];
    base.extend(eight_lights());
    let mut with = base.clone();
    with.extend(["--json".into(), s(&a).into()]);
    let mut without = base;
    without.extend(["--json".into(), s(&b).into(), "--direct-only".into()]);
    assert!(run(&with).status.success());
    assert!(run(&without).status.success());
    let read = |p: &Path| -> serde_json::Value {
        serde_json::from_slice(&std::fs::read(p).unwrap()).unwrap()
    };
    let (va, vb) = (read(&a), read(&b));
    assert_eq!(vb["indirect"], false);
    for (x, y) in va["areas"]
        .as_array()
        .unwrap()
        .iter()
        .zip(vb["areas"].as_array().unwrap())
    {
        assert!(
            x["em"].as_f64().unwrap() > y["em"].as_f64().unwrap(),
            "{x} {y}"
        );
    }
    // With the direct light only there is no background luminance: no UGR value, a note.
    assert!(vb["ugr"].get("value").is_none() && vb["ugr"].get("note").is_some());
}

#[test]
fn bad_input_writes_nothing() {
    let dir = tmpdir("report", "bad");
    let out = dir.join("r.json");
    let html = dir.join("r.html");
    let outputs = [
        "--json".to_string(),
        s(&out).into(),
        "--html".into(),
        s(&html).into(),
    ];
    for (room, extra, want) in [
        ("6x5x2.8", vec!["--task", "knitting"], "office-writing"),
        (
            "6x5x2.8",
            vec!["--reflectances", "0.2,1,0.7"],
            "reflectance",
        ),
        ("6x5x2.8", vec!["--height", "3"], "height"),
        ("20000x20000x3", vec![], "limit"),
    ] {
        let mut a = vec!["report".to_string()];
        a.extend(eight_lights_in(room));
        a.extend(outputs.iter().cloned());
        a.extend(extra.iter().map(|x| x.to_string()));
        let o = run(&a);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{extra:?}: {err}");
        assert!(err.contains(want), "{extra:?}: {err}");
        assert!(!err.contains("panicked"));
        assert!(!out.exists() && !html.exists(), "{extra:?} wrote a file");
    }
}

/// The one line on stderr (besides clap's "For more information" hint), checked free of
/// panics.
fn one_line(o: &std::process::Output) -> String {
    let err = String::from_utf8_lossy(&o.stderr);
    let lines: Vec<&str> = err
        .lines()
        .filter(|l| !l.is_empty() && !l.starts_with("For more information"))
        .collect();
    assert_eq!(lines.len(), 1, "one line: {err}");
    assert!(!err.contains("panicked"), "{err}");
    lines[0].to_string()
}

/// The budgets `viewer report` is held to (`lut_core::limits`): more luminaires than
/// `MAX_LIGHTS` (200) on the command line or in a scene file, a room side past
/// `MAX_ROOM_SIDE` (100 m): one line naming the value and the limit, exit 2 (exit 1 when
/// the numbers come from a scene file), none of the three outputs written. One luminaire fewer, at the limit, is reported.
#[test]
fn past_the_limits_one_line_naming_the_limit_and_nothing_written() {
    let dir = tmpdir("report", "limits");
    let (json, png, html) = (dir.join("r.json"), dir.join("r.png"), dir.join("r.html"));
    let outputs: Vec<String> = vec![
        "--json".into(),
        s(&json).into(),
        "--png".into(),
        s(&png).into(),
        "--html".into(),
        s(&html).into(),
    ];
    let light = |i: usize| {
        // Spread over the ceiling of a 6 × 5 m room (the positions need not differ).
        let (x, z) = ((i % 20) as f64 * 0.25 - 2.4, (i / 20) as f64 * 0.4 - 2.0);
        format!("{}@{x},2.75,{z}", louvre())
    };
    let cli = |n: usize, room: &str| {
        let mut a = vec!["report".to_string(), "--room".into(), room.into()];
        for i in 0..n {
            a.push("--light".into());
            a.push(light(i));
        }
        a
    };
    let scene = |n: usize, room: [f64; 3]| {
        let lights: Vec<serde_json::Value> = (0..n)
            .map(|i| {
                let (x, z) = ((i % 20) as f64 * 0.25 - 2.4, (i / 20) as f64 * 0.4 - 2.0);
                serde_json::json!({"file": louvre(), "position": [x, 2.75, z]})
            })
            .collect();
        let v = serde_json::json!({
            "format": "lutpano-scene", "version": 1,
            "room": {"width": room[0], "depth": room[1], "height": room[2],
                     "camera_height": 1.5},
            "lights": lights,
            "exposure_lux": 300.0, "ambient": 0.15
        });
        let p = dir.join(format!("scene-{n}-{}.json", room[0]));
        std::fs::write(&p, serde_json::to_string(&v).unwrap()).unwrap();
        vec!["report".to_string(), "--scene".into(), s(&p).into()]
    };
    // Exit 2 for the command line, 1 for a file's content (the project's one rule,
    // docs/reliability.md).
    for (what, mut a, want, code) in [
        (
            "201 --light",
            cli(201, "6x5x2.8"),
            "luminaires 201 exceeds the limit of 200",
            2,
        ),
        (
            "a scene of 201 lights",
            scene(201, [6.0, 5.0, 2.8]),
            "luminaires 201 exceeds the limit of 200",
            1,
        ),
        (
            "a 101 m room",
            cli(1, "101x5x2.8"),
            "101 m exceeds the limit of 100 m",
            2,
        ),
        (
            "a scene's 101 m room",
            scene(1, [101.0, 5.0, 2.8]),
            "101 m exceeds the limit of 100 m",
            1,
        ),
    ] {
        a.extend(outputs.iter().cloned());
        let o = run(&a);
        let line = one_line(&o);
        assert_eq!(o.status.code(), Some(code), "{what}: {line}");
        assert!(line.contains(want), "{what}: {line}");
        for f in [&json, &png, &html] {
            assert!(!f.exists(), "{what} wrote {}", f.display());
        }
    }
    // At the limit: reported (the JSON alone, the direct light: the limit is checked,
    // not the cost of 200 lights' inter-reflections).
    let mut a = cli(200, "6x5x2.8");
    a.extend([
        "--direct-only".to_string(),
        "--json".into(),
        s(&json).into(),
    ]);
    let o = run(&a);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let v: serde_json::Value = serde_json::from_slice(&std::fs::read(&json).unwrap()).unwrap();
    assert_eq!(v["luminaires"].as_array().unwrap().len(), 200);
}

/// Chromium's executable, if installed.
fn chromium() -> Option<&'static str> {
    ["chromium", "chromium-browser", "google-chrome"]
        .into_iter()
        .find(|c| {
            std::process::Command::new(c)
                .arg("--version")
                .output()
                .is_ok_and(|o| o.status.success())
        })
}

#[test]
fn html_report_opens_in_a_browser() {
    let dir = tmpdir("report", "html");
    let (html, png) = (dir.join("report.html"), dir.join("report.png"));
    let mut args = vec!["report".to_string()];
    args.extend(eight_lights());
    args.extend([
        "--html".into(),
        s(&html).into(),
        "--png".into(),
        s(&png).into(),
        "--yaw".into(),
        "30".into(),
        "--pitch".into(),
        "10".into(),
    ]);
    let o = run(&args);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let page = std::fs::read_to_string(&html).unwrap();
    assert!(page.contains("data:image/png;base64,") && page.contains("<table id=\"areas\">"));
    assert!(!page.contains("src=\"http") && !page.contains("<script"));
    let img = image::open(&png).unwrap().to_rgb8();
    assert!(img.width() > 800 && img.height() > 300);
    let Some(browser) = chromium() else {
        eprintln!(
            "\n\n*** SKIPPED: html_report_opens_in_a_browser: Chromium is not installed \
             (scripts/test.sh installs it with apt-get when it can) ***\n\n"
        );
        return;
    };
    let shot = dir.join("shot.png");
    let profile = dir.join("profile");
    let o = std::process::Command::new(browser)
        .args([
            "--headless",
            "--no-sandbox",
            "--disable-gpu",
            "--no-first-run",
            "--disable-background-networking",
            "--disable-component-update",
            "--disable-sync",
            "--hide-scrollbars",
            &format!("--user-data-dir={}", s(&profile)),
            &format!("--screenshot={}", s(&shot)),
            "--window-size=1400,1600",
            &format!("file://{}", s(&html)),
        ])
        .output()
        .unwrap();
    assert!(
        shot.exists(),
        "no screenshot: {}",
        String::from_utf8_lossy(&o.stderr)
    );
    let shot = image::open(&shot).unwrap().to_rgb8();
    // The plan's false colours (saturated pixels), the tables' text and borders (dark
    // pixels) and the white page are all there.
    let (mut vivid, mut dark, mut white) = (0usize, 0usize, 0usize);
    for p in shot.pixels() {
        let (mx, mn) = (*p.0.iter().max().unwrap(), *p.0.iter().min().unwrap());
        if mx - mn > 120 {
            vivid += 1;
        }
        if mx < 80 {
            dark += 1;
        }
        if mn > 245 {
            white += 1;
        }
    }
    let n = (shot.width() * shot.height()) as usize;
    assert!(vivid > n / 50, "the plan's colours: {vivid} of {n} pixels");
    assert!(dark > n / 500, "the text and tables: {dark} of {n} pixels");
    assert!(
        white > n / 5,
        "a page, not a blank or black image: {white} of {n}"
    );
}
