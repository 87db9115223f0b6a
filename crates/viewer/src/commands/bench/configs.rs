//! What `viewer bench` measures: the fixed view sets, the renderer configurations, and
//! the minification set's views and configurations.

use anyhow::{anyhow, Result};
use lut_core::TableKind;
use lut_core::{
    CubeRenderer, IndexStep, LutChoice, Named, RenderOptions, RendererKind, Sampler, Surface, View,
};

/// Which views to measure.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ViewsArg {
    /// 5 fixed views and an 8-frame pan per set.
    Quick,
    /// 9 fixed views (adds the zenith and near-nadir) and a 24-frame pan per set.
    Full,
}

impl Named for ViewsArg {
    const ALL: &'static [Self] = &[ViewsArg::Quick, ViewsArg::Full];
    fn name(self) -> &'static str {
        match self {
            ViewsArg::Quick => "quick",
            ViewsArg::Full => "full",
        }
    }
    fn help(self) -> &'static str {
        match self {
            ViewsArg::Quick => "5 fixed views and an 8-frame pan per set",
            ViewsArg::Full => {
                "9 fixed views (adds the zenith and near-nadir) and a 24-frame pan per set"
            }
        }
    }
}

/// A set of frames rendered with one table choice.
#[derive(Debug, Clone, PartialEq)]
pub struct ViewSet {
    /// The table the set is natural for.
    pub table: TableKind,
    /// Horizontal field of view of every frame.
    pub hfov: f64,
    /// The frames.
    pub views: Vec<View>,
    /// A set of one view given with `--view`: its rows carry `view` [yaw, pitch, hfov].
    pub given: Option<[f64; 3]>,
}

/// One `--view YAW,PITCH,HFOV` (degrees), checked as a [`View`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ViewArg(pub [f64; 3]);

/// Parse one `--view YAW,PITCH,HFOV`: three finite numbers of degrees, a valid view
/// (pitch within ±90, hfov within the rectilinear range).
pub fn parse_view(s: &str) -> Result<ViewArg, String> {
    let parts: Vec<&str> = s.split(',').collect();
    if parts.len() != 3 {
        return Err(format!(
            "view '{s}' must be YAW,PITCH,HFOV in degrees (three numbers, e.g. 30,90,90)"
        ));
    }
    let mut v = [0.0; 3];
    for (x, p) in v.iter_mut().zip(&parts) {
        *x = crate::args::parse_angle(p).map_err(|e| format!("view '{s}': {e}"))?;
    }
    if !(-90.0..=90.0).contains(&v[1]) {
        return Err(format!(
            "view '{s}': pitch {} is outside -90..90 degrees",
            v[1]
        ));
    }
    View::new(v[0], v[1], v[2]).map_err(|e| format!("view '{s}': {e}"))?;
    Ok(ViewArg(v))
}

/// The sets of `--view`: one set of one frame per view, in the order given, on the table
/// the renderer would choose for its hfov (wide above [`lut_core::LUT_SWITCH_HFOV`],
/// else high).
pub fn given_view_sets(given: &[ViewArg]) -> Result<Vec<ViewSet>> {
    given
        .iter()
        .map(|&ViewArg([y, p, hfov])| {
            let table = if hfov > lut_core::LUT_SWITCH_HFOV {
                TableKind::Wide
            } else {
                TableKind::High
            };
            Ok(ViewSet {
                table,
                hfov,
                views: views(&[(y, p)], hfov)?,
                given: Some([y, p, hfov]),
            })
        })
        .collect()
}

/// The fixed (yaw, pitch) views of every set: center, the ±180° seam, two oblique, near
/// a pole. The minification set uses them too.
const FIXED: [(f64, f64); 5] = [
    (0.0, 0.0),
    (180.0, 0.0),
    (37.5, 25.0),
    (-100.0, -45.0),
    (60.0, 80.0),
];

/// What `full` adds: the zenith, near-nadir and two more.
const FULL_EXTRA: [(f64, f64); 4] = [(0.0, 90.0), (-150.0, -89.9), (123.4, 60.0), (270.2, -10.0)];

/// Views at (yaw, pitch) with one hfov.
fn views(at: &[(f64, f64)], hfov: f64) -> Result<Vec<View>> {
    at.iter()
        .map(|&(y, p)| View::new(y, p, hfov).map_err(|e| anyhow!("bench view: {e}")))
        .collect()
}

/// The fixed, documented view sets. Each has the fixed views (`FIXED`; `full` adds
/// `FULL_EXTRA`) and a pan at pitch 10° (yaw advancing by 360°/n, offset 3.7° so no
/// frame is axis-aligned). The wide table's set is at hfov 90°, the high table's at hfov
/// 50° (its natural range, < 60°; forcing the high table at 90° would make the pixels
/// beyond it exact).
pub fn view_sets(which: ViewsArg) -> Result<Vec<ViewSet>> {
    let mut at: Vec<(f64, f64)> = FIXED.to_vec();
    let pan_frames = match which {
        ViewsArg::Quick => 8,
        ViewsArg::Full => {
            at.extend(FULL_EXTRA);
            24
        }
    };
    at.extend((0..pan_frames).map(|k| (3.7 + k as f64 * 360.0 / pan_frames as f64, 10.0)));
    [(TableKind::Wide, 90.0), (TableKind::High, 50.0)]
        .into_iter()
        .map(|(table, hfov)| {
            Ok(ViewSet {
                table,
                hfov,
                views: views(&at, hfov)?,
                given: None,
            })
        })
        .collect()
}

/// One renderer configuration.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Config {
    /// The exact renderer.
    Exact(Sampler),
    /// The LUT renderer with an index step (the set's table, on the cylinder).
    Lut(Sampler, IndexStep),
    /// The LUT renderer on another table surface (plane, diamond), adaptive step.
    LutSurface(Sampler, Surface),
    /// The per-view adaptive grid (`--renderer grid`).
    Grid(Sampler),
    /// A cube renderer on the map converted to a cube.
    Cube(Sampler, CubeRenderer),
    /// A plain gather along precomputed (exact, nearest) indices: the floor for any
    /// table-driven renderer.
    Gather,
}

/// The index steps measured, in report order.
pub const STEPS: [IndexStep; 6] = [
    IndexStep::Fixed(1),
    IndexStep::Fixed(2),
    IndexStep::Fixed(4),
    IndexStep::Fixed(8),
    IndexStep::Fixed(16),
    IndexStep::Adaptive,
];

/// The samplers measured (also the exact images each view is compared with).
pub const SAMPLERS: [Sampler; 2] = [Sampler::Nearest, Sampler::Bilinear];

/// The table surfaces measured beside the cylinder (adaptive step).
pub const OTHER_SURFACES: [Surface; 2] = [Surface::Plane, Surface::Diamond];

/// Every configuration, in report order: exact, LUT (sampler × step), LUT on the other
/// surfaces (sampler × surface), the grid (per sampler), the cube renderers (when
/// `cube`), the gather.
pub fn configs(cube: bool) -> Vec<Config> {
    let mut v: Vec<Config> = SAMPLERS.iter().map(|&s| Config::Exact(s)).collect();
    for s in SAMPLERS {
        for st in STEPS {
            v.push(Config::Lut(s, st));
        }
    }
    for s in SAMPLERS {
        for surface in OTHER_SURFACES {
            v.push(Config::LutSurface(s, surface));
        }
    }
    for s in SAMPLERS {
        v.push(Config::Grid(s));
    }
    if cube {
        for s in SAMPLERS {
            for r in CubeRenderer::ALL {
                v.push(Config::Cube(s, *r));
            }
        }
    }
    v.push(Config::Gather);
    v
}

/// The LUT choice that forces `table`.
pub fn lut_choice(table: TableKind) -> LutChoice {
    match table {
        TableKind::Wide => LutChoice::Wide,
        TableKind::High => LutChoice::High,
    }
}

/// Render options of a configuration whose sampling positions are measured (LUT, LUT
/// on another surface, grid), on the set's table; `None` for the others.
pub fn position_opts(cfg: Config, table: TableKind) -> Option<RenderOptions> {
    match cfg {
        Config::Lut(s, st) => Some(lut_opts(s, st, table)),
        Config::LutSurface(s, surface) => Some(RenderOptions {
            surface,
            ..lut_opts(s, IndexStep::Adaptive, table)
        }),
        Config::Grid(s) => Some(RenderOptions {
            renderer: RendererKind::Grid,
            sampler: s,
            ..RenderOptions::default()
        }),
        _ => None,
    }
}

/// Render options of a LUT configuration on the set's table.
pub fn lut_opts(sampler: Sampler, step: IndexStep, table: TableKind) -> RenderOptions {
    RenderOptions {
        renderer: RendererKind::Lut,
        sampler,
        index_step: step,
        lut: lut_choice(table),
        surface: Surface::Cylinder,
        threads: true,
        ..RenderOptions::default()
    }
}

impl Config {
    /// The sampler; the gather samples the nearest pixel.
    pub fn sampler(self) -> Sampler {
        match self {
            Config::Exact(s)
            | Config::Lut(s, _)
            | Config::LutSurface(s, _)
            | Config::Grid(s)
            | Config::Cube(s, _) => s,
            Config::Gather => Sampler::Nearest,
        }
    }

    /// The same configuration with the nearest sampler (positions do not depend on the
    /// sampler: they are measured once, on the nearest twin).
    pub fn nearest_twin(self) -> Config {
        match self {
            Config::Lut(_, st) => Config::Lut(Sampler::Nearest, st),
            Config::LutSurface(_, surface) => Config::LutSurface(Sampler::Nearest, surface),
            Config::Grid(_) => Config::Grid(Sampler::Nearest),
            c => c,
        }
    }

    /// The report's `surface` field: the table surface of LUT configurations.
    pub fn surface(self) -> Option<&'static str> {
        match self {
            Config::Lut(..) => Some(Surface::Cylinder.name()),
            Config::LutSurface(_, surface) => Some(surface.name()),
            _ => None,
        }
    }

    /// The report's `renderer` field.
    pub fn renderer_name(self) -> &'static str {
        match self {
            Config::Exact(_) => RendererKind::Exact.name(),
            Config::Lut(..) | Config::LutSurface(..) => RendererKind::Lut.name(),
            Config::Grid(_) => RendererKind::Grid.name(),
            Config::Cube(_, CubeRenderer::Basic) => "cube-basic",
            Config::Cube(_, CubeRenderer::Accelerated) => "cube-scanline",
            Config::Gather => "gather",
        }
    }

    /// The report's `index_step` (a number, "adaptive", or null) and `lut` ("wide",
    /// "high" or null): LUT configurations only.
    pub fn lut_fields(self, table: TableKind) -> (serde_json::Value, Option<&'static str>) {
        match self {
            Config::Lut(_, st) => (step_json(st), Some(lut_choice(table).name())),
            Config::LutSurface(..) => (
                step_json(IndexStep::Adaptive),
                Some(lut_choice(table).name()),
            ),
            _ => (serde_json::Value::Null, None),
        }
    }
}

/// An index step as the report writes it: a number, or "adaptive".
pub fn step_json(step: IndexStep) -> serde_json::Value {
    match step {
        IndexStep::Fixed(n) => serde_json::json!(n),
        IndexStep::Adaptive => serde_json::json!("adaptive"),
    }
}

/// The minification set's hfov: zoomed out, so one screen pixel covers several map pixels.
pub const MINIFY_HFOV: f64 = 120.0;

/// The minification set's views: the fixed views at [`MINIFY_HFOV`].
pub fn minify_views() -> Result<Vec<View>> {
    views(&FIXED, MINIFY_HFOV)
}

/// The minification set's output size: a third of the bench's.
pub fn minify_size(size: (u32, u32)) -> (u32, u32) {
    ((size.0 / 3).max(1), (size.1 / 3).max(1))
}

/// The minification set's configurations: LUT (adaptive step, wide table) and exact.
pub const MINIFY_CONFIGS: [(RendererKind, Sampler); 5] = [
    (RendererKind::Lut, Sampler::Nearest),
    (RendererKind::Lut, Sampler::Bilinear),
    (RendererKind::Lut, Sampler::Trilinear),
    (RendererKind::Exact, Sampler::Bilinear),
    (RendererKind::Exact, Sampler::Trilinear),
];

/// Render options of a minification configuration.
pub fn minify_opts(renderer: RendererKind, sampler: Sampler) -> RenderOptions {
    RenderOptions {
        renderer,
        sampler,
        index_step: IndexStep::Adaptive,
        lut: LutChoice::Wide,
        ..RenderOptions::default()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn view_sets_are_the_documented_ones() {
        let quick = view_sets(ViewsArg::Quick).unwrap();
        let full = view_sets(ViewsArg::Full).unwrap();
        for (sets, n) in [(&quick, 5 + 8), (&full, 9 + 24)] {
            assert_eq!(sets.len(), 2);
            assert_eq!((sets[0].table, sets[0].hfov), (TableKind::Wide, 90.0));
            assert_eq!((sets[1].table, sets[1].hfov), (TableKind::High, 50.0));
            for s in sets.iter() {
                assert_eq!(s.views.len(), n);
                assert!(s.views.iter().all(|v| v.hfov_deg() == s.hfov));
            }
        }
        // The pan: pitch 10, yaw 3.7 + k·360/n, no frame axis-aligned.
        let pan = &quick[0].views[5..];
        assert!(pan.iter().all(|v| v.pitch_deg() == 10.0));
        assert!((pan[1].yaw_deg() - (3.7 + 45.0)).abs() < 1e-9);
        // full starts with quick's fixed views.
        assert_eq!(full[0].views[..5], quick[0].views[..5]);
    }

    #[test]
    fn given_views_parse_and_make_one_set_each() {
        assert_eq!(parse_view("30,90,90"), Ok(ViewArg([30.0, 90.0, 90.0])));
        assert_eq!(
            parse_view(" -10.5, -45 ,150"),
            Ok(ViewArg([-10.5, -45.0, 150.0]))
        );
        for bad in [
            "30,90",
            "30,90,90,1",
            "a,0,90",
            "0,nan,90",
            "0,91,90",
            "0,0,0",
            "",
        ] {
            let e = parse_view(bad).unwrap_err();
            assert!(e.contains(&format!("'{bad}'")), "{e}");
            assert!(!e.contains('\n'), "{e}");
        }
        let sets =
            given_view_sets(&[ViewArg([30.0, 90.0, 90.0]), ViewArg([0.0, 0.0, 50.0])]).unwrap();
        assert_eq!(sets.len(), 2);
        assert_eq!((sets[0].table, sets[0].hfov), (TableKind::Wide, 90.0));
        assert_eq!(sets[0].given, Some([30.0, 90.0, 90.0]));
        assert_eq!(sets[0].views.len(), 1);
        assert_eq!(sets[0].views[0].pitch_deg(), 90.0);
        assert_eq!(sets[1].table, TableKind::High);
    }

    #[test]
    fn configurations_in_report_order() {
        let with = configs(true);
        let without = configs(false);
        assert_eq!(with.len(), 2 + 2 * 6 + 2 * 2 + 2 + 2 * 2 + 1);
        assert_eq!(without.len(), 2 + 2 * 6 + 2 * 2 + 2 + 1);
        assert_eq!(with[0], Config::Exact(Sampler::Nearest));
        assert_eq!(with[2], Config::Lut(Sampler::Nearest, IndexStep::Fixed(1)));
        assert_eq!(with[7], Config::Lut(Sampler::Nearest, IndexStep::Adaptive));
        assert_eq!(
            with[14..20],
            [
                Config::LutSurface(Sampler::Nearest, Surface::Plane),
                Config::LutSurface(Sampler::Nearest, Surface::Diamond),
                Config::LutSurface(Sampler::Bilinear, Surface::Plane),
                Config::LutSurface(Sampler::Bilinear, Surface::Diamond),
                Config::Grid(Sampler::Nearest),
                Config::Grid(Sampler::Bilinear),
            ]
        );
        assert_eq!(*with.last().unwrap(), Config::Gather);
        assert!(!without.iter().any(|c| matches!(c, Config::Cube(..))));
        let names: Vec<&str> = with[20..24].iter().map(|c| c.renderer_name()).collect();
        assert_eq!(
            names,
            ["cube-basic", "cube-scanline", "cube-basic", "cube-scanline"]
        );
        assert_eq!(with[18].renderer_name(), "grid");
        assert_eq!(with[17].renderer_name(), "lut");
        assert_eq!(with[17].surface(), Some("diamond"));
        assert_eq!(with[7].surface(), Some("cylinder"));
        assert_eq!(with[19].surface(), None);
        assert_eq!(with[19].nearest_twin(), Config::Grid(Sampler::Nearest));
        let o = position_opts(with[17], TableKind::High).unwrap();
        assert_eq!(
            (o.surface, o.lut, o.index_step),
            (Surface::Diamond, LutChoice::High, IndexStep::Adaptive)
        );
        assert_eq!(
            position_opts(with[18], TableKind::Wide).unwrap().renderer,
            RendererKind::Grid
        );
        assert_eq!(position_opts(with[0], TableKind::Wide), None);
    }

    #[test]
    fn report_fields_of_a_configuration() {
        let lut = Config::Lut(Sampler::Bilinear, IndexStep::Fixed(8));
        assert_eq!(lut.renderer_name(), "lut");
        assert_eq!(
            lut.lut_fields(TableKind::High),
            (serde_json::json!(8), Some("high"))
        );
        let adaptive = Config::Lut(Sampler::Nearest, IndexStep::Adaptive);
        assert_eq!(
            adaptive.lut_fields(TableKind::Wide),
            (serde_json::json!("adaptive"), Some("wide"))
        );
        assert_eq!(
            Config::Exact(Sampler::Nearest).lut_fields(TableKind::Wide),
            (serde_json::Value::Null, None)
        );
        assert_eq!(Config::Gather.sampler(), Sampler::Nearest);
        assert_eq!(Config::Gather.renderer_name(), "gather");
        let o = lut_opts(Sampler::Nearest, IndexStep::Fixed(2), TableKind::High);
        assert_eq!(
            (o.lut, o.index_step),
            (LutChoice::High, IndexStep::Fixed(2))
        );
    }

    #[test]
    fn minification_set() {
        let v = minify_views().unwrap();
        assert_eq!(v.len(), FIXED.len());
        assert!(v.iter().all(|v| v.hfov_deg() == MINIFY_HFOV));
        assert_eq!(minify_size((1920, 1080)), (640, 360));
        assert_eq!(minify_size((2, 2)), (1, 1));
        let o = minify_opts(RendererKind::Exact, Sampler::Trilinear);
        assert_eq!(
            (o.lut, o.index_step),
            (LutChoice::Wide, IndexStep::Adaptive)
        );
    }
}
