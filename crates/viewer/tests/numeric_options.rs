//! Every numeric option of every command fed the extremes (issue 32, class 1 and 6): 0,
//! −0, denormals, ±1e308, ±inf, NaN, 2^63 and a 400-digit number, in each place of the
//! option's value, must end with exit 0, 1 or 2 (never 101, 134 or a signal), finite
//! JSON, one line on stderr, within 20 s. A property test (proptest) with a few cases per
//! option, so the run stays short; every option that takes a value in `--help` must be
//! listed here (as numeric with its templates, or as not numeric), so an option added
//! later is not left out silently.

mod common;

use common::{s, tmpdir};
use proptest::prelude::*;
use proptest::test_runner::{Config, TestRunner};
use std::io::Read;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

/// The extremes, as typed.
fn extremes() -> Vec<String> {
    vec![
        "0".into(),
        "-0".into(),
        "5e-324".into(),
        "2.2250738585072014e-308".into(),
        "1e308".into(),
        "-1e308".into(),
        "inf".into(),
        "-inf".into(),
        "NaN".into(),
        "9223372036854775808".into(),
        "18446744073709551616".into(),
        format!("1{}", "0".repeat(400)),
        format!("0.{}1", "0".repeat(400)),
    ]
}

/// Options that take a value that is not a number (files, names, choices).
const NOT_NUMERIC: &[&str] = &[
    "--output",
    "--scene",
    "--projection",
    "--layout",
    "--naming",
    "--cube-renderer",
    "--view-projection",
    "--renderer",
    "--sampler",
    "--step",
    "--lut",
    "--surface",
    "--light-interpolation",
    "--to",
    "--views",
    "--kernel",
    "--plot",
    "--json-out",
    "--peers",
    "--report",
    "--only",
    "--compare",
    "--error-map",
    "--index-step",
    "--lut-surface",
    "--tour",
    "--task",
    "--json",
    "--png",
    "--html",
];

/// One command and its cheap base arguments (`{iso}`, `{png}`, `{out}` replaced).
struct Cmd {
    name: &'static str,
    base: &'static [&'static str],
    /// Numeric options: the option and its value templates (`{}` is the extreme).
    options: &'static [(&'static str, &'static [&'static str])],
}

const LIGHT_OPTS: &[(&str, &[&str])] = &[
    (
        "--light",
        &[
            "{iso}@{},2,0",
            "{iso}@0,{},0",
            "{iso}@0,2,0:{},-90",
            "{iso}@0,2,0:0,{}",
        ],
    ),
    ("--room", &["{}x5x3", "5x{}x3", "5x5x{}"]),
    ("--camera-height", &["{}"]),
    ("--room-yaw", &["{}"]),
    ("--room-center", &["{},0", "0,{}"]),
    ("--light-multiplier", &["{}"]),
    (
        "--reflectances",
        &["{},0.5,0.7", "0.2,{},0.7", "0.2,0.5,{}"],
    ),
];

const RENDER_OPTS: &[(&str, &[&str])] = &[
    ("--yaw", &["{}"]),
    ("--pitch", &["{}"]),
    ("--hfov", &["{}"]),
    ("--pannini-d", &["{}"]),
    ("--size", &["{}x32", "64x{}"]),
    ("--exposure", &["{}"]),
    ("--max-pixels", &["{}"]),
    (
        "--coverage",
        &["{}x60", "90x{}", "90x60+{}+0", "90x60+0+{}"],
    ),
    ("--exposure-lux", &["{}"]),
    ("--ambient", &["{}"]),
    ("--false-color-max", &["{}"]),
    ("--cache-mib", &["{}"]),
    ("--horizon-pitch", &["{}"]),
    ("--horizon-roll", &["{}"]),
];

fn commands() -> Vec<Cmd> {
    vec![
        Cmd {
            name: "render",
            base: &["render", "{png}", "-o", "/dev/null", "--size", "64x32"],
            options: RENDER_OPTS,
        },
        Cmd {
            name: "render",
            base: &[
                "render",
                "{png}",
                "-o",
                "/dev/null",
                "--size",
                "64x32",
                "--light",
                "{iso}@0,2,0",
            ],
            options: LIGHT_OPTS,
        },
        Cmd {
            name: "lux",
            base: &["lux", "--json", "--light", "{iso}@0,2,0", "--at", "0,0,0"],
            options: LIGHT_OPTS,
        },
        Cmd {
            name: "lux",
            base: &["lux", "--json", "--light", "{iso}@0,2,0"],
            options: &[(
                "--at",
                &[
                    "{},0,0",
                    "0,{},0",
                    "0,0,{}",
                    "0,1,0:{},0,0",
                    "0,1,0:0,{},0",
                    "0,1,0:1,1,{}",
                ],
            )],
        },
        Cmd {
            name: "convert",
            base: &["convert", "{png}", "{out}", "--to", "cube"],
            options: &[
                ("--face-size", &["{}"]),
                ("--size", &["{}x16", "32x{}"]),
                ("--max-pixels", &["{}"]),
            ],
        },
        Cmd {
            name: "ies",
            base: &["ies", "--json", "{iso}"],
            options: &[("--sample", &["{},0", "0,{}"])],
        },
        Cmd {
            name: "report",
            base: &[
                "report",
                "--room",
                "5x5x3",
                "--light",
                "{iso}@0,2,0",
                "--json",
                "{json}",
            ],
            options: LIGHT_OPTS,
        },
        Cmd {
            name: "report",
            base: &[
                "report",
                "--room",
                "5x5x3",
                "--light",
                "{iso}@0,2,0",
                "--json",
                "{json}",
            ],
            options: &[
                ("--height", &["{}"]),
                ("--yaw", &["{}"]),
                ("--pitch", &["{}"]),
                ("--hfov", &["{}"]),
            ],
        },
        Cmd {
            name: "tile",
            base: &["tile", "--synthetic", "64x32", "-o", "{tiles}", "--quiet"],
            options: &[
                ("--synthetic", &["{}x32", "64x{}"]),
                ("--tile-size", &["{}"]),
                ("--quality", &["{}"]),
                ("--fallback-size", &["{}"]),
                ("--cube-size", &["{}"]),
                ("--hfov", &["{}"]),
                ("--max-pixels", &["{}"]),
            ],
        },
    ]
}

/// The commands whose every value option must be classified (`tour` has subcommands).
const CLASSIFIED: &[&[&str]] = &[
    &["render"],
    &["lux"],
    &["convert"],
    &["ies"],
    &["report"],
    &["tile"],
    &["tour", "check"],
    &["tour", "convert"],
];

/// The value options `viewer CMD --help` lists (`--name <VALUE>`).
fn value_options(cmd: &[&str]) -> Vec<String> {
    let out = Command::new(env!("CARGO_BIN_EXE_viewer"))
        .args(cmd)
        .arg("--help")
        .output()
        .unwrap();
    let help = String::from_utf8_lossy(&out.stdout).to_string();
    let mut v = Vec::new();
    for line in help.lines() {
        let t = line.trim_start();
        for word in t.split([' ', ',']) {
            if word.starts_with("--") && t.contains(&format!("{word} <")) {
                v.push(word.trim_end_matches('=').to_string());
            }
        }
    }
    v.sort();
    v.dedup();
    v
}

/// Exit status (None: killed by a signal), stdout, stderr; panics after 20 s.
fn run(args: &[String]) -> (Option<i32>, String, String) {
    let mut child = Command::new(env!("CARGO_BIN_EXE_viewer"))
        .args(args)
        .env("RUST_BACKTRACE", "0")
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let t0 = Instant::now();
    let status = loop {
        if let Some(st) = child.try_wait().unwrap() {
            break st;
        }
        if t0.elapsed() > Duration::from_secs(20) {
            let _ = child.kill();
            let _ = child.wait();
            panic!("viewer {args:?} still running after 20 s");
        }
        std::thread::sleep(Duration::from_millis(10));
    };
    let (mut o, mut e) = (String::new(), String::new());
    child.stdout.take().unwrap().read_to_string(&mut o).unwrap();
    child.stderr.take().unwrap().read_to_string(&mut e).unwrap();
    (status.code(), o, e)
}

#[test]
fn every_numeric_option_takes_the_extremes_calmly() {
    let dir = tmpdir("numeric", "options");
    let png = dir.join("p.png");
    image::RgbImage::from_fn(64, 32, |x, y| image::Rgb([x as u8 * 3, y as u8 * 7, 1]))
        .save(&png)
        .unwrap();
    let iso = test_support::test_data("ies/isotropic_10000lm.ies");
    let out = dir.join("faces");
    let tiles = dir.join("tiles");
    let json = dir.join("report.json");
    let fill = |t: &str, v: &str| {
        t.replace("{iso}", s(&iso))
            .replace("{png}", s(&png))
            .replace("{out}", s(&out))
            .replace("{tiles}", s(&tiles))
            .replace("{json}", s(&json))
            .replace("{}", v)
    };
    let cmds = commands();
    // Every value option of these commands is classified.
    for cmd in CLASSIFIED {
        let name = cmd.join(" ");
        for opt in value_options(cmd) {
            let numeric = cmds
                .iter()
                .filter(|c| c.name == name)
                .any(|c| c.options.iter().any(|(o, _)| *o == opt));
            assert!(
                numeric || NOT_NUMERIC.contains(&opt.as_str()),
                "`viewer {name} {opt}` is not classified: add it to this test's numeric \
                 options (with its value templates) or to NOT_NUMERIC"
            );
        }
    }
    let ext = extremes();
    let mut runs = 0;
    for cmd in &cmds {
        for (opt, templates) in cmd.options {
            // A few cases per option: a template and an extreme each.
            let mut runner = TestRunner::new(Config {
                cases: 3,
                failure_persistence: None,
                ..Config::default()
            });
            let strategy = (0..templates.len(), 0..ext.len());
            runner
                .run(&strategy, |(ti, ei)| {
                    let mut args: Vec<String> = cmd.base.iter().map(|a| fill(a, "")).collect();
                    // The option replaces a base value of its own (`--size`, `--light`).
                    if let Some(i) = args.iter().position(|a| a == opt) {
                        args.drain(i..=i + 1);
                    }
                    // `--opt=VALUE`: a negative value is a value, not an option.
                    args.push(format!("{opt}={}", fill(templates[ti], &ext[ei])));
                    let _ = std::fs::remove_file(&json);
                    let (code, stdout, stderr) = run(&args);
                    prop_assert!(
                        matches!(code, Some(0..=2)),
                        "{args:?}: exit {code:?}: {stderr}"
                    );
                    prop_assert!(!stderr.contains("panicked"), "{args:?}: {stderr}");
                    prop_assert!(stderr.len() < 3000, "{args:?}: {} bytes", stderr.len());
                    // JSON on standard output (`report --json` names a file instead).
                    let json_out = cmd.base.contains(&"--json") && !cmd.base.contains(&"{json}");
                    if code == Some(0) && json_out {
                        prop_assert!(!stdout.contains("null"), "{args:?}: {stdout}");
                        let v: serde_json::Value = serde_json::from_str(&stdout)
                            .map_err(|e| TestCaseError::fail(format!("{args:?}: {e}")))?;
                        prop_assert!(v.is_object());
                    }
                    // A JSON file written (`report --json`): the same rule.
                    if code == Some(0) && cmd.base.contains(&"{json}") {
                        let text = std::fs::read_to_string(&json)
                            .map_err(|e| TestCaseError::fail(format!("{args:?}: {e}")))?;
                        prop_assert!(!text.contains("null"), "{args:?}: {text}");
                    }
                    Ok(())
                })
                .unwrap_or_else(|e| panic!("viewer {} {opt}: {e}", cmd.name));
            runs += 3;
        }
    }
    assert!(runs > 60, "{runs}");
}
