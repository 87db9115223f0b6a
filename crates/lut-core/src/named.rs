//! One list of names for every option and value enum: [`Named`].
//!
//! The command line, the viewer's panel, JSON reports and messages all take an enum's
//! values and names from here, so a value added to an enum appears everywhere at once and
//! no second list (a clap mirror enum, a panel label table) can drift from it. `FromStr`
//! of these types matches the same names (plus a few documented aliases) through
//! [`parse_name`], and its error lists them through [`name_list`].

use crate::{CubeRenderer, IndexStep, Layout, LutChoice, Naming, Projection, RendererKind};
use crate::{Sampler, Surface};

/// An enum whose values have one name each, listed in one place.
pub trait Named: Copy + Sized + 'static {
    /// Every value, in the order menus list them.
    const ALL: &'static [Self];
    /// The one name used by the CLI, the panel, JSON and messages.
    fn name(self) -> &'static str;
    /// One-line help shown by the CLI and as the panel's tooltip.
    fn help(self) -> &'static str {
        ""
    }
}

/// The value of `T` whose [`Named::name`] is exactly `s`.
pub fn parse_name<T: Named>(s: &str) -> Option<T> {
    T::ALL.iter().copied().find(|v| v.name() == s)
}

/// The names of every value of `T` for a message: `"a, b or c"`.
pub fn name_list<T: Named>() -> String {
    let names: Vec<&str> = T::ALL.iter().map(|v| v.name()).collect();
    match names.split_last() {
        Some((last, rest)) if !rest.is_empty() => format!("{} or {last}", rest.join(", ")),
        Some((last, _)) => (*last).to_string(),
        None => String::new(),
    }
}

/// The `FromStr` error of a name that is none of `T`'s: "unknown WHAT 'S' (expected …)".
pub(crate) fn unknown_name<T: Named>(what: &str, s: &str) -> String {
    format!("unknown {what} '{s}' (expected {})", name_list::<T>())
}

impl Named for Projection {
    const ALL: &'static [Self] = &Projection::ALL;
    fn name(self) -> &'static str {
        match self {
            Projection::Equirect => "equirect",
            Projection::Cylinder => "cylinder",
            Projection::Sine => "sine",
            Projection::Elliptical => "elliptical",
            Projection::Diamond => "diamond",
        }
    }
    fn help(self) -> &'static str {
        match self {
            Projection::Equirect => "Spherical, latitude/longitude (2:1)",
            Projection::Cylinder => "Cylindrical: limited vertical coverage",
            Projection::Sine => "Sine distribution (equal-area)",
            Projection::Elliptical => "Elliptical (sinusoidal): rows scaled by cos(latitude)",
            Projection::Diamond => "Diamond: rows scaled linearly to 0 at the poles",
        }
    }
}

impl Named for Sampler {
    const ALL: &'static [Self] = &[Sampler::Nearest, Sampler::Bilinear, Sampler::Trilinear];
    fn name(self) -> &'static str {
        match self {
            Sampler::Nearest => "nearest",
            Sampler::Bilinear => "bilinear",
            Sampler::Trilinear => "trilinear",
        }
    }
    fn help(self) -> &'static str {
        match self {
            Sampler::Nearest => "Nearest source pixel",
            Sampler::Bilinear => "Bilinear",
            Sampler::Trilinear => {
                "Trilinear: bilinear on the two pyramid levels around the pixel footprint \
                 (anti-aliased when zoomed out; the pyramid takes up to 1/3 more memory)"
            }
        }
    }
}

impl Named for RendererKind {
    const ALL: &'static [Self] = &[RendererKind::Lut, RendererKind::Exact];
    fn name(self) -> &'static str {
        match self {
            RendererKind::Lut => "lut",
            RendererKind::Exact => "exact",
        }
    }
    fn help(self) -> &'static str {
        match self {
            RendererKind::Lut => "The scanline-coherent LUT renderer",
            RendererKind::Exact => "The exact per-pixel renderer",
        }
    }
}

impl Named for LutChoice {
    const ALL: &'static [Self] = &[LutChoice::Auto, LutChoice::Wide, LutChoice::High];
    fn name(self) -> &'static str {
        match self {
            LutChoice::Auto => "auto",
            LutChoice::Wide => "wide",
            LutChoice::High => "high",
        }
    }
    fn help(self) -> &'static str {
        match self {
            LutChoice::Auto => "Wide above 60 degrees hfov, high-resolution at or below",
            LutChoice::Wide => "The wide-FOV table",
            LutChoice::High => "The high-resolution table",
        }
    }
}

impl Named for Surface {
    const ALL: &'static [Self] = &[Surface::Cylinder, Surface::Plane];
    fn name(self) -> &'static str {
        match self {
            Surface::Cylinder => "cylinder",
            Surface::Plane => "plane",
        }
    }
    fn help(self) -> &'static str {
        match self {
            Surface::Cylinder => "Cylinder (FIGS. 5-7)",
            Surface::Plane => "Plane (FIG. 8A)",
        }
    }
}

/// The steps rendering accepts, the adaptive one first (the default). A `Fixed` step
/// outside {1, 2, 4, 8, 16}, which rendering refuses, is named `invalid`.
impl Named for IndexStep {
    const ALL: &'static [Self] = &[
        IndexStep::Adaptive,
        IndexStep::Fixed(1),
        IndexStep::Fixed(2),
        IndexStep::Fixed(4),
        IndexStep::Fixed(8),
        IndexStep::Fixed(16),
    ];
    fn name(self) -> &'static str {
        match self {
            IndexStep::Adaptive => "adaptive",
            IndexStep::Fixed(1) => "1",
            IndexStep::Fixed(2) => "2",
            IndexStep::Fixed(4) => "4",
            IndexStep::Fixed(8) => "8",
            IndexStep::Fixed(16) => "16",
            IndexStep::Fixed(_) => "invalid",
        }
    }
    fn help(self) -> &'static str {
        match self {
            IndexStep::Adaptive => "The longest step the error bound allows, per scanline region",
            IndexStep::Fixed(1) => "Read the table at every pixel",
            IndexStep::Fixed(2) => "Read the table every 2nd pixel, interpolate between",
            IndexStep::Fixed(4) => "Read the table every 4th pixel, interpolate between",
            IndexStep::Fixed(8) => "Read the table every 8th pixel, interpolate between",
            IndexStep::Fixed(16) => "Read the table every 16th pixel, interpolate between",
            IndexStep::Fixed(_) => "Not a step rendering accepts",
        }
    }
}

impl Named for Layout {
    const ALL: &'static [Self] = &Layout::ALL;
    fn name(self) -> &'static str {
        match self {
            Layout::Files => "files",
            Layout::Cross => "cross",
            Layout::Strip => "strip",
            Layout::Grid3x2 => "3x2",
        }
    }
    fn help(self) -> &'static str {
        match self {
            Layout::Files => "Six files (a folder or a list)",
            Layout::Cross => "One 4:3 image, horizontal cross",
            Layout::Strip => "One 6:1 image: px nx py ny pz nz",
            Layout::Grid3x2 => "One 3:2 image: px nx py over ny pz nz",
        }
    }
}

impl Named for Naming {
    const ALL: &'static [Self] = &[Naming::Conventions, Naming::Cube2, Naming::Irrlicht];
    fn name(self) -> &'static str {
        match self {
            Naming::Conventions => "conventions",
            Naming::Cube2 => "cube2",
            Naming::Irrlicht => "irrlicht",
        }
    }
    fn help(self) -> &'static str {
        match self {
            Naming::Conventions => "Names mean what they say, images oriented as the conventions",
            Naming::Cube2 => "Sauerbraten / Cube 2 sky boxes (ft rt bk lf up dn)",
            Naming::Irrlicht => "Irrlicht sky boxes",
        }
    }
}

impl Named for CubeRenderer {
    const ALL: &'static [Self] = &[CubeRenderer::Basic, CubeRenderer::Accelerated];
    fn name(self) -> &'static str {
        match self {
            CubeRenderer::Basic => "basic",
            CubeRenderer::Accelerated => "scanline",
        }
    }
    fn help(self) -> &'static str {
        match self {
            CubeRenderer::Basic => "Per pixel: face by the largest coordinate",
            CubeRenderer::Accelerated => "Per scanline: face segments split by binary search",
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every value's name is unique and parses back to it; names are what scripts type.
    fn round_trip<T: Named + PartialEq + std::fmt::Debug>() {
        for (i, v) in T::ALL.iter().enumerate() {
            assert_eq!(parse_name::<T>(v.name()), Some(*v), "{v:?}");
            assert!(!v.help().is_empty(), "{v:?} has no help");
            for w in &T::ALL[..i] {
                assert_ne!(w.name(), v.name());
            }
        }
        assert_eq!(parse_name::<T>("no such name"), None);
    }

    #[test]
    fn names_round_trip() {
        round_trip::<Projection>();
        round_trip::<Sampler>();
        round_trip::<RendererKind>();
        round_trip::<LutChoice>();
        round_trip::<Surface>();
        round_trip::<IndexStep>();
        round_trip::<Layout>();
        round_trip::<Naming>();
        round_trip::<CubeRenderer>();
    }

    #[test]
    fn lists_read_as_prose() {
        assert_eq!(name_list::<Sampler>(), "nearest, bilinear or trilinear");
        assert_eq!(name_list::<RendererKind>(), "lut or exact");
        assert_eq!(
            unknown_name::<Layout>("layout", "hex"),
            "unknown layout 'hex' (expected files, cross, strip or 3x2)"
        );
    }

    #[test]
    fn from_str_takes_the_names_and_the_aliases() {
        for &p in Projection::ALL.iter() {
            assert_eq!(p.name().parse::<Projection>(), Ok(p));
            assert_eq!(p.name().to_uppercase().parse::<Projection>(), Ok(p));
        }
        assert_eq!("spherical".parse::<Projection>(), Ok(Projection::Equirect));
        assert_eq!(
            "sinusoidal".parse::<Projection>(),
            Ok(Projection::Elliptical)
        );
        assert_eq!(
            "mercator".parse::<Projection>(),
            Err("unknown projection 'mercator' (expected equirect, cylinder, sine, elliptical or diamond)".into())
        );
        assert_eq!("trilinear".parse::<Sampler>(), Ok(Sampler::Trilinear));
        assert_eq!("3x2".parse::<Layout>(), Ok(Layout::Grid3x2));
        assert_eq!("sauerbraten".parse::<Naming>(), Ok(Naming::Cube2));
        assert_eq!(
            "scanline".parse::<CubeRenderer>(),
            Ok(CubeRenderer::Accelerated)
        );
        assert_eq!(
            "accel".parse::<CubeRenderer>(),
            Ok(CubeRenderer::Accelerated)
        );
        assert!("cubic".parse::<Sampler>().unwrap_err().contains("cubic"));
    }
}
