//! Lighting frames from the illuminance map: the map of the current luminaires is built
//! once per lighting change ([`LitCache`]), every frame then samples it (rendered and lit
//! in one pass, [`LightsState::render_lit`]: each band of rows lit by
//! [`lut_core::FrameShader`] as soon as it is drawn), and the automatic exposure is set
//! from it.
//! In the window a change first builds a coarse map ([`lut_core::MapOptions::preview`],
//! immediate feedback while a value is dragged), refined on the next frame.

use super::state::{LightsKey, LightsState};
use crate::scene::render_scene_lit;
use lut_core::{Camera, IlluminanceMap, MapOptions, RenderOptions, RenderReport, View};
use std::sync::Arc;

/// The illuminance map of a [`LightsState`]'s luminaires, kept until they change.
#[derive(Debug, Default)]
pub struct LitCache {
    /// What the map was built from (the luminaires and room, not the shading).
    key: Option<LightsKey>,
    map: Option<Arc<IlluminanceMap>>,
    /// The map is the coarse preview: the next update refines it.
    coarse: bool,
    /// Counts the maps built (a lit frame depends on it).
    generation: u64,
}

impl LitCache {
    /// The map for `st`, rebuilt when its luminaires or room changed: with `progressive`
    /// a change first gets the coarse preview map and the next call the full one. Each
    /// new map sets the automatic exposure ([`LightsState::apply_auto_exposure`]).
    /// `None` with no luminaire.
    ///
    /// # Errors
    /// A room or luminaire the map cannot be built for (a light outside the room).
    pub fn update(
        &mut self,
        st: &mut LightsState,
        progressive: bool,
    ) -> Result<Option<Arc<IlluminanceMap>>, String> {
        let key = st.geometry_key();
        let changed = self.key.as_ref() != Some(&key);
        if !changed && !self.coarse {
            return Ok(self.map.clone());
        }
        let coarse = changed && progressive;
        self.key = Some(key);
        self.map = None;
        self.coarse = false;
        self.generation += 1;
        let Some(scene) = st.scene()? else {
            return Ok(None);
        };
        let opts = if coarse {
            MapOptions::preview()
        } else {
            MapOptions::default()
        };
        let map = Arc::new(IlluminanceMap::build(&scene, &opts).map_err(|e| e.to_string())?);
        st.apply_auto_exposure(&map);
        self.map = Some(map.clone());
        self.coarse = coarse;
        Ok(Some(map))
    }

    /// A coarse map waits to be refined (the window asks for another frame).
    pub fn refining(&self) -> bool {
        self.coarse && self.map.is_some()
    }

    /// Changes whenever a new map is built.
    pub fn generation(&self) -> u64 {
        self.generation
    }

    /// The current map's memory in bytes (0 without one).
    pub fn bytes(&self) -> usize {
        self.map.as_ref().map_or(0, |m| m.bytes())
    }
}

/// Why [`LightsState::render_lit`] failed.
#[derive(Debug)]
pub enum LitRenderError {
    /// The lights: a room or luminaire the map cannot be built for, or bad shading
    /// options (nothing was rendered).
    Lights(String),
    /// The render itself.
    Render(lut_core::ViewError),
}

impl std::fmt::Display for LitRenderError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            LitRenderError::Lights(e) => f.write_str(e),
            LitRenderError::Render(e) => write!(f, "render failed: {e}"),
        }
    }
}

impl std::error::Error for LitRenderError {}

impl LightsState {
    /// Render `view` of `pano` into `frame` (`width × height`), lit from the
    /// illuminance map in `cache` (updated first, see [`LitCache::update`]) as the rows
    /// are drawn ([`render_scene_lit`]); unlit with no luminaire. The pixels are those
    /// of rendering, then [`LightsState::light_frame_with`].
    ///
    /// # Errors
    /// [`LitRenderError::Lights`] as [`LightsState::light_frame_with`] (before rendering),
    /// [`LitRenderError::Render`] as [`crate::scene::render_scene`].
    #[allow(clippy::too_many_arguments)]
    pub fn render_lit(
        &mut self,
        cache: &mut LitCache,
        progressive: bool,
        pano: &mut lut_core::Panorama,
        view: View,
        opts: &RenderOptions,
        frame: &mut [u32],
        (width, height): (u32, u32),
    ) -> Result<RenderReport, LitRenderError> {
        let map = cache
            .update(self, progressive)
            .map_err(LitRenderError::Lights)?;
        let cam = Camera::new(view, width, height);
        let shader = match &map {
            Some(m) => Some(
                m.frame_shader(&cam, &self.shade_options())
                    .map_err(|e| LitRenderError::Lights(e.to_string()))?,
            ),
            None => None,
        };
        render_scene_lit(pano, view, opts, frame, width, height, shader.as_ref())
            .map_err(LitRenderError::Render)
    }

    /// Light a rendered `width × height` frame of `view` in place from the illuminance
    /// map in `cache` (updated first, see [`LitCache::update`]); a no-op with no
    /// luminaire.
    ///
    /// # Errors
    /// As [`LightsState::scene`], or a frame that is not `width × height`.
    pub fn light_frame_with(
        &mut self,
        cache: &mut LitCache,
        progressive: bool,
        view: View,
        frame: &mut [u32],
        width: u32,
        height: u32,
    ) -> Result<(), String> {
        let Some(map) = cache.update(self, progressive)? else {
            return Ok(());
        };
        let cam = Camera::new(view, width, height);
        map.shade_frame(&cam, frame, width, height, &self.shade_options())
            .map_err(|e| e.to_string())
    }

    /// [`LightsState::light_frame_with`] with a map built for this one frame (the full
    /// map: what `viewer render` does).
    ///
    /// # Errors
    /// As [`LightsState::light_frame_with`].
    pub fn light_frame(
        &mut self,
        view: View,
        frame: &mut [u32],
        width: u32,
        height: u32,
    ) -> Result<(), String> {
        self.light_frame_with(&mut LitCache::default(), false, view, frame, width, height)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::path::Path;

    fn lamp() -> std::path::PathBuf {
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../../tests/data/ies/label_lines.ies")
    }

    #[test]
    fn built_once_per_change_coarse_then_fine() {
        let mut st = LightsState::default();
        st.load_and_add(&lamp()).unwrap();
        let mut c = LitCache::default();
        let a = c.update(&mut st, true).unwrap().unwrap();
        assert!(c.refining());
        let g = c.generation();
        let b = c.update(&mut st, true).unwrap().unwrap();
        assert!(!c.refining() && c.generation() == g + 1);
        assert!(b.nodes() > a.nodes(), "{} {}", b.nodes(), a.nodes());
        // Unchanged: the same map; a shading change does not rebuild it.
        st.exposure_lux *= 2.0;
        st.false_color = true;
        let c2 = c.update(&mut st, true).unwrap().unwrap();
        assert!(Arc::ptr_eq(&b, &c2) && c.generation() == g + 1);
        // A light moved: rebuilt.
        st.lights[0].position[0] += 0.1;
        c.update(&mut st, false).unwrap();
        assert!(!c.refining() && c.generation() == g + 2);
        // No light: no map.
        st.lights.clear();
        assert!(c.update(&mut st, true).unwrap().is_none());
        assert_eq!(c.bytes(), 0);
    }

    #[test]
    fn auto_exposure_follows_the_lights() {
        let mut st = LightsState {
            auto_exposure: true,
            ..LightsState::default()
        };
        st.load_and_add(&lamp()).unwrap();
        let mut c = LitCache::default();
        c.update(&mut st, false).unwrap();
        let one = st.exposure_lux;
        st.lights[0].multiplier = 10.0;
        c.update(&mut st, false).unwrap();
        assert!(
            (st.exposure_lux / one - 10.0).abs() < 1e-6,
            "{one} {}",
            st.exposure_lux
        );
    }

    /// Issue 33 (5): a luminaire added to a scene whose exposure is fixed (a scene file's,
    /// here 1 lx) would leave most of the room above the exposure (white); after
    /// `lights_added` the exposure follows the lights and at most 5 % of the room's
    /// surface is above it.
    #[test]
    fn a_light_added_at_a_fixed_exposure_keeps_the_picture_readable() {
        let mut st = LightsState {
            auto_exposure: false,
            exposure_lux: 1.0,
            ..LightsState::default()
        };
        assert_eq!(st.lights_added(), None, "no light: nothing to do");
        st.load_and_add(&lamp()).unwrap();
        st.lights[0].multiplier = 50.0;
        let mut fixed = st.clone();
        let map = LitCache::default()
            .update(&mut fixed, false)
            .unwrap()
            .unwrap();
        assert_eq!(fixed.exposure_lux, 1.0, "fixed: not followed");
        assert!(
            map.quantile(0.5) > fixed.exposure_lux,
            "the test's light must blow out half the room at the fixed exposure: {} lx",
            map.quantile(0.5)
        );
        let notice = st.lights_added().expect("a notice");
        assert!(
            notice.contains("automatic") && notice.contains("1 lx"),
            "{notice}"
        );
        assert!(st.auto_exposure);
        let map = LitCache::default().update(&mut st, false).unwrap().unwrap();
        let above = map.quantile(crate::lighting::state::AUTO_EXPOSURE_QUANTILE);
        assert!(
            st.exposure_lux >= above * (1.0 - 1e-9),
            "exposure {} lx below the 95 % quantile {above} lx",
            st.exposure_lux
        );
        assert_eq!(st.lights_added(), None, "said once");
    }
}
