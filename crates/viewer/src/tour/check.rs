//! `viewer tour check`: every link, file and scene id of a tour, each problem one line
//! with its place in the file.
//!
//! On top of what reading reports (syntax, unknown types, absurd numbers, paths that
//! leave the folder, links to missing scenes), it checks that every image, cube face and
//! tile folder exists as a regular file or folder, and that every scene can be reached
//! from the first one. Cycles of links are what tours are made of and are not reported.

use super::{HotspotKind, Problem, Source, Tour};
use std::path::Path;

/// The problems of `tour` beyond those of reading (`file`: the config, for the lines).
pub fn check(tour: &Tour, file: &Path) -> Vec<Problem> {
    let mut out = Vec::new();
    let mut add = |line: usize, place: String, message: String| {
        out.push(Problem {
            file: file.to_path_buf(),
            line,
            place,
            message,
        })
    };
    for s in &tour.scenes {
        let place = |k: &str| {
            if tour.single {
                k.to_string()
            } else {
                format!("scenes.{}.{k}", s.id)
            }
        };
        // A problem found while `file_exists` holds `add`.
        let mut late: Option<(String, String)> = None;
        let mut file_exists = |rel: &str, what: String| match tour.resolve(rel) {
            Err(why) => add(s.source_line, what, why),
            Ok(p) => match std::fs::metadata(&p) {
                Ok(m) if m.is_file() => {}
                Ok(_) => add(
                    s.source_line,
                    what,
                    format!("\"{rel}\" is not a regular file"),
                ),
                Err(e) => add(s.source_line, what, format!("\"{rel}\": {}", describe(&e))),
            },
        };
        match &s.source {
            Source::Equirect(p) => file_exists(p, place("panorama")),
            Source::Cube(faces) => {
                for (i, f) in faces.iter().enumerate() {
                    if let Some(f) = f {
                        file_exists(f, format!("{}[{i}]", place("cubeMap")));
                    }
                }
            }
            Source::Multires(m) => {
                // Inline numbers (no config.json beside the tiles) are read as the
                // window reads them: refused ones are named.
                if m.get("path").is_some() {
                    if let Ok(dir) = tour.multires_base(&s.id, m) {
                        if dir.is_dir() && !dir.join("config.json").is_file() {
                            if let Err(e) = tour.multires_config(file, m) {
                                let why = e
                                    .strip_prefix(&format!("{}: ", file.display()))
                                    .unwrap_or(&e)
                                    .to_string();
                                late = Some((place("multiRes"), why));
                            }
                        }
                    }
                }
                let base = m.get("basePath").and_then(|b| b.as_str()).unwrap_or(".");
                let base = base.trim_start_matches("./");
                let base = if base.is_empty() { "." } else { base };
                match m.get("path").and_then(|p| p.as_str()) {
                    None => add(
                        s.line,
                        place("multiRes.path"),
                        "missing: no tile can be found".into(),
                    ),
                    Some(pat) => {
                        let ext = m.get("extension").and_then(|e| e.as_str()).unwrap_or("jpg");
                        // The one tile every face has: level 1, x 0, y 0.
                        for face in ["f", "r", "b", "l", "u", "d"] {
                            let rel = pat
                                .replace("%l0", "0")
                                .replace("%l", "1")
                                .replace("%s", face)
                                .replace("%x", "0")
                                .replace("%y", "0");
                            let rel = format!(
                                "{}/{}.{ext}",
                                base.trim_end_matches('/'),
                                rel.trim_start_matches('/')
                            );
                            file_exists(
                                &rel,
                                format!("{} (face {face}, level 1)", place("multiRes")),
                            );
                        }
                    }
                }
            }
            Source::MarzipanoTiles { dir, levels, .. } => {
                if levels.is_empty() {
                    file_exists(
                        "",
                        format!(
                            "{} (no usable level: the scene has no tiles)",
                            place("levels")
                        ),
                    );
                }
                // The levels as the pyramid reader takes them (sorted by size, `z` the
                // sorted index), and the smallest level on every face: read at open,
                // from preview.jpg when the folder has one, else its first tiles.
                if !levels.is_empty() {
                    if let Ok(root) = tour.resolve(dir) {
                        if let Err(e) = lut_core::MultiresConfig::marzipano(file, &root, levels) {
                            late = Some((place("levels"), e.reason));
                        }
                    }
                    let preview = format!("{dir}/preview.jpg");
                    if tour.resolve(&preview).is_ok_and(|p| p.is_file()) {
                        file_exists(&preview, format!("{} (level 0)", place("levels")));
                    } else {
                        for face in ["b", "d", "f", "l", "r", "u"] {
                            file_exists(
                                &format!("{dir}/0/{face}/0/0.jpg"),
                                format!("{} (face {face}, level 0)", place("levels")),
                            );
                        }
                    }
                }
            }
        }
        if let Some((place, message)) = late {
            add(s.source_line, place, message);
        }
    }
    // Every scene reachable from the first.
    if let Some(first) = tour.first() {
        let mut seen = vec![false; tour.scenes.len()];
        let mut stack = vec![tour.index(&first.id).unwrap_or(0)];
        while let Some(i) = stack.pop() {
            if std::mem::replace(&mut seen[i], true) {
                continue;
            }
            for h in &tour.scenes[i].hotspots {
                if let HotspotKind::Scene { scene_id, .. } = &h.kind {
                    if let Some(j) = tour.index(scene_id) {
                        stack.push(j);
                    }
                }
            }
        }
        for (s, seen) in tour.scenes.iter().zip(seen) {
            if !seen {
                add(
                    s.line,
                    format!("scenes.{}", s.id),
                    format!("no link leads here from the first scene \"{}\"", first.id),
                );
            }
        }
    }
    out
}

fn describe(e: &std::io::Error) -> String {
    match e.kind() {
        std::io::ErrorKind::NotFound => "no such file".into(),
        _ => e.to_string(),
    }
}
