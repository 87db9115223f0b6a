//! `viewer report`: the lighting of a room checked against EN 12464-1, as a planner
//! reads it: the work plane, the floor, the ceiling and each wall on the standard's
//! calculation grids ([`lut_core::CalcGrid`]), per area Em, Emin, Emax, U0 and Ud with
//! the inter-reflections ([`lut_core::Radiosity`]); pass or fail against a task of
//! EN 12464-1's tables ([`TASKS`]); the luminaires and their flux; CIE 117's UGR for the
//! observer at the camera. Printed as a table, and written as JSON (`--json`), a PNG
//! (`--png`: the work plane's plan in false colours with isolux lines and the luminaires,
//! and the lit view beside it) and one self-contained HTML page (`--html`).

mod html;
mod json;
mod png;

use crate::lighting::RoomArgs;
use crate::usage;
use anyhow::{Context, Result};
use clap::Args;
use glam::DVec3;
use lut_core::{AreaStats, CalcGrid, LightScene, LuminousArea, Photometry, Reflectances, RoomFace};
use std::path::PathBuf;
use std::sync::Arc;

/// Arguments of `viewer report`.
// The field docs are the command-line help.
#[allow(rustdoc::broken_intra_doc_links)]
#[derive(Args, Debug)]
pub struct ReportArgs {
    /// The panorama for the lit view beside the plan (--png, --html): default the
    /// --scene file's, else the bundled sample.
    pub panorama: Vec<PathBuf>,
    /// The room and its luminaires (at least one --light, or a --scene with lights).
    #[command(flatten)]
    pub room: RoomArgs,
    /// The work plane's height above the floor in metres.
    #[arg(long, default_value_t = 0.75)]
    pub height: f64,
    /// The task the room is checked against (EN 12464-1); an unknown name prints the list.
    #[arg(long, default_value = "office-writing")]
    pub task: String,
    /// View yaw in degrees for the lit view and the UGR observer (default the --scene
    /// file's view, else 0).
    #[arg(long, allow_hyphen_values = true)]
    pub yaw: Option<f64>,
    /// View pitch in degrees (default the --scene file's, else 0: a horizontal line of
    /// sight, as CIE 117 assumes).
    #[arg(long, allow_hyphen_values = true)]
    pub pitch: Option<f64>,
    /// Horizontal field of view of the lit view in degrees (default the scene's, else 90).
    #[arg(long)]
    pub hfov: Option<f64>,
    /// Write the report as JSON.
    #[arg(long, value_name = "OUT.json")]
    pub json: Option<PathBuf>,
    /// Write the plan and the lit view as a PNG image.
    #[arg(long, value_name = "OUT.png")]
    pub png: Option<PathBuf>,
    /// Write one self-contained HTML page (images inline, print-friendly).
    #[arg(long, value_name = "OUT.html")]
    pub html: Option<PathBuf>,
}

/// One task of EN 12464-1's tables: the maintained illuminance and uniformity on the
/// task area, and the walls' and ceiling's mean illuminance.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Task {
    /// The name `--task` takes.
    pub name: &'static str,
    /// What it is, and the table's reference.
    pub description: &'static str,
    /// Em required on the work plane, lux.
    pub em: f64,
    /// U0 required on the work plane.
    pub u0: f64,
    /// Em required on the walls, lux.
    pub walls_em: f64,
    /// Em required on the ceiling, lux.
    pub ceiling_em: f64,
}

/// U0 the walls and the ceiling need (EN 12464-1:2011 4.2.2: ≥ 0.10).
pub const SURFACE_U0: f64 = 0.10;

/// The tasks `--task` knows (EN 12464-1:2011 table 5.26 offices, 5.36 educational
/// buildings, 5.1 circulation areas; walls and ceilings by 4.2.2: 75 and 50 lx in
/// offices, educational buildings and hospitals, 50 and 30 lx elsewhere).
pub const TASKS: &[Task] = &[
    Task {
        name: "office-writing",
        description: "Offices: writing, typing, reading, data processing (5.26.2)",
        em: 500.0,
        u0: 0.60,
        walls_em: 75.0,
        ceiling_em: 50.0,
    },
    Task {
        name: "office-filing",
        description: "Offices: filing, copying (5.26.1)",
        em: 300.0,
        u0: 0.40,
        walls_em: 75.0,
        ceiling_em: 50.0,
    },
    Task {
        name: "office-drawing",
        description: "Offices: technical drawing (5.26.3)",
        em: 750.0,
        u0: 0.70,
        walls_em: 75.0,
        ceiling_em: 50.0,
    },
    Task {
        name: "office-cad",
        description: "Offices: CAD work stations (5.26.4)",
        em: 500.0,
        u0: 0.60,
        walls_em: 75.0,
        ceiling_em: 50.0,
    },
    Task {
        name: "conference",
        description: "Offices: conference and meeting rooms (5.26.5)",
        em: 500.0,
        u0: 0.60,
        walls_em: 75.0,
        ceiling_em: 50.0,
    },
    Task {
        name: "reception",
        description: "Offices: reception desk (5.26.6)",
        em: 300.0,
        u0: 0.60,
        walls_em: 75.0,
        ceiling_em: 50.0,
    },
    Task {
        name: "archives",
        description: "Offices: archives (5.26.7)",
        em: 200.0,
        u0: 0.40,
        walls_em: 75.0,
        ceiling_em: 50.0,
    },
    Task {
        name: "classroom",
        description: "Educational buildings: classrooms, tutorial rooms (5.36.2)",
        em: 300.0,
        u0: 0.60,
        walls_em: 75.0,
        ceiling_em: 50.0,
    },
    Task {
        name: "classroom-evening",
        description:
            "Educational buildings: classrooms for evening classes and adult education (5.36.3)",
        em: 500.0,
        u0: 0.60,
        walls_em: 75.0,
        ceiling_em: 50.0,
    },
    Task {
        name: "corridor",
        description: "Circulation areas: corridors (5.1.2)",
        em: 100.0,
        u0: 0.40,
        walls_em: 50.0,
        ceiling_em: 30.0,
    },
];

/// The task named `name`.
///
/// # Errors
/// A usage error listing the known names.
pub fn task(name: &str) -> Result<&'static Task> {
    TASKS.iter().find(|t| t.name == name).ok_or_else(|| {
        let list: Vec<String> = TASKS
            .iter()
            .map(|t| format!("{} ({} lx, U0 {:.2})", t.name, t.em, t.u0))
            .collect();
        usage!(
            "--task '{}' is not in the table; known tasks: {}",
            name.escape_debug(),
            list.join(", ")
        )
    })
}

/// One calculation area's figures and verdict.
#[derive(Debug, Clone)]
pub struct AreaLine {
    /// The grid.
    pub grid: CalcGrid,
    /// The illuminance at its points, lux.
    pub values: Vec<f64>,
    /// Em, Emin, Emax, U0, Ud.
    pub stats: AreaStats,
    /// What the task asks of it (Em, U0), if anything.
    pub required: Option<(f64, f64)>,
    /// Whether it meets that.
    pub pass: Option<bool>,
}

/// One luminaire as listed.
#[derive(Debug, Clone)]
pub struct LuminaireLine {
    /// The file as given.
    pub file: String,
    /// Position, room coordinates, metres.
    pub position: [f64; 3],
    /// Aim yaw and pitch, degrees.
    pub aim: [f64; 2],
    /// Its multiplier (0 when switched off).
    pub multiplier: f64,
    /// Its luminous flux, lm (the table integrated over the sphere, × multiplier).
    pub flux_lm: f64,
    /// The power the file gives, W.
    pub power_w: Option<f64>,
    /// The luminous area the file gives.
    pub luminous_area: Option<LuminousArea>,
}

/// Everything a report shows.
#[derive(Debug, Clone)]
pub struct Report {
    /// Room width, depth, height, metres.
    pub room: [f64; 3],
    /// The reflectances given.
    pub reflectances: Reflectances,
    /// Inter-reflections included.
    pub indirect: bool,
    /// The work plane's height, metres.
    pub height: f64,
    /// The border band left out of the work plane, metres.
    pub band: f64,
    /// The areas: work plane, floor, ceiling, then the walls.
    pub areas: Vec<AreaLine>,
    /// The task.
    pub task: &'static Task,
    /// Every area with a requirement passes.
    pub pass: bool,
    /// The luminaires.
    pub luminaires: Vec<LuminaireLine>,
    /// Their total flux, lm.
    pub total_flux_lm: f64,
    /// The glare rating.
    pub ugr: lut_core::Ugr,
    /// The observer (room coordinates) and the line of sight (room frame).
    pub observer: (DVec3, DVec3),
    /// The view: yaw, pitch, hfov in degrees.
    pub view: [f64; 3],
}

/// The room's lit scene, the state and the view these arguments give.
struct Setup {
    st: crate::lighting::LightsState,
    scene: LightScene,
    view: [f64; 3],
}

fn setup(a: &ReportArgs) -> Result<Setup> {
    let st = a.room.state()?;
    if st.lights.is_empty() {
        return Err(usage!(
            "no luminaire: give --light FILE@X,Y,Z[:YAW,PITCH] (or a --scene with lights)"
        ));
    }
    Ok(Setup {
        scene: st
            .direct_scene()
            .map_err(anyhow::Error::msg)?
            .context("no luminaire")?,
        view: view_of(a)?,
        st,
    })
}

fn view_of(a: &ReportArgs) -> Result<[f64; 3]> {
    let (_, scene_view) = a.room.scene_panorama()?;
    Ok([
        a.yaw.or(scene_view.map(|v| v.yaw)).unwrap_or(0.0),
        a.pitch.or(scene_view.map(|v| v.pitch)).unwrap_or(0.0),
        a.hfov.or(scene_view.map(|v| v.hfov)).unwrap_or(90.0),
    ])
}

/// Compute the report (no output written).
///
/// # Errors
/// Bad arguments (usage, exit 2), unreadable files (exit 1), limits.
pub fn compute(a: &ReportArgs) -> Result<(Report, LightScene, crate::lighting::LightsState)> {
    let task = task(&a.task)?;
    if !(a.height.is_finite() && a.height > 0.0) {
        return Err(usage!(
            "--height must be a positive number of metres, got {}",
            a.height
        ));
    }
    for (name, v) in [("--yaw", a.yaw), ("--pitch", a.pitch), ("--hfov", a.hfov)] {
        if v.is_some_and(|v| !v.is_finite()) {
            return Err(usage!("{name} must be a finite number of degrees"));
        }
    }
    let Setup { st, scene, view } = setup(a)?;
    let (report, scene) = compute_state(&st, scene, a.height, task, view)?;
    Ok((report, scene, st))
}

/// Compute the report of the light state `st` (whose direct scene is `scene`) with the
/// work plane at `height`, against `task`, the observer looking along `view` (yaw,
/// pitch, hfov): what `viewer report` computes once its arguments are read, and what the
/// window's "Report…" button computes from the panel.
///
/// # Errors
/// A height outside the room or grids past the budget (usage errors), reflectances out
/// of range, an unreadable luminaire file.
pub fn compute_state(
    st: &crate::lighting::LightsState,
    scene: LightScene,
    height: f64,
    task: &'static Task,
    view: [f64; 3],
) -> Result<(Report, LightScene)> {
    let room = *scene.room();
    let mut grids = vec![CalcGrid::work_plane(&room, height).map_err(|e| match e {
        lut_core::LightError::TooMany { .. } => usage!("--room: {e}"),
        e => usage!("--height: {e}"),
    })?];
    for face in [
        RoomFace::Floor,
        RoomFace::Ceiling,
        RoomFace::Left,
        RoomFace::Right,
        RoomFace::Back,
        RoomFace::Front,
    ] {
        grids.push(CalcGrid::face(&room, face).map_err(|e| usage!("--room: {e}"))?);
    }
    let total: usize = grids.iter().map(|g| g.points.len()).sum();
    if total > lut_core::MAX_GRID_POINTS {
        return Err(usage!(
            "--room: the calculation grids need {total} points, more than the limit of {}",
            lut_core::MAX_GRID_POINTS
        ));
    }
    // The inter-reflections, once the grids are known to fit.
    let scene = if st.indirect {
        scene
            .with_reflectances(st.reflectances)
            .map_err(|e| usage!("--reflectances: {e}"))?
    } else {
        scene
    };
    let mut areas = Vec::new();
    for grid in grids {
        let values = crate::lighting::read_grid(&scene, &grid);
        let stats = AreaStats::of(&values);
        let required = match grid.face {
            None => Some((task.em, task.u0)),
            Some(RoomFace::Floor) => None,
            Some(RoomFace::Ceiling) => Some((task.ceiling_em, SURFACE_U0)),
            Some(_) => Some((task.walls_em, SURFACE_U0)),
        };
        let pass = required.map(|(em, u0)| stats.em >= em && stats.u0 >= u0);
        areas.push(AreaLine {
            grid,
            values,
            stats,
            required,
            pass,
        });
    }
    let pass = areas.iter().all(|l| l.pass != Some(false));
    // The luminaires: each table's flux and each file's data once.
    let mut flux_of: Vec<(usize, f64)> = Vec::new();
    let mut file_of: Vec<(PathBuf, Option<f64>, Option<LuminousArea>)> = Vec::new();
    let mut luminaires = Vec::new();
    let mut areas_lum = Vec::new();
    for (l, placed) in st.lights.iter().zip(scene.luminaires()) {
        let key = Arc::as_ptr(&l.table) as usize;
        let flux = match flux_of.iter().find(|(k, _)| *k == key) {
            Some(&(_, f)) => f,
            None => {
                let f = l.table.luminous_flux();
                flux_of.push((key, f));
                f
            }
        };
        let (power, area) = match file_of.iter().find(|(p, _, _)| *p == l.path) {
            Some((_, w, a)) => (*w, *a),
            None => {
                let ph = Photometry::load(&l.path)?;
                let w = match &ph.source {
                    lut_core::PhotometrySource::Ies(f) => Some(f.input_watts),
                    lut_core::PhotometrySource::Ldt(f) => f.lamp_sets.first().map(|s| s.watts),
                }
                .filter(|w| w.is_finite() && *w > 0.0);
                let area = LuminousArea::of(&ph);
                file_of.push((l.path.clone(), w, area));
                (w, area)
            }
        };
        areas_lum.push(area);
        luminaires.push(LuminaireLine {
            file: l.path.display().to_string(),
            position: l.position,
            aim: [l.yaw, l.pitch],
            multiplier: placed.multiplier,
            flux_lm: flux * placed.multiplier,
            power_w: power,
            luminous_area: area,
        });
    }
    let total_flux_lm = luminaires.iter().map(|l| l.flux_lm).sum();
    let (sy, cy) = view[0].to_radians().sin_cos();
    let (sp, cp) = view[1].clamp(-90.0, 90.0).to_radians().sin_cos();
    let sight = room.to_room(DVec3::new(sy * cp, sp, cy * cp));
    let eye = room.camera_position();
    let ugr = lut_core::ugr(&scene, &areas_lum, eye, sight);
    let report = Report {
        room: [room.width(), room.depth(), room.height()],
        reflectances: st.reflectances,
        indirect: st.indirect,
        height,
        band: lut_core::border_band(room.width(), room.depth()),
        areas,
        task,
        pass,
        luminaires,
        total_flux_lm,
        ugr,
        observer: (eye, sight),
        view,
    };
    Ok((report, scene))
}

/// Lux with three significant digits at most, as the tables print it.
pub fn lux(v: f64) -> String {
    if v >= 100.0 {
        format!("{v:.0}")
    } else if v >= 10.0 {
        format!("{v:.1}")
    } else {
        format!("{v:.2}")
    }
}

/// The report as text (what `viewer report` prints).
pub fn text(r: &Report) -> String {
    let mut s = format!(
        "room {} x {} x {} m, reflectances floor {:.2} walls {:.2} ceiling {:.2}, {}\n",
        r.room[0],
        r.room[1],
        r.room[2],
        r.reflectances.floor,
        r.reflectances.walls,
        r.reflectances.ceiling,
        if r.indirect {
            "inter-reflections included"
        } else {
            "direct light only"
        }
    );
    s += &format!(
        "task: {} ({}): work plane Em >= {} lx, U0 >= {:.2}; walls Em >= {} lx, ceiling Em >= {} lx (U0 >= {:.2})\n\n",
        r.task.name, r.task.description, r.task.em, r.task.u0, r.task.walls_em, r.task.ceiling_em, SURFACE_U0
    );
    s += "area          m2      grid         Em      Emin    Emax    U0    Ud    required       result\n";
    for l in &r.areas {
        let g = &l.grid;
        s += &format!(
            "{:<13} {:<7.2} {:<12} {:<7} {:<7} {:<7} {:<5.2} {:<5.2} {:<14} {}\n",
            g.name,
            g.area_m2(),
            format!("{}x{} @{:.2}", g.nu, g.nv, g.spacing_m()),
            lux(l.stats.em),
            lux(l.stats.emin),
            lux(l.stats.emax),
            l.stats.u0,
            l.stats.ud,
            l.required
                .map_or("-".into(), |(em, u0)| format!(">={em} U0>={u0:.2}")),
            match l.pass {
                Some(true) => "pass",
                Some(false) => "FAIL",
                None => "-",
            }
        );
    }
    s += &format!(
        "\nresult: {}\n\nluminaires (total flux {:.0} lm):\n",
        if r.pass { "pass" } else { "FAIL" },
        r.total_flux_lm
    );
    for (i, l) in r.luminaires.iter().enumerate() {
        s += &format!(
            "{:<3} {} at ({:.2}, {:.2}, {:.2}) aim ({:.0}, {:.0}): {:.0} lm{}\n",
            i + 1,
            lut_core::shown(&l.file),
            l.position[0],
            l.position[1],
            l.position[2],
            l.aim[0],
            l.aim[1],
            l.flux_lm,
            l.power_w.map_or(String::new(), |w| format!(", {w:.1} W"))
        );
    }
    s += &match (r.ugr.value, r.ugr.note) {
        (Some(v), _) => {
            format!("\nUGR {v:.1} (CIE 117, observer at the camera looking along the view)\n")
        }
        (None, Some(n)) => format!("\nUGR: none ({n})\n"),
        (None, None) => "\nUGR: none\n".into(),
    };
    for t in &r.ugr.terms {
        if let Some(why) = t.excluded {
            s += &format!("    luminaire {}: not rated: {why}\n", t.index + 1);
        }
    }
    s
}

/// Run `viewer report`.
pub fn run(a: ReportArgs) -> Result<()> {
    // The outputs are checked before anything is computed.
    let outs: Vec<&PathBuf> = [&a.json, &a.png, &a.html].into_iter().flatten().collect();
    if let Some(p) = &a.png {
        if crate::output::output_kind(p)? != crate::output::ImageKind::Png {
            return Err(usage!("--png {}: the name must end in .png", p.display()));
        }
    }
    for (i, x) in outs.iter().enumerate() {
        if outs[..i].contains(x) {
            return Err(usage!("{}: given as two outputs", x.display()));
        }
    }
    let mut inputs: Vec<PathBuf> = a.panorama.clone();
    inputs.extend(a.room.scene.iter().cloned());
    inputs.extend(a.room.lights.iter().map(|l| l.file.clone()));
    crate::output::check_not_input(
        &outs.iter().map(|p| (*p).clone()).collect::<Vec<_>>(),
        &inputs,
    )?;
    let (report, scene, _st) = compute(&a)?;
    // Everything is made before anything is written.
    let image = if a.png.is_some() || a.html.is_some() {
        Some(png::render(&a, &report, &scene)?)
    } else {
        None
    };
    let png_bytes = image.as_ref().map(png::encode).transpose()?;
    // Through the one JSON writer that refuses a number that is not finite (never null):
    // made whatever is asked, so that no output (the page, the text) shows one either.
    let j = json::json(&report)?;
    if let Some(p) = &a.json {
        crate::output::write_image_atomic(p, |w| Ok(w.write_all(j.as_bytes())?))?;
    }
    if let (Some(p), Some(bytes)) = (&a.png, &png_bytes) {
        crate::output::write_image_atomic(p, |w| Ok(w.write_all(bytes)?))?;
    }
    if let (Some(p), Some(bytes)) = (&a.html, &png_bytes) {
        let page = html::html(&report, bytes);
        crate::output::write_image_atomic(p, |w| Ok(w.write_all(page.as_bytes())?))?;
    }
    crate::outln!("{}", text(&report).trim_end_matches('\n'))?;
    Ok(())
}

/// The kinds of file the window's "Report…" writes, by the name's extension.
pub const WINDOW_REPORT_EXTENSIONS: &[&str] = &["html", "json", "png"];

/// Write the report of the window's light state `st` to `path` (the kind by its
/// extension: `.html` the page with the image and tables, `.json`, `.png`), with
/// `viewer report`'s defaults (work plane 0.75 m, task office-writing) and the observer
/// along `view` (yaw, pitch, hfov in degrees); `pano`, the panorama shown, gives the lit
/// view beside the plan (rendered as `viewer render` does, exposed so the work plane's
/// Em looks like the photograph; grey without one). Everything is made before anything
/// is written; the file is written atomically. Returns the line the window shows.
///
/// # Errors
/// No luminaire, an unknown extension, the computation's errors, a failed write.
pub fn write_from_state(
    st: &crate::lighting::LightsState,
    pano: Option<&mut lut_core::Panorama>,
    view: [f64; 3],
    path: &std::path::Path,
) -> Result<String> {
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase)
        .unwrap_or_default();
    if !WINDOW_REPORT_EXTENSIONS.contains(&ext.as_str()) {
        anyhow::bail!(
            "{}: a report is written as .html, .json or .png",
            path.display()
        );
    }
    let scene = st
        .direct_scene()
        .map_err(anyhow::Error::msg)?
        .context("no luminaire to report on")?;
    let task = task("office-writing")?;
    let (report, scene) = compute_state(st, scene, crate::lighting::WORK_PLANE_HEIGHT, task, view)?;
    let bytes: Vec<u8> = if ext == "json" {
        json::json(&report)?.into_bytes()
    } else {
        let (w, h) = png::VIEW_SIZE;
        let mut frame = vec![0x808080u32; (w * h) as usize];
        if let Some(pano) = pano {
            let mut lit = st.clone();
            lit.exposure_lux = report.areas[0].stats.em.max(1.0);
            lit.auto_exposure = false;
            lit.false_color = false;
            lit.show_room = false;
            let v = lut_core::View::new(view[0], view[1], view[2])
                .map_err(|e| anyhow::anyhow!("the lit view: {e}"))?;
            lit.render_lit(
                &mut crate::lighting::LitCache::default(),
                false,
                pano,
                v,
                &lut_core::RenderOptions::default(),
                &mut frame,
                (w, h),
            )
            .map_err(|e| anyhow::anyhow!("the lit view: {e}"))?;
        }
        let image = png::encode(&png::render_with(&report, &scene, &frame)?)?;
        if ext == "png" {
            image
        } else {
            html::html(&report, &image).into_bytes()
        }
    };
    crate::output::write_image_atomic(path, |w| Ok(w.write_all(&bytes)?))?;
    let wp = &report.areas[0].stats;
    Ok(format!(
        "report {}: work plane Em {} lx, U0 {:.2}: {}",
        path.display(),
        lux(wp.em),
        wp.u0,
        if report.pass { "pass" } else { "FAIL" }
    ))
}

#[cfg(test)]
mod tests {
    use super::*;
    use clap::Parser;

    #[derive(Parser)]
    struct Cli {
        #[command(flatten)]
        report: ReportArgs,
    }

    fn louvre_at(x: f64, z: f64) -> String {
        format!(
            "{}@{x},2.75,{z}",
            test_support::test_data("ldt/office_louvre_2x28w.ldt").display()
        )
    }

    /// The window's "Report…" writes what `viewer report` computes for the same lights:
    /// the JSON of the panel's state (here the state `viewer report` read from its
    /// arguments) is byte for byte the command's JSON; an unknown extension is refused
    /// and writes nothing; the panel's live figures from the solving thread are the
    /// report's work plane.
    #[test]
    fn the_window_report_is_the_commands_report() {
        let mut argv = vec!["report".to_string(), "--room".into(), "6x5x2.8".into()];
        for (x, z) in [(-1.5, -1.2), (1.5, -1.2), (-1.5, 1.2), (1.5, 1.2)] {
            argv.push("--light".into());
            argv.push(louvre_at(x, z));
        }
        let a = Cli::parse_from(&argv).report;
        let (report, _, st) = compute(&a).unwrap();
        let want = json::json(&report).unwrap();
        let dir = std::env::temp_dir().join(format!("viewer-window-report-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("r.json");
        let line = write_from_state(&st, None, view_of(&a).unwrap(), &path).unwrap();
        let got = std::fs::read_to_string(&path).unwrap();
        assert_eq!(got, want);
        assert!(line.contains("work plane Em"), "{line}");
        assert!(report.areas[0].stats.em > 0.0);
        let bad = dir.join("r.txt");
        let e = write_from_state(&st, None, [0.0, 0.0, 90.0], &bad).unwrap_err();
        assert!(e.to_string().contains(".html, .json or .png"), "{e}");
        assert!(!bad.exists());
        let _ = std::fs::remove_dir_all(&dir);
        // The panel's live figures, from the solving thread, are the report's work plane.
        let mut solver = crate::lighting::Solver::start(Arc::new(|| {}));
        assert!(solver.request(&st));
        let key = st.geometry_key();
        let t0 = std::time::Instant::now();
        while !solver.poll(&key) {
            assert!(
                t0.elapsed().as_secs() < 120,
                "no result from the solving thread"
            );
            std::thread::sleep(std::time::Duration::from_millis(5));
        }
        let (live, points) = solver.latest().unwrap().work_plane.clone().unwrap();
        let wp = &report.areas[0];
        assert_eq!(points, wp.grid.points.len());
        for (got, want) in [
            (live.em, wp.stats.em),
            (live.emin, wp.stats.emin),
            (live.emax, wp.stats.emax),
            (live.u0, wp.stats.u0),
        ] {
            assert!(
                (got - want).abs() <= 1e-9 * want.abs(),
                "{live:?} vs {:?}",
                wp.stats
            );
        }
    }
}
