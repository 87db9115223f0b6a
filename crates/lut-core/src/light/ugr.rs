//! Discomfort glare: CIE 117-1995's Unified Glare Rating for one observer,
//!
//! UGR = 8 log10( 0.25 / Lb · Σ L² ω / p² ),
//!
//! summed over the luminaires the observer sees above the line of sight, where
//!
//! * L is the luminance of the luminaire's luminous area toward the eye, cd/m²: the
//!   intensity toward the eye over the area's projection seen from there;
//! * ω is the solid angle of that projected area at the eye (projected area / d²);
//! * p is Guth's position index for the direction, from the closed form of Kim, Han and
//!   Kim (2009) fitted to Guth's table: p = exp\[(35.2 − 0.31889 τ − 1.22 e^(−2τ/9)) ·
//!   10⁻³ σ plus (21 + 0.26667 τ − 0.002963 τ²) · 10⁻⁵ σ²\], σ the angle between the line
//!   of sight and the direction to the luminaire, τ the angle from the vertical of the
//!   plane holding both (degrees);
//! * Lb the background luminance, cd/m²: the indirect illuminance at the eye on a plane
//!   facing along the line of sight, over π (CIE 117's definition), so it needs the
//!   inter-reflections.
//!
//! The luminous area comes from the file: IES LM-63 width, length and height of the
//! luminous opening (feet or metres; a negative width is a round opening of that
//! diameter), EULUMDAT's luminous area length (or diameter) and width (0: round) and the
//! mean of its four luminous heights. A file that gives none (all zero: a point source)
//! has no luminance, so it is left out of the sum and reported as such.

use super::photometry::{Photometry, PhotometrySource};
use super::shade::{LightScene, Luminaire};
use glam::DVec3;
use std::f64::consts::PI;

/// A luminaire's luminous area, metres, in its own frame: `width` across (the C90-C270
/// axis, the frame's x), `length` along (C0-C180, y), `height` its luminous sides
/// (along the aim, z); `round` for a disc of diameter `width`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LuminousArea {
    /// Across, metres (a disc's diameter).
    pub width: f64,
    /// Along, metres.
    pub length: f64,
    /// The luminous sides' height, metres.
    pub height: f64,
    /// A disc (or cylinder) rather than a rectangle (or box).
    pub round: bool,
}

impl LuminousArea {
    /// The luminous area a photometric file gives, `None` when it gives none.
    pub fn of(p: &Photometry) -> Option<LuminousArea> {
        let a = match &p.source {
            PhotometrySource::Ies(f) => {
                let unit = if f.units_type == 1 { 0.3048 } else { 1.0 };
                let [w, l, h] = f.opening.map(|x| x * unit);
                if w < 0.0 {
                    LuminousArea {
                        width: -w,
                        length: -w,
                        height: h.abs(),
                        round: true,
                    }
                } else {
                    LuminousArea {
                        width: w,
                        length: l.abs(),
                        height: h.abs(),
                        round: false,
                    }
                }
            }
            PhotometrySource::Ldt(f) => {
                let [la, b] = f.luminous_area_mm.map(|x| x.abs() / 1000.0);
                let h = f.luminous_heights_mm.iter().map(|x| x.abs()).sum::<f64>() / 4000.0;
                if b == 0.0 {
                    LuminousArea {
                        width: la,
                        length: la,
                        height: h,
                        round: true,
                    }
                } else {
                    LuminousArea {
                        width: b,
                        length: la,
                        height: h,
                        round: false,
                    }
                }
            }
        };
        (a.projected(DVec3::Z) > 0.0 || a.height > 0.0).then_some(a)
    }

    /// The area seen along the unit direction `d` (luminaire frame, from the luminaire
    /// toward the eye), m²: the bottom (facing the aim) when the eye is in front of it,
    /// and the sides.
    pub fn projected(&self, d: DVec3) -> f64 {
        let front = d.z.max(0.0);
        if self.round {
            PI * self.width * self.width / 4.0 * front
                + self.width * self.height * (d.x * d.x + d.y * d.y).sqrt()
        } else {
            self.width * self.length * front
                + self.length * self.height * d.x.abs()
                + self.width * self.height * d.y.abs()
        }
    }
}

/// Guth's position index for a source `sigma` degrees off the line of sight in a plane
/// `tau` degrees from the vertical (Kim, Han and Kim's closed form).
pub fn position_index(tau: f64, sigma: f64) -> f64 {
    ((35.2 - 0.31889 * tau - 1.22 * (-2.0 * tau / 9.0).exp()) * 1e-3 * sigma
        + (21.0 + 0.26667 * tau - 0.002963 * tau * tau) * 1e-5 * sigma * sigma)
        .exp()
}

/// One luminaire's part in the rating.
#[derive(Debug, Clone, PartialEq)]
pub struct GlareTerm {
    /// The luminaire (index into the scene's).
    pub index: usize,
    /// Why it is not in the sum, if it is not.
    pub excluded: Option<&'static str>,
    /// Luminance toward the eye, cd/m².
    pub luminance: f64,
    /// Solid angle of the luminous area at the eye, sr.
    pub solid_angle: f64,
    /// Guth's position index.
    pub position_index: f64,
}

/// The rating for one observer.
#[derive(Debug, Clone, PartialEq)]
pub struct Ugr {
    /// The UGR, when there is something to rate.
    pub value: Option<f64>,
    /// Why there is no value, when there is none.
    pub note: Option<&'static str>,
    /// The background luminance Lb, cd/m².
    pub background_luminance: f64,
    /// Every luminaire's term.
    pub terms: Vec<GlareTerm>,
}

/// The UGR at `eye` (room coordinates) looking along `view` (room frame, any length but
/// zero) of `scene`'s luminaires, `areas[i]` the luminous area of luminaire i.
pub fn ugr(scene: &LightScene, areas: &[Option<LuminousArea>], eye: DVec3, view: DVec3) -> Ugr {
    let v = view.normalize();
    let lb = scene.indirect(eye, v) / PI;
    let mut sum = 0.0;
    let mut terms = Vec::new();
    for (index, l) in scene.luminaires().iter().enumerate() {
        let mut t = GlareTerm {
            index,
            excluded: None,
            luminance: 0.0,
            solid_angle: 0.0,
            position_index: 0.0,
        };
        let to = l.position - eye;
        let r = to.length();
        let s = to / r;
        let cos_sigma = s.dot(v);
        // τ: the angle between "up" and the source, both seen across the line of sight.
        let sp = s - v * cos_sigma;
        let up = DVec3::Y - v * v.y;
        let tau = if sp.length() < 1e-12 || up.length() < 1e-12 {
            0.0
        } else {
            sp.normalize()
                .dot(up.normalize())
                .clamp(-1.0, 1.0)
                .acos()
                .to_degrees()
        };
        match areas.get(index).copied().flatten() {
            None => t.excluded = Some("the file gives no luminous area"),
            Some(_) if l.multiplier <= 0.0 => t.excluded = Some("switched off"),
            Some(_) if cos_sigma <= 0.0 => t.excluded = Some("behind the observer"),
            Some(_) if tau > 90.0 => t.excluded = Some("below the line of sight"),
            Some(area) => {
                let d = local(l, -s);
                let ap = area.projected(d);
                let tilt = l.table.tilt().map_or(1.0, |tt| tt.factor_at(l.tilt_deg()));
                let i = l.table.candela_dir(d) * l.multiplier * tilt;
                if ap <= 0.0 || i <= 0.0 {
                    t.excluded = Some("sends no light toward the eye");
                } else {
                    t.luminance = i / ap;
                    t.solid_angle = ap / (r * r);
                    t.position_index =
                        position_index(tau, cos_sigma.clamp(-1.0, 1.0).acos().to_degrees());
                    sum += t.luminance * t.luminance * t.solid_angle
                        / (t.position_index * t.position_index);
                }
            }
        }
        terms.push(t);
    }
    let (value, note) = if lb <= 0.0 {
        (None, Some("no background luminance: the rating needs the inter-reflections (not with --direct-only or black surfaces)"))
    } else if sum <= 0.0 {
        (
            None,
            Some("no luminaire with a luminous area is seen above the line of sight"),
        )
    } else {
        (Some(8.0 * (0.25 / lb * sum).log10()), None)
    };
    Ugr {
        value,
        note,
        background_luminance: lb,
        terms,
    }
}

/// A room-frame direction in `l`'s frame (x right, y up, z aim).
fn local(l: &Luminaire, d: DVec3) -> DVec3 {
    let (right, up, aim) = l.frame();
    DVec3::new(d.dot(right), d.dot(up), d.dot(aim))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn position_index_is_one_on_the_line_of_sight_and_grows_off_it() {
        assert!((position_index(0.0, 0.0) - 1.0).abs() < 1e-12);
        let a = position_index(0.0, 30.0);
        let b = position_index(0.0, 60.0);
        assert!(a > 1.0 && b > a);
        // Off to the side (τ = 90°) a source glares more (a smaller index) than one
        // straight above the line of sight at the same angle (the brows shade that).
        assert!(position_index(90.0, 45.0) < position_index(0.0, 45.0));
    }

    #[test]
    fn projected_area_of_a_flat_panel() {
        let a = LuminousArea {
            width: 0.6,
            length: 0.6,
            height: 0.0,
            round: false,
        };
        assert!((a.projected(DVec3::Z) - 0.36).abs() < 1e-12);
        let d = DVec3::new(0.0, 0.5f64.sqrt(), 0.5f64.sqrt());
        assert!((a.projected(d) - 0.36 * 0.5f64.sqrt()).abs() < 1e-12);
        assert_eq!(a.projected(-DVec3::Z), 0.0);
    }
}
