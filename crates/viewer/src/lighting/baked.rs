//! The lit panorama in the window: once the lighting has settled, the panorama is lit once
//! ([`lut_core::IlluminanceMap::bake_map`] / `bake_cube`) and from then on panned like an
//! unlit one, at an unlit frame's cost.
//!
//! While the lighting changes (a light or the room dragged, a slider moving, the coarse
//! preview map shown) frames are lit one by one from the illuminance map, so each change
//! shows at once. The lighting has settled when the full map is built, nothing is being
//! dragged, and the map and shading options are the same as on the frame before: then the
//! copy is baked. Exposure, ambient and false-colour changes bake again from the same
//! map. Panoramas whose lit copy would exceed [`lut_core::BAKE_MAX_BYTES`] keep the
//! per-frame lighting.

use crate::scene::{Scene, SceneRef};
use lut_core::{
    lit_cube_bytes, lit_map_bytes, CubeMap, EnvMap, IlluminanceMap, ShadeOptions, BAKE_MAX_BYTES,
};
use std::time::Instant;

/// What a lit copy was baked from.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BakeKey {
    /// The illuminance map's generation ([`super::LitCache::generation`]).
    pub map_generation: u64,
    /// The panorama's generation (a new file, or the same one reloaded).
    pub scene_generation: u64,
    /// How E turns into colour.
    pub shade: ShadeOptions,
}

/// A lit copy of the panorama.
enum LitCopy {
    Map(EnvMap),
    Cube(CubeMap),
}

/// Where the lit panorama stands (the lights panel shows it).
#[derive(Debug, Clone, PartialEq, Default)]
pub enum BakeState {
    /// No luminaire: nothing to bake.
    #[default]
    Off,
    /// The lighting is changing: frames are lit one by one.
    Changing,
    /// Baked: frames pan the lit copy.
    Baked {
        /// Its memory (the copy and its pyramid).
        bytes: usize,
        /// How long the bake took.
        ms: f64,
    },
    /// Too large to bake: frames are lit one by one.
    TooLarge {
        /// The memory the copy would take.
        bytes: usize,
    },
    /// The bake failed (bad shading options): frames are lit one by one.
    Failed(String),
}

impl BakeState {
    /// One line for the lights panel.
    pub fn describe(&self) -> String {
        let mib = |b: usize| b as f64 / f64::from(1 << 20);
        match self {
            BakeState::Off => String::new(),
            BakeState::Changing => "lit panorama: lighting changing, each frame lit".into(),
            BakeState::Baked { bytes, ms } => {
                format!("lit panorama: {:.0} MiB, baked in {ms:.0} ms", mib(*bytes))
            }
            BakeState::TooLarge { bytes } => format!(
                "lit panorama: would take {:.0} MiB (over {} MiB), each frame lit",
                mib(*bytes),
                BAKE_MAX_BYTES >> 20
            ),
            BakeState::Failed(e) => format!("lit panorama: {e}"),
        }
    }
}

/// The lit copy of the current panorama, baked once the lighting has settled.
#[derive(Default)]
pub struct LitPanorama {
    /// The key of the previous frame.
    seen: Option<BakeKey>,
    /// The key the copy (or the decision not to bake) is for.
    key: Option<BakeKey>,
    copy: Option<LitCopy>,
    state: BakeState,
    /// The lighting was settled on the last update (a bake is due on the next frame when
    /// it is [`BakeState::Changing`]).
    settled: bool,
}

impl LitPanorama {
    /// Update for this frame: `key` is the current lighting (`None` without luminaires),
    /// `settled` whether nothing is being dragged and the full map is built, `map` the
    /// illuminance map and `scene` the panorama. Bakes when the lighting has been the
    /// same since the frame before and is settled; drops the copy as soon as the
    /// lighting differs from it. True when frames should pan the lit copy
    /// ([`LitPanorama::scene_ref`]).
    pub fn update(
        &mut self,
        key: Option<BakeKey>,
        settled: bool,
        map: Option<&IlluminanceMap>,
        scene: &Scene,
    ) -> bool {
        let (Some(key), Some(map)) = (key, map) else {
            *self = LitPanorama::default();
            return false;
        };
        self.settled = settled;
        if self.key == Some(key) {
            return self.copy.is_some();
        }
        // Lit for other lighting: of no use any more.
        self.copy = None;
        self.key = None;
        let stable = self.seen == Some(key);
        self.seen = Some(key);
        if !(stable && settled) {
            self.state = BakeState::Changing;
            return false;
        }
        self.key = Some(key);
        let bytes = match scene {
            Scene::Map { map, .. } => lit_map_bytes(map),
            Scene::Cube(cube) => lit_cube_bytes(cube),
        };
        if bytes > BAKE_MAX_BYTES {
            self.state = BakeState::TooLarge { bytes };
            return false;
        }
        let t0 = Instant::now();
        let copy = match scene {
            Scene::Map { map: pano, .. } => map.bake_map(pano, &key.shade).map(LitCopy::Map),
            Scene::Cube(cube) => map.bake_cube(cube, &key.shade).map(LitCopy::Cube),
        };
        match copy {
            Ok(c) => {
                let ms = t0.elapsed().as_secs_f64() * 1e3;
                self.state = BakeState::Baked { bytes, ms };
                self.copy = Some(c);
                true
            }
            Err(e) => {
                self.state = BakeState::Failed(e.to_string());
                false
            }
        }
    }

    /// A bake is due on the next frame (the window asks for one).
    pub fn pending(&self) -> bool {
        self.settled && self.state == BakeState::Changing
    }

    /// Where the lit panorama stands.
    pub fn state(&self) -> &BakeState {
        &self.state
    }

    /// The lit copy of `scene` to render, with `scene`'s renderer (the copy has the same
    /// geometry), or `None` when there is none.
    pub fn scene_ref<'a>(&'a self, scene: &'a mut Scene) -> Option<SceneRef<'a>> {
        match (&self.copy, scene) {
            (Some(LitCopy::Map(map)), Scene::Map { renderer, .. }) => {
                Some(SceneRef::Map { map, renderer })
            }
            (Some(LitCopy::Cube(cube)), Scene::Cube(_)) => Some(SceneRef::Cube(cube)),
            _ => None,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::lighting::{LightsState, LitCache};
    use crate::scene::render_scene;
    use lut_core::{grid_map, Camera, Projection, RenderOptions, Sampler, View};
    use std::path::Path;

    fn lamp() -> std::path::PathBuf {
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../../tests/data/ies/label_lines.ies")
    }

    fn key(cache: &LitCache, st: &LightsState) -> Option<BakeKey> {
        Some(BakeKey {
            map_generation: cache.generation(),
            scene_generation: 1,
            shade: st.shade_options(),
        })
    }

    #[test]
    fn baked_when_settled_dropped_when_changing() {
        let mut st = LightsState::default();
        st.load_and_add(&lamp()).unwrap();
        let mut cache = LitCache::default();
        let mut scene = Scene::map(grid_map(256, 128, Projection::Equirect).unwrap());
        let mut lit = LitPanorama::default();
        // Coarse map, then the full one: frames lit one by one.
        let m = cache.update(&mut st, true).unwrap();
        assert!(!lit.update(key(&cache, &st), !cache.refining(), m.as_deref(), &scene));
        assert_eq!(lit.state(), &BakeState::Changing);
        let m = cache.update(&mut st, true).unwrap();
        assert!(!lit.update(key(&cache, &st), !cache.refining(), m.as_deref(), &scene));
        assert!(lit.pending(), "the full map is there: a bake is due");
        // Unchanged for a frame: baked.
        assert!(lit.update(key(&cache, &st), true, m.as_deref(), &scene));
        assert!(matches!(lit.state(), BakeState::Baked { bytes, .. } if *bytes > 0));
        assert!(lit.state().describe().starts_with("lit panorama: "));
        assert!(lit.scene_ref(&mut scene).is_some());
        // Its frames are the lit room: against the per-frame lighting, within the
        // filtering-order tolerance of tests/lit_bake.rs (here: a few levels on average).
        let view = View::new(20.0, -30.0, 90.0).unwrap();
        let (w, h) = (160u32, 100u32);
        let opts = RenderOptions {
            sampler: Sampler::Bilinear,
            ..RenderOptions::default()
        };
        let mut want = vec![0u32; (w * h) as usize];
        render_scene(scene.as_mut(), view, &opts, &mut want, w, h).unwrap();
        m.as_ref()
            .unwrap()
            .shade_frame(
                &Camera::new(view, w, h),
                &mut want,
                w,
                h,
                &st.shade_options(),
            )
            .unwrap();
        let mut got = vec![0u32; (w * h) as usize];
        let r = lit.scene_ref(&mut scene).unwrap();
        render_scene(r, view, &opts, &mut got, w, h).unwrap();
        let close = want
            .iter()
            .zip(&got)
            .filter(|(a, b)| test_support::pixels::max_channel_diff(**a, **b) <= 2)
            .count();
        assert!(close * 100 >= want.len() * 98, "{close} of {}", want.len());
        // The exposure changes: the copy is dropped at once, baked again a frame later
        // from the same map.
        st.exposure_lux *= 2.0;
        st.auto_exposure = false;
        let m = cache.update(&mut st, true).unwrap();
        assert!(!lit.update(key(&cache, &st), true, m.as_deref(), &scene));
        assert!(lit.scene_ref(&mut scene).is_none());
        assert!(lit.update(key(&cache, &st), true, m.as_deref(), &scene));
        // Dragging (not settled): never baked.
        st.lights[0].position[0] += 0.1;
        let m = cache.update(&mut st, false).unwrap();
        for _ in 0..3 {
            assert!(!lit.update(key(&cache, &st), false, m.as_deref(), &scene));
            assert!(!lit.pending());
        }
        // No luminaire: off.
        assert!(!lit.update(None, true, None, &scene));
        assert_eq!(lit.state(), &BakeState::Off);
    }
}
