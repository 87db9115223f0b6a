//! `viewer bench`'s report: one [`Row`] per configuration and set (the `--json` array's
//! elements; the field names are an interface scripts read), the text table, and the
//! minification set's note.

use lut_core::Sampler;
use serde::{Deserialize, Serialize};
use std::borrow::Cow;
use std::io::Write;

/// A name in a row: the program's own (`Cow::Borrowed`) or one read back from a `--json`
/// file by `viewer bench --replot` (`Cow::Owned`); written the same either way.
pub type Name = Cow<'static, str>;

/// What every row of one run shares: output size, threads, the map.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RunInfo {
    /// Output width.
    pub width: u32,
    /// Output height.
    pub height: u32,
    /// Worker threads.
    pub threads: usize,
    /// Map width.
    pub map_width: u32,
    /// Map height.
    pub map_height: u32,
    /// The map's projection name.
    pub projection: Name,
    /// The span kernel that ran (`lut_core::Kernel` name: scalar, sse41, avx2, avx512).
    pub kernel: Name,
}

/// One line of the report (one element of the `--json` array).
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
pub struct Row {
    /// "exact", "lut", "grid", "cube-basic", "cube-scanline" or "gather".
    pub renderer: Name,
    /// The sampler's name.
    pub sampler: Name,
    /// A number, "adaptive", or null (not a LUT renderer).
    pub index_step: serde_json::Value,
    /// "wide", "high" or null.
    #[serde(default)]
    pub lut: Option<Name>,
    /// Output size, threads, the map (`width` … `projection` in the JSON).
    #[serde(flatten)]
    pub run: RunInfo,
    /// Horizontal field of view of the set.
    pub hfov: f64,
    /// Frames in the set.
    pub frames: usize,
    /// Median milliseconds per frame.
    pub ms_median: f64,
    /// Fastest frame.
    pub ms_min: f64,
    /// Slowest frame.
    pub ms_max: f64,
    /// Output megapixels per second at the median frame time.
    pub mpix_s: f64,
    /// Max sampling-position error over all frames, source pixels (null: not measured,
    /// e.g. a cube renderer samples cube faces, not the map).
    pub max_err_px: Option<f64>,
    /// Mean sampling-position error, source pixels.
    pub mean_err_px: Option<f64>,
    /// PSNR against the exact render with the same sampler (null: identical images).
    pub psnr_db: Option<f64>,
    /// PSNR against the exact render supersampled 8×8 per pixel (the minification set).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub psnr_ss_db: Option<f64>,
    /// Fraction of pixels the LUT or grid renderer evaluated exactly (pole zones, beyond
    /// a table; grid cells that failed their budget at the smallest size).
    pub exact_fraction: Option<f64>,
    /// Bytes of the table (LUT rows).
    pub table_bytes: Option<usize>,
    /// Milliseconds the table took to build (LUT rows, once per map); grid rows: the
    /// median milliseconds of the grid's per-view build alone (part of every frame).
    pub table_build_ms: Option<f64>,
    /// The table surface: "cylinder", "plane" or "diamond" (LUT rows), else null.
    #[serde(default)]
    pub surface: Option<Name>,
    /// Rows whose sampling positions are stepped between exact ones rather than exact or
    /// measured: how far, in face texels, a position may lie from the exact one. No row
    /// `viewer bench` writes today has one (the cube scanline renderer's bilinear runs
    /// were stepped, within 0.0207 texels, until 2026-12-02); kept so that `--replot`
    /// reads JSON files written before and labels those rows.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub position_bound_texels: Option<f64>,
    /// With `--view`: the one view this row timed, [yaw, pitch, hfov] in degrees (absent
    /// for the fixed view sets).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub view: Option<[f64; 3]>,
}

impl Row {
    /// A row of `renderer` with `sampler` over `frames` frames at `hfov` that took `times`
    /// milliseconds each; nothing measured yet (the caller fills in what it measured).
    pub fn timed(
        run: &RunInfo,
        renderer: &'static str,
        sampler: Sampler,
        hfov: f64,
        frames: usize,
        times: &[f64],
    ) -> Row {
        let ms_median = super::measure::median(times);
        Row {
            renderer: renderer.into(),
            sampler: sampler.name().into(),
            index_step: serde_json::Value::Null,
            lut: None,
            run: run.clone(),
            hfov,
            frames,
            ms_median,
            ms_min: times.iter().copied().fold(f64::INFINITY, f64::min),
            ms_max: times.iter().copied().fold(0.0, f64::max),
            mpix_s: (run.width as f64 * run.height as f64)
                / (ms_median * 1e3).max(f64::MIN_POSITIVE),
            max_err_px: None,
            mean_err_px: None,
            psnr_db: None,
            psnr_ss_db: None,
            exact_fraction: None,
            table_bytes: None,
            table_build_ms: None,
            surface: None,
            position_bound_texels: None,
            view: None,
        }
    }
}

/// The two tables (wide, high) of one surface: build milliseconds, bytes, bytes
/// unfolded.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Tables {
    /// Build time in milliseconds.
    pub build_ms: [f64; 2],
    /// Bytes as stored (folded).
    pub bytes: [usize; 2],
    /// Bytes of the same table unfolded.
    pub unfolded: [usize; 2],
}

/// One line of the tables' summary: a surface's two tables.
fn tables_line(name: &str, t: &Tables) -> String {
    format!(
        "{name}: wide {:.1} ms, {} KiB (unfolded {} KiB, 1/{:.2}); high {:.1} ms, {} KiB (unfolded {} KiB, 1/{:.2})",
        t.build_ms[0],
        t.bytes[0] / 1024,
        t.unfolded[0] / 1024,
        t.unfolded[0] as f64 / t.bytes[0].max(1) as f64,
        t.build_ms[1],
        t.bytes[1] / 1024,
        t.unfolded[1] / 1024,
        t.unfolded[1] as f64 / t.bytes[1].max(1) as f64
    )
}

fn fmt_opt(v: Option<f64>, prec: usize) -> String {
    v.map_or("-".to_string(), |x| format!("{x:.prec$}"))
}

/// An index step as the table and the chart show it: a number, "adaptive", or "-".
pub fn step_str(v: &serde_json::Value) -> String {
    match v {
        serde_json::Value::Null => "-".into(),
        serde_json::Value::String(s) => s.clone(),
        o => o.to_string(),
    }
}

/// One row as a line of the text table (also the progress line).
pub fn row_line(r: &Row) -> String {
    let renderer = match r.surface.as_deref() {
        Some(sf) if sf != "cylinder" => format!("{}/{sf}", r.renderer),
        _ => r.renderer.to_string(),
    };
    format!(
        "{:<13} {:<8} {:>8} {:<4} {:>5} {:>9.2} {:>9.2} {:>7.0} {:>10} {:>10} {:>7} {:>7}",
        renderer,
        r.sampler,
        step_str(&r.index_step),
        r.lut.as_deref().unwrap_or("-"),
        r.hfov,
        r.ms_median,
        r.ms_min,
        r.mpix_s,
        fmt_opt(r.max_err_px, 4),
        fmt_opt(r.mean_err_px, 5),
        fmt_opt(r.psnr_db, 1),
        r.exact_fraction
            .map_or("-".into(), |f| format!("{:.2}%", f * 100.0)),
    )
}

/// The text table: what was measured, the kernel, the tables (the cylinder's, then the
/// other surfaces' in `others`), one line per row, the units.
///
/// `cpu`: the kernel line (`lut_core::kernel_info()`: the kernel, how it was chosen, the
/// CPU features detected).
pub fn write_table(
    o: &mut impl Write,
    rows: &[Row],
    t: &Tables,
    others: &[(&str, Tables)],
    cpu: &str,
) -> std::io::Result<()> {
    if let Some(r) = rows.first() {
        let run = &r.run;
        writeln!(
            o,
            "map {}x{} {}, output {}x{}, {} threads, {} frames per set",
            run.map_width,
            run.map_height,
            run.projection,
            run.width,
            run.height,
            run.threads,
            r.frames
        )?;
    }
    writeln!(o, "{cpu}")?;
    writeln!(o, "{}", tables_line("tables", t))?;
    for (name, t) in others {
        writeln!(o, "{}", tables_line(&format!("{name} tables"), t))?;
    }
    writeln!(
        o,
        "{:<13} {:<8} {:>8} {:<4} {:>5} {:>9} {:>9} {:>7} {:>10} {:>10} {:>7} {:>7}",
        "renderer",
        "sampler",
        "step",
        "lut",
        "hfov",
        "ms_med",
        "ms_min",
        "Mpx/s",
        "max_err",
        "mean_err",
        "PSNR",
        "exact"
    )?;
    for r in rows {
        writeln!(o, "{}", row_line(r))?;
    }
    writeln!(
        o,
        "Mpx/s: output megapixels per second at the median; errors in source pixels (angular metric); PSNR in dB against the exact render with the same sampler ('-' = identical); grid rows: per-view grid build {} ms median (inside each frame)",
        rows.iter()
            .find(|r| r.renderer == "grid")
            .and_then(|r| r.table_build_ms)
            .map_or("-".into(), |ms| format!("{ms:.2}"))
    )
}

/// The minification set in a few lines: what it is, the pyramid, each row's time and
/// PSNR against the supersampled truth.
pub fn minify_note(
    size: (u32, u32),
    views: usize,
    pyramid_ms: f64,
    pyramid_bytes: usize,
    map_bytes: usize,
    rows: &[Row],
) -> String {
    let (w, h) = size;
    let mut note = format!(
        "minification set: {w}x{h} at hfov {}, {views} views; pyramid built in {pyramid_ms:.0} ms, \
         {:.1} MiB ({:.0} % of the map); PSNR against the exact render supersampled 8x8:",
        super::configs::MINIFY_HFOV,
        pyramid_bytes as f64 / 1048576.0,
        100.0 * pyramid_bytes as f64 / map_bytes as f64
    );
    for r in rows {
        note.push_str(&format!(
            "\n  {:<6} {:<9} {:>7.2} ms  {:>5.1} dB",
            r.renderer,
            r.sampler,
            r.ms_median,
            r.psnr_ss_db.unwrap_or(f64::INFINITY)
        ));
    }
    note
}

#[cfg(test)]
mod tests {
    use super::*;

    fn run() -> RunInfo {
        RunInfo {
            width: 1920,
            height: 1080,
            threads: 2,
            map_width: 8192,
            map_height: 4096,
            projection: "equirect".into(),
            kernel: "avx2".into(),
        }
    }

    fn lut_row() -> Row {
        Row {
            index_step: serde_json::json!(4),
            lut: Some("wide".into()),
            max_err_px: Some(0.01234),
            mean_err_px: Some(0.001),
            psnr_db: Some(48.25),
            exact_fraction: Some(0.0125),
            table_bytes: Some(1 << 20),
            table_build_ms: Some(12.0),
            ..Row::timed(&run(), "lut", Sampler::Bilinear, 90.0, 3, &[3.0, 1.0, 2.0])
        }
    }

    /// The JSON field names and their order are an interface (scripts/peers.py, docs).
    #[test]
    fn json_fields_are_the_interface() {
        let v = serde_json::to_value(lut_row()).unwrap();
        let keys: Vec<&str> = v.as_object().unwrap().keys().map(|k| k.as_str()).collect();
        let mut want = vec![
            "renderer",
            "sampler",
            "index_step",
            "lut",
            "width",
            "height",
            "threads",
            "map_width",
            "map_height",
            "projection",
            "kernel",
            "hfov",
            "frames",
            "ms_median",
            "ms_min",
            "ms_max",
            "mpix_s",
            "max_err_px",
            "mean_err_px",
            "psnr_db",
            "exact_fraction",
            "table_bytes",
            "table_build_ms",
            "surface",
        ];
        let mut got = keys.clone();
        got.sort_unstable();
        want.sort_unstable();
        assert_eq!(got, want, "psnr_ss_db is left out when not measured");
        let text = serde_json::to_string(&lut_row()).unwrap();
        assert!(
            text.starts_with(
                r#"{"renderer":"lut","sampler":"bilinear","index_step":4,"lut":"wide","width":1920"#
            ),
            "{text}"
        );
        assert_eq!(v["ms_median"], 2.0);
        // 1920×1080 pixels in 2 ms.
        assert_eq!(v["mpix_s"], 1920.0 * 1080.0 / 2000.0);
        assert_eq!(v["kernel"], "avx2");
        assert_eq!(
            (v["ms_min"].as_f64(), v["ms_max"].as_f64()),
            (Some(1.0), Some(3.0))
        );
        let ss = Row {
            psnr_ss_db: Some(30.0),
            ..lut_row()
        };
        assert_eq!(serde_json::to_value(ss).unwrap()["psnr_ss_db"], 30.0);
        let exact = serde_json::to_value(Row::timed(
            &run(),
            "exact",
            Sampler::Nearest,
            50.0,
            1,
            &[9.0],
        ))
        .unwrap();
        assert!(exact["index_step"].is_null() && exact["lut"].is_null());
    }

    /// Rows read back (`viewer bench --replot`) own their names (nothing is leaked) and
    /// write the same JSON bytes as the rows that were written.
    #[test]
    fn rows_read_back_write_the_same_json() {
        let rows = vec![
            lut_row(),
            Row {
                surface: Some("diamond".into()),
                psnr_ss_db: Some(30.0),
                ..lut_row()
            },
            Row::timed(&run(), "exact", Sampler::Nearest, 50.0, 1, &[9.0]),
        ];
        let text = serde_json::to_string_pretty(&rows).unwrap();
        let back: Vec<Row> = serde_json::from_str(&text).unwrap();
        assert_eq!(back, rows);
        let owned = |n: &Name| matches!(n, Cow::Owned(_));
        assert!(owned(&back[0].renderer) && owned(&back[0].sampler));
        assert!(owned(&back[0].run.projection) && owned(&back[0].run.kernel));
        assert!(back[1].lut.as_ref().is_some_and(owned));
        assert!(back[1].surface.as_ref().is_some_and(owned));
        assert_eq!(serde_json::to_string_pretty(&back).unwrap(), text);
    }

    #[test]
    fn table_lines() {
        assert_eq!(
            row_line(&lut_row()),
            "lut           bilinear        4 wide    90      2.00      1.00    1037     0.0123    0.00100    48.2   1.25%"
        );
        let gather = Row::timed(&run(), "gather", Sampler::Nearest, 90.0, 13, &[0.5]);
        assert_eq!(
            row_line(&gather),
            "gather        nearest         - -       90      0.50      0.50    4147          -          -       -       -"
        );
        assert_eq!(step_str(&serde_json::json!("adaptive")), "adaptive");
        let mut out = Vec::new();
        let tables = Tables {
            build_ms: [10.0, 20.0],
            bytes: [2048, 4096],
            unfolded: [16384, 8192],
        };
        write_table(
            &mut out,
            &[lut_row()],
            &tables,
            &[("diamond", tables)],
            "kernel avx2 (auto; CPU: avx2)",
        )
        .unwrap();
        let text = String::from_utf8(out).unwrap();
        let mut lines: Vec<&str> = text.lines().collect();
        assert_eq!(lines.len(), 7, "{text}");
        assert_eq!(
            lines[0],
            "map 8192x4096 equirect, output 1920x1080, 2 threads, 3 frames per set"
        );
        assert_eq!(lines.remove(1), "kernel avx2 (auto; CPU: avx2)");
        assert_eq!(
            lines[1],
            "tables: wide 10.0 ms, 2 KiB (unfolded 16 KiB, 1/8.00); high 20.0 ms, 4 KiB (unfolded 8 KiB, 1/2.00)"
        );
        assert_eq!(
            lines[2],
            "diamond tables: wide 10.0 ms, 2 KiB (unfolded 16 KiB, 1/8.00); high 20.0 ms, 4 KiB (unfolded 8 KiB, 1/2.00)"
        );
        assert!(lines[3].starts_with("renderer      sampler"));
        assert_eq!(lines[4], row_line(&lut_row()));
        let diamond = Row {
            surface: Some("diamond".into()),
            ..lut_row()
        };
        assert!(row_line(&diamond).starts_with("lut/diamond   bilinear"));
    }

    #[test]
    fn minify_note_lines() {
        let rows = [Row {
            psnr_ss_db: Some(31.26),
            ..Row::timed(&run(), "lut", Sampler::Trilinear, 120.0, 5, &[4.0])
        }];
        let note = minify_note((640, 360), 5, 80.0, 3 << 20, 12 << 20, &rows);
        assert_eq!(
            note,
            "minification set: 640x360 at hfov 120, 5 views; pyramid built in 80 ms, 3.0 MiB (25 % of the map); PSNR against the exact render supersampled 8x8:\n  lut    trilinear    4.00 ms   31.3 dB"
        );
    }
}
