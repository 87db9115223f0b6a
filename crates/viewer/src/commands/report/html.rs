//! `viewer report --html`: one self-contained page: the plan and lit view (the PNG
//! inline, base64), the areas against the task, the luminaires and the glare rating,
//! styled to print on A4 (no scripts, no external files).

use super::{lux, Report, SURFACE_U0};

/// Standard base64 (RFC 4648, with padding).
pub fn base64(bytes: &[u8]) -> String {
    const T: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut s = String::with_capacity(bytes.len().div_ceil(3) * 4);
    for c in bytes.chunks(3) {
        let n = (c[0] as u32) << 16
            | (*c.get(1).unwrap_or(&0) as u32) << 8
            | *c.get(2).unwrap_or(&0) as u32;
        s.push(T[(n >> 18) as usize & 63] as char);
        s.push(T[(n >> 12) as usize & 63] as char);
        s.push(if c.len() > 1 {
            T[(n >> 6) as usize & 63] as char
        } else {
            '='
        });
        s.push(if c.len() > 2 {
            T[n as usize & 63] as char
        } else {
            '='
        });
    }
    s
}

/// Text made safe inside HTML.
pub fn escape(s: &str) -> String {
    s.chars()
        .map(|c| match c {
            '&' => "&amp;".into(),
            '<' => "&lt;".into(),
            '>' => "&gt;".into(),
            '"' => "&quot;".into(),
            '\'' => "&#39;".into(),
            c => c.to_string(),
        })
        .collect()
}

const STYLE: &str = "
body { font-family: 'DejaVu Sans', Arial, sans-serif; margin: 2em; color: #111; }
h1 { font-size: 1.5em; margin-bottom: 0.2em; }
h2 { font-size: 1.15em; margin-top: 1.4em; border-bottom: 1px solid #999; }
table { border-collapse: collapse; margin: 0.5em 0; }
th, td { border: 1px solid #888; padding: 0.25em 0.6em; text-align: right; }
th { background: #e8e8e8; }
td.name, th.name { text-align: left; }
.pass { color: #060; font-weight: bold; }
.fail { color: #b00; font-weight: bold; }
img.plan { max-width: 100%; border: 1px solid #888; }
p.note { font-size: 0.9em; color: #444; }
@media print {
  body { margin: 1cm; font-size: 10pt; }
  img.plan { max-width: 100%; page-break-inside: avoid; }
  table, h2 { page-break-inside: avoid; page-break-after: auto; }
  th { background: #ddd !important; -webkit-print-color-adjust: exact; print-color-adjust: exact; }
}
@page { size: A4 landscape; margin: 1cm; }
";

/// The page, with `png` (the report's image) inline.
pub fn html(r: &Report, png: &[u8]) -> String {
    let verdict = |p: Option<bool>| match p {
        Some(true) => "<span class=\"pass\">pass</span>".to_string(),
        Some(false) => "<span class=\"fail\">fail</span>".to_string(),
        None => "–".to_string(),
    };
    let mut s = String::from("<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">\n");
    s += "<title>Lighting report</title>\n<style>";
    s += STYLE;
    s += "</style></head><body>\n";
    s += &format!(
        "<h1>Lighting report: {} × {} × {} m room</h1>\n<p>Task: <b>{}</b> – {} (EN 12464-1): work plane Em ≥ {} lx, U0 ≥ {:.2}; walls Em ≥ {} lx, ceiling Em ≥ {} lx, U0 ≥ {:.2}. Result: {}</p>\n",
        r.room[0], r.room[1], r.room[2],
        escape(r.task.name), escape(r.task.description), r.task.em, r.task.u0,
        r.task.walls_em, r.task.ceiling_em, SURFACE_U0, verdict(Some(r.pass))
    );
    s += &format!(
        "<p>Reflectances: floor {:.2}, walls {:.2}, ceiling {:.2}; {}. Work plane at {:.2} m, border band {:.2} m.</p>\n",
        r.reflectances.floor, r.reflectances.walls, r.reflectances.ceiling,
        if r.indirect { "inter-reflections included (radiosity)" } else { "direct light only" },
        r.height, r.band
    );
    s += &format!(
        "<img class=\"plan\" alt=\"work plane plan in false colours with isolux lines, and the lit view\" src=\"data:image/png;base64,{}\">\n",
        base64(png)
    );
    s += "<h2>Calculation areas</h2>\n<table id=\"areas\"><tr><th class=\"name\">Area</th><th>m²</th><th>Grid</th><th>Spacing m</th><th>Em lx</th><th>Emin lx</th><th>Emax lx</th><th>U0</th><th>Ud</th><th>Required</th><th>Result</th></tr>\n";
    for l in &r.areas {
        let g = &l.grid;
        s += &format!(
            "<tr><td class=\"name\">{}</td><td>{:.2}</td><td>{} × {}</td><td>{:.3}</td><td>{}</td><td>{}</td><td>{}</td><td>{:.2}</td><td>{:.2}</td><td>{}</td><td>{}</td></tr>\n",
            escape(&g.name), g.area_m2(), g.nu, g.nv, g.spacing_m(),
            lux(l.stats.em), lux(l.stats.emin), lux(l.stats.emax), l.stats.u0, l.stats.ud,
            l.required.map_or("–".into(), |(em, u0)| format!("Em ≥ {em}, U0 ≥ {u0:.2}")),
            verdict(l.pass)
        );
    }
    s += "</table>\n";
    s += "<h2>Luminaires</h2>\n<table id=\"luminaires\"><tr><th>#</th><th class=\"name\">File</th><th>Position m</th><th>Aim °</th><th>Flux lm</th><th>Power W</th></tr>\n";
    for (i, l) in r.luminaires.iter().enumerate() {
        s += &format!(
            "<tr><td>{}</td><td class=\"name\">{}</td><td>{:.2}, {:.2}, {:.2}</td><td>{:.0}, {:.0}</td><td>{:.0}</td><td>{}</td></tr>\n",
            i + 1, escape(&lut_core::shown(&l.file)), l.position[0], l.position[1], l.position[2],
            l.aim[0], l.aim[1], l.flux_lm,
            l.power_w.map_or("–".into(), |w| format!("{w:.1}"))
        );
    }
    s += &format!(
        "<tr><th></th><th class=\"name\">Total</th><th></th><th></th><th>{:.0}</th><th></th></tr></table>\n",
        r.total_flux_lm
    );
    s += "<h2>Glare (CIE 117 UGR)</h2>\n";
    s += &match (r.ugr.value, r.ugr.note) {
        (Some(v), _) => format!(
            "<p>UGR <b>{v:.1}</b> for an observer at the camera ({:.2}, {:.2}, {:.2}) m looking along the view (yaw {:.0}°, pitch {:.0}°); background luminance {:.1} cd/m².</p>\n",
            r.observer.0.x, r.observer.0.y, r.observer.0.z, r.view[0], r.view[1], r.ugr.background_luminance
        ),
        (None, note) => format!("<p>No UGR: {}.</p>\n", escape(note.unwrap_or("nothing to rate"))),
    };
    let excluded: Vec<String> = r
        .ugr
        .terms
        .iter()
        .filter_map(|t| {
            t.excluded
                .map(|w| format!("luminaire {}: {}", t.index + 1, escape(w)))
        })
        .collect();
    if !excluded.is_empty() {
        s += &format!(
            "<p class=\"note\">Not rated: {}.</p>\n",
            excluded.join("; ")
        );
    }
    s += "<p class=\"note\">Grids per EN 12464-1 (p = 0.2 × 5<sup>log10 d</sup> m, points at cell centres); illuminance includes the light reflected by the room's surfaces when inter-reflections are on. Made by lutpano <code>viewer report</code>.</p>\n";
    s += "</body></html>\n";
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn base64_of_known_strings() {
        assert_eq!(base64(b""), "");
        assert_eq!(base64(b"f"), "Zg==");
        assert_eq!(base64(b"fo"), "Zm8=");
        assert_eq!(base64(b"foo"), "Zm9v");
        assert_eq!(base64(b"foobar"), "Zm9vYmFy");
        assert_eq!(escape("<a&'b'>"), "&lt;a&amp;&#39;b&#39;&gt;");
    }
}
