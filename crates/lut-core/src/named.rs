//! One list of names for every option and value enum: [`Named`].
//!
//! The command line, the viewer's panel, JSON reports and messages all take an enum's
//! values and names from here, so a value added to an enum appears everywhere at once and
//! no second list (a clap mirror enum, a panel label table) can drift from it. `FromStr`
//! of these types matches the same names (plus a few documented aliases) through
//! [`parse_name`], and its error lists them through [`name_list`].

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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{CubeRenderer, IndexStep, Layout, LutChoice, Naming, Projection, RendererKind};
    use crate::{Kernel, Sampler, Surface};

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
        round_trip::<Kernel>();
        round_trip::<crate::Interpolation>();
        round_trip::<crate::ViewProjection>();
    }

    #[test]
    fn lists_read_as_prose() {
        assert_eq!(name_list::<Sampler>(), "nearest, bilinear or trilinear");
        assert_eq!(name_list::<RendererKind>(), "lut, grid or exact");
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
