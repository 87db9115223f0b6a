//! Lighting a rendered panorama frame with goniometric luminaires.
//!
//! The panorama is taken as the albedo of a box-shaped room around the camera (for a cube
//! panorama, the cube is the room). For every output pixel: the scene point is the camera
//! ray ∩ the room box; for each luminaire, the direction and distance from the light give
//! E = I(direction) · cos(incidence) / d² (through the distance series of [`LightTable`]);
//! the shaded colour is albedo · (ambient + exposure · ΣE), computed on linear light
//! (sRGB decoded, multiplied, encoded again).
//!
//! Positions are in room coordinates ([`Room`]): metres along the box's edges, origin on
//! the floor below the camera; camera rays are turned from the panorama's frame into the
//! room's by the room's yaw. The walls are convex around every light inside, so there are
//! no shadows to trace.
//!
//! This is the per-pixel path: exact, and the reference the illuminance map
//! ([`super::lumamap`]) is measured against; the window lights frames from that map.

use super::room::Room;
use super::table::LightTable;
use super::{LightError, PhotometricType};
use crate::geom::camera::Camera;
use glam::DVec3;
use rayon::prelude::*;
use std::sync::{Arc, OnceLock};

/// One luminaire placed in the room.
#[derive(Debug, Clone)]
pub struct Luminaire {
    /// Its intensity distribution.
    pub table: Arc<LightTable>,
    /// Position in metres, world frame.
    pub position: DVec3,
    /// Aim yaw in degrees (the camera's sense: positive turns right).
    pub yaw_deg: f64,
    /// Aim pitch in degrees (positive up; −90 = straight down), clamped to [−90, 90].
    pub pitch_deg: f64,
    /// Multiplies the intensity (e.g. several lamps, dimming).
    pub multiplier: f64,
}

impl Luminaire {
    /// A luminaire at `position`, aimed straight down, multiplier 1.
    pub fn new(table: Arc<LightTable>, position: DVec3) -> Luminaire {
        Luminaire {
            table,
            position,
            yaw_deg: 0.0,
            pitch_deg: -90.0,
            multiplier: 1.0,
        }
    }

    /// The frame its table's angles are measured in (right, up, aim) as unit world
    /// vectors: [`Luminaire::mount_frame`], turned by the file's tilt during measurement
    /// θ ([`LightTable::measurement_tilt_deg`], EULUMDAT only) about the up axis (the
    /// C0-C180 axis), so the luminaire's own nadir lies at γ = θ in the table's C90
    /// plane: right' = cos θ·right − sin θ·aim, aim' = sin θ·right + cos θ·aim. With no
    /// tilt it is the mount frame.
    pub fn frame(&self) -> (DVec3, DVec3, DVec3) {
        let (r, u, a) = self.mount_frame();
        let t = self.table.measurement_tilt_deg();
        if t == 0.0 {
            return (r, u, a);
        }
        let (st, ct) = t.to_radians().sin_cos();
        (r * ct - a * st, u, r * st + a * ct)
    }

    /// The luminaire's own frame (right, up, aim) as unit world vectors, from its yaw and
    /// pitch: the camera's rotation, pitch about X then yaw about Y. Aimed down at yaw 0,
    /// "up" points along +Z.
    pub fn mount_frame(&self) -> (DVec3, DVec3, DVec3) {
        let (sp, cp) = self.pitch_deg.clamp(-90.0, 90.0).to_radians().sin_cos();
        let (sy, cy) = self.yaw_deg.to_radians().sin_cos();
        let rot = |v: DVec3| {
            let y1 = v.y * cp + v.z * sp;
            let z1 = v.z * cp - v.y * sp;
            DVec3::new(v.x * cy + z1 * sy, y1, z1 * cy - v.x * sy)
        };
        (rot(DVec3::X), rot(DVec3::Y), rot(DVec3::Z))
    }

    /// The lamp's tilt in degrees: for type C the angle between the aim and straight
    /// down, for types A/B the angle between the aim and the horizontal.
    pub fn tilt_deg(&self) -> f64 {
        let (_, _, f) = self.mount_frame();
        match self.table.photometric_type() {
            PhotometricType::C => (-f.y).clamp(-1.0, 1.0).acos().to_degrees(),
            _ => f.y.clamp(-1.0, 1.0).asin().to_degrees().abs(),
        }
    }
}

#[derive(Debug, Clone)]
struct Placed {
    table: Arc<LightTable>,
    pos: DVec3,
    right: DVec3,
    up: DVec3,
    aim: DVec3,
    /// multiplier × tilt factor.
    scale: f64,
}

/// Luminaires in a room: what [`shade_frame`] and [`lux_at`] light.
#[derive(Debug, Clone)]
pub struct LightScene {
    room: Room,
    lights: Vec<Luminaire>,
    placed: Vec<Placed>,
    /// The inter-reflections ([`LightScene::with_reflectances`]), if any.
    indirect: Option<Arc<super::radiosity::Radiosity>>,
}

impl LightScene {
    /// Place the luminaires in the room.
    ///
    /// # Errors
    /// [`LightError::LightOutsideRoom`] for a light outside the box,
    /// [`LightError::BadOption`] for a non-finite position or angle or a negative or
    /// non-finite multiplier.
    pub fn new(room: Room, lights: Vec<Luminaire>) -> Result<LightScene, LightError> {
        crate::guard::check_limit(
            "luminaires",
            lights.len(),
            crate::geom::limits::MAX_LIGHTS,
            "",
        )?;
        let mut placed = Vec::with_capacity(lights.len());
        for (index, l) in lights.iter().enumerate() {
            for (name, value) in [
                ("light position x", l.position.x),
                ("light position y", l.position.y),
                ("light position z", l.position.z),
                ("light yaw", l.yaw_deg),
                ("light pitch", l.pitch_deg),
            ] {
                if !value.is_finite() {
                    return Err(LightError::BadOption {
                        name,
                        expected: "a finite number",
                        value,
                    });
                }
            }
            crate::guard::check_limit(
                "light multiplier",
                l.multiplier,
                crate::geom::limits::MAX_LIGHT_MULTIPLIER,
                "",
            )?;
            if !(l.multiplier.is_finite() && l.multiplier >= 0.0) {
                return Err(LightError::BadOption {
                    name: "light multiplier",
                    expected: "a finite number ≥ 0",
                    value: l.multiplier,
                });
            }
            if !room.contains(l.position) {
                let (lo, hi) = room.bounds();
                return Err(LightError::LightOutsideRoom {
                    index,
                    position: l.position.to_array(),
                    low: lo.to_array(),
                    high: hi.to_array(),
                });
            }
            let (right, up, aim) = l.frame();
            let tilt = l.table.tilt().map_or(1.0, |t| t.factor_at(l.tilt_deg()));
            placed.push(Placed {
                table: l.table.clone(),
                pos: l.position,
                right,
                up,
                aim,
                scale: l.multiplier * tilt,
            });
        }
        Ok(LightScene {
            room,
            lights,
            placed,
            indirect: None,
        })
    }

    /// The same scene with inter-reflections: the room's surfaces reflect diffusely with
    /// `reflectances`, solved by radiosity ([`super::radiosity`]); all zero gives the
    /// direct light only (no solve).
    ///
    /// # Errors
    /// [`LightError::BadOption`] for a reflectance outside [0, 1).
    pub fn with_reflectances(
        mut self,
        reflectances: super::radiosity::Reflectances,
    ) -> Result<LightScene, LightError> {
        reflectances.check()?;
        self.indirect = None;
        if !reflectances.is_zero() {
            self.indirect = Some(super::radiosity::Radiosity::solve_cached(
                &self,
                reflectances,
            )?);
        }
        Ok(self)
    }

    /// The same scene with inter-reflections solved elsewhere (on another thread, say):
    /// `radiosity` should be a solve of this room ([`super::radiosity::Radiosity::solve`]
    /// of this scene, or of the same room with luminaires since moved, as a stand-in
    /// until their own solve is done).
    pub fn with_radiosity(mut self, radiosity: Arc<super::radiosity::Radiosity>) -> LightScene {
        self.indirect = Some(radiosity);
        self
    }

    /// The inter-reflections solved for this scene, if any.
    pub fn radiosity(&self) -> Option<&super::radiosity::Radiosity> {
        self.indirect.as_deref()
    }

    /// The exact indirect illuminance at `p` with unit normal `n` (0 without
    /// inter-reflections): [`super::radiosity::Radiosity::indirect_at`].
    pub fn indirect(&self, p: DVec3, n: DVec3) -> f64 {
        self.indirect.as_ref().map_or(0.0, |r| r.indirect_at(p, n))
    }

    /// The room.
    pub fn room(&self) -> &Room {
        &self.room
    }

    /// The luminaires.
    pub fn luminaires(&self) -> &[Luminaire] {
        &self.lights
    }

    /// Illuminance in lux at surface point `p` with unit normal `n` (facing into the
    /// room): the direct light ([`LightScene::direct`]) plus, with inter-reflections, the
    /// indirect (on the room's faces interpolated between the radiosity patches, see
    /// [`super::radiosity::Radiosity::indirect_fast`]).
    #[inline]
    pub fn illuminance(&self, p: DVec3, n: DVec3) -> f64 {
        let e = self.direct(p, n);
        match &self.indirect {
            Some(r) => e + r.indirect_fast(p, n),
            None => e,
        }
    }

    /// Direct illuminance in lux at surface point `p` with unit normal `n` (facing into
    /// the room): Σ multiplier · tilt factor · I(direction) · cos(incidence) / d².
    #[inline]
    pub fn direct(&self, p: DVec3, n: DVec3) -> f64 {
        let mut e = 0.0;
        for l in &self.placed {
            let to_light = l.pos - p;
            let d2 = to_light.length_squared();
            if d2 < 1e-18 {
                continue;
            }
            let d = d2.sqrt();
            let cos_i = n.dot(to_light) / d;
            if cos_i <= 0.0 {
                continue;
            }
            // Direction from the light to the point, in the light's frame.
            let w = -to_light / d;
            let local = DVec3::new(w.dot(l.right), w.dot(l.up), w.dot(l.aim));
            e += l.scale * l.table.illuminance_normal(local, d) * cos_i;
        }
        e
    }

    /// The scene point and inward normal (room coordinates) seen along direction `dir`
    /// of the panorama (the camera's world frame) from the camera.
    pub fn scene_point(&self, dir: DVec3) -> (DVec3, DVec3) {
        self.room
            .hit(self.room.camera_position(), self.room.to_room(dir))
    }
}

/// How [`shade_frame`] turns illuminance into colour.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ShadeOptions {
    /// Light factor everywhere, lights or not (1 = the panorama as photographed).
    pub ambient: f64,
    /// Light factor per lux (so 1 / exposure lux look like the photograph).
    pub exposure: f64,
    /// Replace the shading by a false-colour illuminance map blended over it.
    pub false_color: bool,
    /// Illuminance at the top (red) of the false-colour scale; the scale is logarithmic
    /// over three decades below it.
    pub false_color_max_lux: f64,
}

impl Default for ShadeOptions {
    fn default() -> Self {
        ShadeOptions {
            ambient: 0.15,
            exposure: 1.0 / 300.0,
            false_color: false,
            false_color_max_lux: 1000.0,
        }
    }
}

impl ShadeOptions {
    /// Check the options.
    ///
    /// # Errors
    /// [`LightError::BadOption`] for non-finite or negative ambient/exposure or a
    /// non-positive false-colour maximum.
    pub fn check(&self) -> Result<(), LightError> {
        for (name, value) in [("ambient", self.ambient), ("exposure", self.exposure)] {
            if !(value.is_finite() && value >= 0.0) {
                return Err(LightError::BadOption {
                    name,
                    expected: "a finite number ≥ 0",
                    value,
                });
            }
        }
        if self.false_color
            && !(self.false_color_max_lux.is_finite() && self.false_color_max_lux > 0.0)
        {
            return Err(LightError::BadOption {
                name: "false-colour maximum",
                expected: "a positive number of lux",
                value: self.false_color_max_lux,
            });
        }
        Ok(())
    }
}

/// [`LightError::BufferSize`] unless `frame` holds `w × h` pixels and `cam` was made for
/// that size.
pub(crate) fn check_frame(cam: &Camera, frame: &[u32], w: u32, h: u32) -> Result<(), LightError> {
    let needed = w as usize * h as usize;
    if frame.len() != needed || cam.width != w || cam.height != h {
        return Err(LightError::BufferSize {
            len: frame.len(),
            width: w,
            height: h,
            needed,
        });
    }
    Ok(())
}

/// sRGB 8-bit → linear.
pub(crate) fn decode_lut() -> &'static [f32; 256] {
    static LUT: OnceLock<[f32; 256]> = OnceLock::new();
    LUT.get_or_init(|| {
        let mut t = [0.0f32; 256];
        for (i, v) in t.iter_mut().enumerate() {
            let c = i as f64 / 255.0;
            *v = if c <= 0.04045 {
                c / 12.92
            } else {
                ((c + 0.055) / 1.055).powf(2.4)
            } as f32;
        }
        t
    })
}

pub(crate) const ENC_N: usize = 4096;

/// Linear [0, 1] in 4096 steps → sRGB 8-bit.
pub(crate) fn encode_lut() -> &'static [u8; ENC_N] {
    static LUT: OnceLock<[u8; ENC_N]> = OnceLock::new();
    LUT.get_or_init(|| {
        let mut t = [0u8; ENC_N];
        for (i, v) in t.iter_mut().enumerate() {
            let l = i as f64 / (ENC_N - 1) as f64;
            let s = if l <= 0.003_130_8 {
                l * 12.92
            } else {
                1.055 * l.powf(1.0 / 2.4) - 0.055
            };
            *v = (s * 255.0).round().clamp(0.0, 255.0) as u8;
        }
        t
    })
}

#[inline]
pub(crate) fn encode(l: f32, enc: &[u8; ENC_N]) -> u32 {
    let i = (l.clamp(0.0, 1.0) * (ENC_N - 1) as f32 + 0.5) as usize;
    enc[i.min(ENC_N - 1)] as u32
}

/// The false-colour ramp at `t` in [0, 1]: dark blue, blue, green, yellow, red.
pub fn false_color(t: f64) -> u32 {
    const STOPS: [(f64, [f64; 3]); 5] = [
        (0.0, [0.0, 0.0, 96.0]),
        (0.25, [0.0, 96.0, 255.0]),
        (0.5, [0.0, 200.0, 80.0]),
        (0.75, [255.0, 220.0, 0.0]),
        (1.0, [255.0, 32.0, 0.0]),
    ];
    let t = if t.is_nan() { 0.0 } else { t.clamp(0.0, 1.0) };
    let k = STOPS.iter().rposition(|s| s.0 <= t).unwrap_or(0).min(3);
    let (t0, c0) = STOPS[k];
    let (t1, c1) = STOPS[k + 1];
    let f = (t - t0) / (t1 - t0);
    let ch = |i: usize| ((c0[i] + (c1[i] - c0[i]) * f).round().clamp(0.0, 255.0)) as u32;
    (ch(0) << 16) | (ch(1) << 8) | ch(2)
}

/// Position in [0, 1] on the false-colour scale (the argument of [`false_color`]) of
/// `lux` for a scale topping at `max_lux`: logarithmic over three decades, 0 at
/// `max_lux / 1000` and below, 1 at `max_lux` and above.
pub fn false_color_position(lux: f64, max_lux: f64) -> f64 {
    if lux.is_nan() || lux <= 0.0 {
        return 0.0;
    }
    ((lux / max_lux).log10() / 3.0 + 1.0).clamp(0.0, 1.0)
}

/// Shade one pixel of albedo `p` with light factor `k`.
#[inline]
pub(crate) fn shade_pixel(p: u32, k: f32, dec: &[f32; 256], enc: &[u8; ENC_N]) -> u32 {
    let r = encode(dec[((p >> 16) & 0xff) as usize] * k, enc);
    let g = encode(dec[((p >> 8) & 0xff) as usize] * k, enc);
    let b = encode(dec[(p & 0xff) as usize] * k, enc);
    (r << 16) | (g << 8) | b
}

/// Light a rendered frame in place: each pixel's colour is taken as the albedo of the
/// room surface its camera ray hits. Rows run in parallel; the result does not depend
/// on the number of threads.
///
/// # Errors
/// [`LightError::BufferSize`] when `frame` does not hold `w × h` pixels (or the camera
/// was made for another size); [`LightError::BadOption`] for non-finite or negative
/// ambient/exposure or a non-positive false-colour maximum.
pub fn shade_frame(
    scene: &LightScene,
    cam: &Camera,
    frame: &mut [u32],
    w: u32,
    h: u32,
    opts: &ShadeOptions,
) -> Result<(), LightError> {
    check_frame(cam, frame, w, h)?;
    opts.check()?;
    if frame.is_empty() {
        return Ok(());
    }
    let dec = decode_lut();
    let enc = encode_lut();
    let origin = scene.room.camera_position();
    frame
        .par_chunks_mut(w as usize)
        .enumerate()
        .for_each(|(y, row)| {
            let py = y as f64 + 0.5;
            for (x, px) in row.iter_mut().enumerate() {
                // Pixels with no direction (outside a fisheye's disc) stay as rendered.
                let Some(ray) = cam.ray(x as f64 + 0.5, py) else {
                    continue;
                };
                let dir = scene.room.to_room(ray);
                let (p, n) = scene.room.hit(origin, dir);
                let e = scene.illuminance(p, n);
                let k = (opts.ambient + opts.exposure * e) as f32;
                let shaded = shade_pixel(*px, k, dec, enc);
                *px = if opts.false_color {
                    blend(
                        false_color(false_color_position(e, opts.false_color_max_lux)),
                        shaded,
                        0.65,
                    )
                } else {
                    shaded
                };
            }
        });
    Ok(())
}

/// a · t + b · (1 − t) per channel.
pub(crate) fn blend(a: u32, b: u32, t: f32) -> u32 {
    let ch = |s: u32| {
        let x = ((a >> s) & 0xff) as f32;
        let y = ((b >> s) & 0xff) as f32;
        ((x * t + y * (1.0 - t)).round() as u32).min(255) << s
    };
    ch(16) | ch(8) | ch(0)
}

/// Illuminance in lux (lights only, no ambient) at the room surface seen through image
/// point (px, py) (pixel coordinates, centres at +0.5) of `cam`.
/// 0 where the view's projection has no direction.
pub fn lux_at(scene: &LightScene, cam: &Camera, px: f64, py: f64) -> f64 {
    let Some(dir) = cam.ray(px, py) else {
        return 0.0;
    };
    let (p, n) = scene.scene_point(dir);
    scene.illuminance(p, n)
}

/// The solve gathers from the scene's direct light (the trait keeps radiosity.rs from
/// importing this file).
impl super::radiosity::DirectLight for LightScene {
    fn room(&self) -> &Room {
        LightScene::room(self)
    }

    fn direct(&self, p: DVec3, n: DVec3) -> f64 {
        LightScene::direct(self, p, n)
    }

    fn lit_positions(&self) -> Vec<DVec3> {
        self.luminaires()
            .iter()
            .filter(|l| l.multiplier > 0.0)
            .map(|l| l.position)
            .collect()
    }

    fn cache_key(&self) -> Vec<(usize, [f64; 3], f64, f64, f64)> {
        self.luminaires()
            .iter()
            .map(|l| {
                (
                    Arc::as_ptr(&l.table) as usize,
                    l.position.to_array(),
                    l.yaw_deg,
                    l.pitch_deg,
                    l.multiplier,
                )
            })
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn light_frame_down_has_up_along_z() {
        let t = Arc::new(
            LightTable::from_ies(
                &crate::light::IesFile::parse("TILT=NONE\n1 -1 1 1 1 1 2 0 0 0 1 1 1 0 0 1\n", "t")
                    .unwrap(),
                &Default::default(),
            )
            .unwrap(),
        );
        let l = Luminaire::new(t, DVec3::ZERO);
        let (r, u, f) = l.frame();
        assert!((r - DVec3::X).length() < 1e-12);
        assert!((u - DVec3::Z).length() < 1e-12);
        assert!((f - DVec3::NEG_Y).length() < 1e-12);
        assert!(l.tilt_deg().abs() < 1e-9);
    }

    #[test]
    fn srgb_luts_round_trip() {
        let (d, e) = (decode_lut(), encode_lut());
        for i in 0..=255u32 {
            assert_eq!(encode(d[i as usize], e), i);
        }
    }

    #[test]
    fn false_color_ends() {
        assert_eq!(false_color(0.0), 0x000060);
        assert_eq!(false_color(1.0), 0xff2000);
        assert_eq!(false_color_position(1000.0, 1000.0), 1.0);
        assert_eq!(false_color_position(1.0, 1000.0), 0.0);
    }
}
