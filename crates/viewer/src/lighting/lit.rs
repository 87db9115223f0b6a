//! Lighting frames from the illuminance map: the map of the current luminaires is built
//! once per lighting change ([`LitCache`]), every frame then samples it (rendered and lit
//! in one pass, [`LightsState::render_lit`]: each band of rows lit by
//! [`lut_core::FrameShader`] as soon as it is drawn), and the automatic exposure is set
//! from it.
//! In the window a change first builds a coarse map ([`lut_core::MapOptions::preview`],
//! immediate feedback while a value is dragged), refined on the next frame; there the
//! inter-reflections are never solved on the UI thread: the map takes the last solve
//! handed in from the solving thread ([`LitCache::set_indirect`], see [`super::Solver`])
//! when it is for these luminaires, or one of the same room and reflectances while the
//! fresh one is on its way, else the direct light; a solve that arrives rebuilds the map.

use super::state::{LightsKey, LightsState};
use crate::scene::render_scene_lit;
use lut_core::{
    Camera, IlluminanceMap, LightScene, MapOptions, Radiosity, RenderOptions, RenderReport, View,
};
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
    /// The scene the map was built from (the lux at the cursor reads it).
    scene: Option<LightScene>,
    /// The last inter-reflections solved off the UI thread, and what for.
    indirect: Option<(LightsKey, Arc<Radiosity>)>,
    /// The solve the map was built with (its address; 0 for none).
    built_with: usize,
}

impl LitCache {
    /// The map for `st`, rebuilt when its luminaires or room changed: with `progressive`
    /// a change first gets the coarse preview map and the next call the full one. Each
    /// new map sets the automatic exposure ([`LightsState::apply_auto_exposure`]).
    /// `None` with no luminaire.
    ///
    /// # Errors
    /// A room or luminaire the map cannot be built for (a light outside the room).
    ///
    /// With `progressive` (the window) the inter-reflections are not solved here: the
    /// map takes the solve handed in ([`LitCache::set_indirect`]) for these luminaires,
    /// else one of the same room and reflectances, else none (direct light), and is
    /// rebuilt when a different solve is handed in. Without (`viewer render`) the scene
    /// is solved here ([`LightsState::scene`]).
    pub fn update(
        &mut self,
        st: &mut LightsState,
        progressive: bool,
    ) -> Result<Option<Arc<IlluminanceMap>>, String> {
        let key = st.geometry_key();
        let solved = if progressive && st.indirect {
            self.indirect
                .as_ref()
                .filter(|(k, _)| *k == key || k.same_room(&key))
                .map(|(_, r)| r.clone())
        } else {
            None
        };
        let with = solved.as_ref().map_or(0, |r| Arc::as_ptr(r) as usize);
        let moved = self.key.as_ref() != Some(&key);
        let changed = moved || (progressive && with != self.built_with);
        if !changed && !self.coarse {
            return Ok(self.map.clone());
        }
        let coarse = moved && progressive;
        self.key = Some(key);
        self.map = None;
        self.scene = None;
        self.coarse = false;
        self.built_with = with;
        self.generation += 1;
        let scene = if progressive {
            match (st.direct_scene()?, solved) {
                (None, _) => None,
                (Some(s), Some(r)) => Some(s.with_radiosity(r)),
                (Some(s), None) => Some(s),
            }
        } else {
            st.scene()?
        };
        let Some(scene) = scene else {
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
        self.scene = Some(scene);
        self.coarse = coarse;
        Ok(Some(map))
    }

    /// Hand in the inter-reflections solved for `key` (`None`: nothing to add, every
    /// reflectance 0 or inter-reflections off); the next [`LitCache::update`] rebuilds
    /// the map with them when they are for its luminaires or room.
    pub fn set_indirect(&mut self, key: LightsKey, radiosity: Option<Arc<Radiosity>>) {
        self.indirect = radiosity.map(|r| (key, r));
    }

    /// The scene the current map was built from (with the inter-reflections it was
    /// built with), `None` without a map.
    pub fn scene(&self) -> Option<&LightScene> {
        self.scene.as_ref()
    }

    /// The map was built with the solve handed in for exactly these luminaires (or
    /// needs none): false while a fresh solve is awaited.
    pub fn indirect_current(&self, st: &LightsState) -> bool {
        !st.indirect
            || st.reflectances.is_zero()
            || self.indirect.as_ref().is_some_and(|(k, r)| {
                *k == st.geometry_key() && Arc::as_ptr(r) as usize == self.built_with
            })
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

    /// The window's path (progressive) never solves the inter-reflections itself: with
    /// no solve handed in the map is the direct light; the solve handed in (as the
    /// solving thread does) rebuilds it with the same light as `viewer render`'s scene;
    /// a moved luminaire keeps the old solve of the same room as a stand-in until its
    /// own arrives; a changed room does not.
    #[test]
    fn the_window_path_takes_the_solve_handed_in_and_never_solves() {
        use glam::DVec3;
        let mut st = LightsState {
            room: (6.0, 5.0, 2.8),
            ..LightsState::default()
        };
        st.load_and_add(&lamp()).unwrap();
        assert!(st.indirect);
        let (p, n) = (DVec3::new(0.3, 0.0, 0.2), DVec3::Y);
        let mut c = LitCache::default();
        c.update(&mut st, true).unwrap();
        c.update(&mut st, true).unwrap();
        let direct = st.direct_scene().unwrap().unwrap().direct(p, n);
        assert!(direct > 0.0);
        let s = c.scene().unwrap();
        assert!(s.radiosity().is_none(), "solved on the UI thread");
        assert_eq!(s.illuminance(p, n), direct);
        assert!(!c.indirect_current(&st));
        // The solve arrives.
        let g = c.generation();
        let solved = Arc::new(
            lut_core::Radiosity::solve(&st.direct_scene().unwrap().unwrap(), st.reflectances)
                .unwrap(),
        );
        c.set_indirect(st.geometry_key(), Some(solved));
        c.update(&mut st, true).unwrap();
        assert!(c.generation() > g, "rebuilt with the solve");
        assert!(c.indirect_current(&st));
        let with = c.scene().unwrap().illuminance(p, n);
        let want = st.scene().unwrap().unwrap().illuminance(p, n);
        // The floor under a ceiling light gets a little reflected light (about 1 % here).
        assert!(with > direct * 1.005, "{with} vs direct {direct}");
        assert!((with - want).abs() <= 1e-9 * want, "{with} vs {want}");
        // Unchanged: not rebuilt.
        let g = c.generation();
        c.update(&mut st, true).unwrap();
        assert_eq!(c.generation(), g);
        // A light moved: the same room's solve stands in until the fresh one.
        st.lights[0].position[0] += 0.3;
        c.update(&mut st, true).unwrap();
        assert!(c.scene().unwrap().radiosity().is_some());
        assert!(!c.indirect_current(&st));
        // The room changed: no stand-in.
        st.room.0 += 0.5;
        c.update(&mut st, true).unwrap();
        assert!(c.scene().unwrap().radiosity().is_none());
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
