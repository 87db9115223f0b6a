//! `viewer render --show-room` and `--legend` on the repository's lit room
//! (`assets/interior_lit.json`): the wireframe is drawn where the room's edges project
//! (checked against the geometry, independently of the drawing code's own tests) and
//! nowhere else but the markers; the legend only inside its box; `--legend` without false
//! colours is refused with one line.

mod common;

use common::{s, tmpdir, viewer};
use lut_core::{Camera, View};
use viewer::lighting::legend::legend_box;
use viewer::lighting::overlay::{project_point, room_edges, ROOM_COLOR};
use viewer::lighting::SceneFile;

const W: u32 = 480;
const H: u32 = 270;

fn render(extra: &[&str], name: &str) -> Vec<[u8; 3]> {
    let dir = tmpdir("overlay", name);
    let out = dir.join(format!("{name}.png"));
    let scene = test_support::repo_root().join("assets/interior_lit.json");
    let mut args = vec![
        "render",
        "--scene",
        s(&scene),
        "-o",
        s(&out),
        "--size",
        "480x270",
    ];
    args.extend_from_slice(extra);
    let r = viewer(&args);
    assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
    image::open(&out)
        .unwrap()
        .to_rgb8()
        .pixels()
        .map(|p| p.0)
        .collect()
}

fn dist_to_segment(p: (f64, f64), a: (f64, f64), b: (f64, f64)) -> f64 {
    let (dx, dy) = (b.0 - a.0, b.1 - a.1);
    let l2 = dx * dx + dy * dy;
    let t = if l2 > 0.0 {
        (((p.0 - a.0) * dx + (p.1 - a.1) * dy) / l2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    ((p.0 - a.0 - t * dx).powi(2) + (p.1 - a.1 - t * dy).powi(2)).sqrt()
}

#[test]
fn the_wireframe_lies_on_the_room_edges() {
    let plain = render(&[], "plain");
    let shown = render(&["--show-room"], "shown");
    // The geometry: the scene's room and view, projected by the library.
    let path = test_support::repo_root().join("assets/interior_lit.json");
    let file = SceneFile::load(&path).unwrap();
    let st = file.to_state(path.parent().unwrap()).unwrap();
    let room = st.room_box().unwrap();
    let v = file.view.unwrap();
    let cam = Camera::new(View::new(v.yaw, v.pitch, v.hfov).unwrap(), W, H);
    let edges = room_edges(&room, &cam);
    assert!(edges.len() >= 6, "{edges:?}");
    let markers: Vec<(f64, f64)> = st
        .lights
        .iter()
        .filter_map(|l| project_point(&room, &cam, l.position.into()))
        .collect();
    let near_edge =
        |p: (f64, f64), r: f64| edges.iter().any(|&(a, b)| dist_to_segment(p, a, b) <= r);
    let near_marker =
        |p: (f64, f64), r: f64| markers.iter().any(|m| (m.0 - p.0).hypot(m.1 - p.1) <= r);
    let mut changed = 0;
    for y in 0..H {
        for x in 0..W {
            let i = (y * W + x) as usize;
            if plain[i] == shown[i] {
                continue;
            }
            changed += 1;
            let p = (x as f64 + 0.5, y as f64 + 0.5);
            // 2-px lines and 5-px markers (with their strokes toward the aim, 35 cm).
            assert!(
                near_edge(p, 2.5) || near_marker(p, 60.0),
                "pixel ({x}, {y}) changed away from every edge and marker"
            );
        }
    }
    assert!(changed > 500, "{changed}");
    // On each edge, away from its ends, the pixel is the wireframe's colour (JPEG-free
    // PNG, so within the anti-aliasing of a 2-px line through the pixel centre).
    let want = ROOM_COLOR.to_be_bytes();
    for &(a, b) in &edges {
        let m = ((a.0 + b.0) / 2.0, (a.1 + b.1) / 2.0);
        let (x, y) = (m.0.floor(), m.1.floor());
        if x < 2.0 || y < 2.0 || x >= (W - 2) as f64 || y >= (H - 2) as f64 {
            continue;
        }
        // The brightest-cyan pixel in the 3 × 3 around the midpoint.
        let best = (-1..=1)
            .flat_map(|dy| (-1..=1).map(move |dx| (dx, dy)))
            .map(|(dx, dy)| shown[((y as i64 + dy) as u32 * W + (x as i64 + dx) as u32) as usize])
            .map(|p| {
                (0..3)
                    .map(|c| (p[c] as i32 - want[c + 1] as i32).abs())
                    .max()
                    .unwrap()
            })
            .min()
            .unwrap();
        assert!(
            best <= 8,
            "edge {a:?}-{b:?}: nearest colour {best} levels off"
        );
    }
}

#[test]
fn the_legend_stays_in_its_box_and_needs_false_colours() {
    let fc = render(&["--false-color"], "fc");
    let legend = render(&["--false-color", "--legend"], "legend");
    let (bx, by, bw, bh) = legend_box(W, H).unwrap();
    let mut inside = 0;
    for y in 0..H {
        for x in 0..W {
            let i = (y * W + x) as usize;
            let boxed = (bx..bx + bw).contains(&x) && (by..by + bh).contains(&y);
            if boxed {
                inside += usize::from(fc[i] != legend[i]);
            } else {
                assert_eq!(fc[i], legend[i], "({x}, {y}) outside the legend changed");
            }
        }
    }
    assert!(inside as u32 > bw * bh / 2, "{inside}");
    let dir = tmpdir("overlay", "refused");
    let out = dir.join("x.png");
    let scene = test_support::repo_root().join("assets/interior_lit.json");
    let r = viewer(&["render", "--scene", s(&scene), "-o", s(&out), "--legend"]);
    assert!(!r.status.success());
    let e = String::from_utf8_lossy(&r.stderr);
    assert_eq!(e.trim_end().lines().count(), 1, "{e}");
    assert!(e.contains("--false-color"), "{e}");
    assert!(!out.exists());
}
