//! How good each frame is: the render settings the panel chooses ([`Settings`]), the
//! anti-aliasing modes ([`AaMode`]) and the rule that picks a frame's quality
//! ([`choose_level`]). Pure: the measured frame times come in as data, so the rule is
//! unit-tested.
//!
//! **Adaptive** (the default): a moving view keeps full quality whenever the last
//! full-quality frame fit the frame budget ([`FRAME_BUDGET_MS`], scaled to the scene's
//! current size); only when it did not, frames degrade step by step ([`Level`]: nearest
//! sampling, then half and quarter resolution upscaled) to the first level whose last
//! measured time (or, before one exists, an estimate from the full frame) fits. Once the
//! view stops, one full-quality frame is drawn. The patent's three modes stay selectable:
//! **Always** (full quality), **Still only** (nearest sampling while moving), **Off**
//! (nearest always).

use lut_core::{CubeRenderer, IndexStep, LutChoice, Named, RenderOptions, RendererKind, Sampler};

use super::input::DragStyle;

/// A frame should take at most this long to render, milliseconds (60 frames a second).
pub const FRAME_BUDGET_MS: f64 = 16.0;

/// When to spend time on anti-aliasing.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum AaMode {
    /// Full quality while moving when it fits the frame budget; degraded only when not.
    #[default]
    Adaptive,
    /// Always the chosen sampler (trilinear by default) with index interpolation.
    Always,
    /// Nearest sampling while the view turns fast, full quality once it stops.
    StillOnly,
    /// Always nearest sampling.
    Off,
}

/// The labels in the panel, the settings file and the docs.
impl Named for AaMode {
    const ALL: &'static [Self] = &[
        AaMode::Adaptive,
        AaMode::Always,
        AaMode::StillOnly,
        AaMode::Off,
    ];
    fn name(self) -> &'static str {
        match self {
            AaMode::Adaptive => "Adaptive",
            AaMode::Always => "Always",
            AaMode::StillOnly => "Still only",
            AaMode::Off => "Off",
        }
    }
    fn help(self) -> &'static str {
        match self {
            AaMode::Adaptive => {
                "Full quality while moving when the last full frame fit 16 ms; \
                 cheaper frames only when it did not"
            }
            AaMode::Always => "Always the chosen sampler",
            AaMode::StillOnly => {
                "Nearest sampling while the view turns fast, full quality once it stops"
            }
            AaMode::Off => "Always nearest sampling",
        }
    }
}

/// A frame's quality, best first.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub enum Level {
    /// The chosen sampler at full resolution.
    Full,
    /// Nearest sampling at full resolution.
    Nearest,
    /// Nearest sampling at half resolution, upscaled bilinearly.
    Half,
    /// Nearest sampling at quarter resolution, upscaled bilinearly.
    Quarter,
}

impl Level {
    /// Every level, best first.
    pub const ALL: [Level; 4] = [Level::Full, Level::Nearest, Level::Half, Level::Quarter];

    /// The scene is rendered at its size divided by this, then upscaled.
    pub fn scale(self) -> u32 {
        match self {
            Level::Full | Level::Nearest => 1,
            Level::Half => 2,
            Level::Quarter => 4,
        }
    }

    /// The sampler of a frame at this level, given the chosen one.
    pub fn sampler(self, chosen: Sampler) -> Sampler {
        match self {
            Level::Full => chosen,
            Level::Nearest | Level::Half | Level::Quarter => Sampler::Nearest,
        }
    }

    /// The readout's words.
    pub fn label(self) -> &'static str {
        match self {
            Level::Full => "full",
            Level::Nearest => "nearest",
            Level::Half => "half resolution",
            Level::Quarter => "quarter resolution",
        }
    }

    /// Before a level has been measured: its time as a share of a full frame's, from
    /// instruction counts (callgrind) of an 800×500 view of the bundled sample at hfov
    /// 90, one thread: trilinear 64.5 M, nearest 23.3 M, nearest at 400×250 10.0 M and
    /// at 200×125 4.6 M, the bilinear upscale to 800×500 4.6 M (docs/viewer.md).
    fn estimate_share(self) -> f64 {
        match self {
            Level::Full => 1.0,
            Level::Nearest => 0.36,
            Level::Half => 0.23,
            Level::Quarter => 0.14,
        }
    }
}

/// How many recent full-quality frames the budget test looks at (their median: one
/// hiccup of a busy machine does not drop the quality of a whole drag).
pub const FULL_FRAMES_KEPT: usize = 3;

/// The recent measured render times of each level, with the scene size each was
/// measured at, newest last.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct FrameTimes {
    last: [Vec<(f64, u64)>; 4],
}

impl FrameTimes {
    /// Record a frame of `level` that took `ms` for a scene of `pixels`.
    pub fn record(&mut self, level: Level, ms: f64, pixels: u64) {
        if ms.is_finite() && ms >= 0.0 && pixels > 0 {
            let v = &mut self.last[level as usize];
            v.push((ms, pixels));
            if v.len() > FULL_FRAMES_KEPT {
                v.remove(0);
            }
        }
    }

    /// The recent full-quality frames' time (median), scaled to a scene of `pixels`.
    pub fn full_ms(&self, pixels: u64) -> Option<f64> {
        self.expected_ms(Level::Full, pixels)
    }

    /// The median of a level's recent times, each scaled to `pixels`.
    fn median_ms(&self, level: Level, pixels: u64) -> Option<f64> {
        let mut v: Vec<f64> = self.last[level as usize]
            .iter()
            .map(|&(ms, px)| ms * pixels as f64 / px as f64)
            .collect();
        v.sort_by(f64::total_cmp);
        v.get(v.len() / 2).copied()
    }

    /// What a frame of `level` is expected to take for a scene of `pixels`: the median
    /// of its recent times scaled by the pixel count, else the full frame's times its
    /// estimated share; `None` before anything was measured.
    pub fn expected_ms(&self, level: Level, pixels: u64) -> Option<f64> {
        self.median_ms(level, pixels).or_else(|| {
            self.median_ms(Level::Full, pixels)
                .map(|ms| ms * level.estimate_share())
        })
    }
}

/// The quality of a frame: `moving` is true while the view turns fast; `times` are the
/// last measured frames; `pixels` is the scene's size; `budget_ms` the frame budget.
pub fn choose_level(
    mode: AaMode,
    moving: bool,
    times: &FrameTimes,
    pixels: u64,
    budget_ms: f64,
) -> Level {
    match mode {
        AaMode::Always => Level::Full,
        AaMode::Off => Level::Nearest,
        AaMode::StillOnly if moving => Level::Nearest,
        AaMode::StillOnly => Level::Full,
        AaMode::Adaptive if !moving => Level::Full,
        AaMode::Adaptive => Level::ALL
            .into_iter()
            .find(|&l| {
                times
                    .expected_ms(l, pixels)
                    .is_none_or(|ms| ms <= budget_ms)
            })
            .unwrap_or(Level::Quarter),
    }
}

/// The level of a frame ([`choose_level`]) and whether a still view would get a better
/// one: then the frame is degraded by motion and a full-quality frame is due once the
/// view settles.
pub fn frame_level(
    mode: AaMode,
    moving: bool,
    times: &FrameTimes,
    pixels: u64,
    budget_ms: f64,
) -> (Level, bool) {
    let level = choose_level(mode, moving, times, pixels, budget_ms);
    let still = choose_level(mode, false, times, pixels, budget_ms);
    (level, level > still)
}

/// Everything the panel lets the user choose that affects motion or rendering.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Settings {
    /// Drag style.
    pub drag: DragStyle,
    /// Keep turning after a grab drag is released.
    pub inertia: bool,
    /// Anti-aliasing mode.
    pub aa: AaMode,
    /// Sampler of full-quality frames.
    pub sampler: Sampler,
    /// LUT index step.
    pub index_step: IndexStep,
    /// LUT or exact renderer.
    pub renderer: RendererKind,
    /// Which LUT (auto by hfov, or forced).
    pub lut: LutChoice,
    /// Cube maps: the paper's basic (per pixel) or accelerated (per scanline) renderer.
    pub cube_renderer: CubeRenderer,
    /// HDR panoramas (`.hdr`, `.exr`): exposure in stops (`lut_core::Tone`).
    pub exposure_ev: f64,
    /// "Save view…": the export is the scene's size times this (1, 2 or 4).
    pub export_scale: u32,
    /// Partial panoramas: keep the view's edges inside the covered area.
    pub view_limit: bool,
    /// Pannini's parameter d when the Pannini projection is chosen (0: rectilinear).
    pub pannini_d: f64,
    /// Show the error heat map instead of the panorama (the renderer's sampling-position
    /// error against the exact map, `lut_core::ErrorMap`).
    pub heat_map: bool,
}

impl Default for Settings {
    fn default() -> Self {
        let o = RenderOptions::default();
        Settings {
            drag: DragStyle::Grab,
            inertia: true,
            aa: AaMode::default(),
            // Trilinear: bilinear when zoomed in, anti-aliased from the pyramid when
            // zoomed out (built on the loader thread).
            sampler: Sampler::Trilinear,
            index_step: o.index_step,
            renderer: o.renderer,
            lut: o.lut,
            cube_renderer: CubeRenderer::Accelerated,
            exposure_ev: 0.0,
            export_scale: 1,
            view_limit: true,
            pannini_d: lut_core::PANNINI_D_DEFAULT,
            heat_map: false,
        }
    }
}

impl Settings {
    /// The sampler of a frame under the patent's modes: `fast` is true while the view
    /// turns fast (adaptive frames: [`choose_level`] and [`Level::sampler`]).
    pub fn sampler_for(&self, fast: bool) -> Sampler {
        let level = match self.aa {
            AaMode::Always | AaMode::Adaptive => Level::Full,
            AaMode::StillOnly if fast => Level::Nearest,
            AaMode::StillOnly => Level::Full,
            AaMode::Off => Level::Nearest,
        };
        level.sampler(self.sampler)
    }

    /// Render options of a frame of a map or a cube map at `level` (the same options
    /// `viewer render` takes).
    pub fn render_options(&self, level: Level) -> RenderOptions {
        RenderOptions {
            renderer: self.renderer,
            sampler: level.sampler(self.sampler),
            index_step: self.index_step,
            lut: self.lut,
            threads: true,
            cube: self.cube_renderer,
            ..RenderOptions::default()
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const PX: u64 = 800 * 500;

    #[test]
    fn adaptive_keeps_full_quality_while_the_full_frame_fits() {
        let mut t = FrameTimes::default();
        let pick = |t: &FrameTimes, moving| choose_level(AaMode::Adaptive, moving, t, PX, 16.0);
        // Nothing measured yet: try full quality (the first frame measures it).
        assert_eq!(pick(&t, true), Level::Full);
        t.record(Level::Full, 7.0, PX);
        assert_eq!(pick(&t, true), Level::Full, "7 ms fits 16 ms");
        t.record(Level::Full, 16.0, PX);
        t.record(Level::Full, 16.0, PX);
        assert_eq!(pick(&t, true), Level::Full, "exactly the budget fits");
        // One slow frame among fast ones (a busy machine) does not drop the quality.
        t.record(Level::Full, 7.0, PX);
        t.record(Level::Full, 7.0, PX);
        t.record(Level::Full, 60.0, PX);
        assert_eq!(pick(&t, true), Level::Full, "median of 7, 7, 60");
        // Still: always full, however slow.
        t.record(Level::Full, 100.0, PX);
        assert_eq!(pick(&t, false), Level::Full);
    }

    #[test]
    fn adaptive_degrades_step_by_step_only_when_the_full_frame_did_not_fit() {
        let mut t = FrameTimes::default();
        let pick = |t: &FrameTimes| choose_level(AaMode::Adaptive, true, t, PX, 16.0);
        // 20 ms full frames: nearest is estimated at 7.2 ms.
        t.record(Level::Full, 20.0, PX);
        assert_eq!(pick(&t), Level::Nearest);
        // Measured nearest too slow: half resolution (estimated 4.6 ms).
        t.record(Level::Nearest, 17.0, PX);
        assert_eq!(pick(&t), Level::Half);
        // Everything too slow: the cheapest.
        t.record(Level::Half, 30.0, PX);
        t.record(Level::Quarter, 30.0, PX);
        assert_eq!(pick(&t), Level::Quarter);
        // Full frames that fit (the still frames after motion) bring full quality back.
        t.record(Level::Full, 9.0, PX);
        t.record(Level::Full, 9.0, PX);
        assert_eq!(pick(&t), Level::Full);
    }

    #[test]
    fn times_scale_with_the_scene_size() {
        let mut t = FrameTimes::default();
        t.record(Level::Full, 10.0, PX);
        assert_eq!(t.full_ms(PX * 2), Some(20.0));
        let close = |a: Option<f64>, b: f64| a.is_some_and(|a| (a - b).abs() < 1e-9);
        assert!(close(t.expected_ms(Level::Half, PX), 2.3));
        // The same 10 ms full frame does not fit a window twice the size.
        assert_eq!(
            choose_level(AaMode::Adaptive, true, &t, PX * 2, 16.0),
            Level::Nearest
        );
        // Nonsense is not recorded.
        t.record(Level::Nearest, f64::NAN, PX);
        t.record(Level::Nearest, 1.0, 0);
        assert!(close(t.expected_ms(Level::Nearest, PX), 3.6));
    }

    #[test]
    fn the_patents_three_modes_ignore_the_times() {
        let mut slow = FrameTimes::default();
        slow.record(Level::Full, 500.0, PX);
        let fast = FrameTimes::default();
        for t in [&slow, &fast] {
            for moving in [false, true] {
                assert_eq!(
                    choose_level(AaMode::Always, moving, t, PX, 16.0),
                    Level::Full
                );
                assert_eq!(
                    choose_level(AaMode::Off, moving, t, PX, 16.0),
                    Level::Nearest
                );
            }
            assert_eq!(
                choose_level(AaMode::StillOnly, true, t, PX, 16.0),
                Level::Nearest
            );
            assert_eq!(
                choose_level(AaMode::StillOnly, false, t, PX, 16.0),
                Level::Full
            );
        }
    }

    #[test]
    fn levels_samplers_and_options() {
        let s = Settings::default();
        assert_eq!(s.aa, AaMode::Adaptive, "the default mode");
        assert_eq!(s.render_options(Level::Full).sampler, Sampler::Trilinear);
        assert_eq!(s.render_options(Level::Nearest).sampler, Sampler::Nearest);
        assert_eq!(s.render_options(Level::Half).sampler, Sampler::Nearest);
        assert_eq!(Level::Quarter.scale(), 4);
        let still = Settings {
            aa: AaMode::StillOnly,
            ..s
        };
        assert_eq!(still.sampler_for(true), Sampler::Nearest);
        assert_eq!(still.sampler_for(false), Sampler::Trilinear);
        let names: Vec<&str> = AaMode::ALL.iter().map(|m| m.name()).collect();
        assert_eq!(names, ["Adaptive", "Always", "Still only", "Off"]);
    }
}
