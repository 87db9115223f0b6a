//! One clap value parser for every option enum, built from [`Named`]: the values, their
//! names and their help come from the enum's one list, so the command line, the panel and
//! JSON cannot disagree on a name.

use clap::builder::{PossibleValue, PossibleValuesParser, TypedValueParser};
use clap::error::ErrorKind;
use lut_core::Named;
use std::ffi::OsStr;
use std::str::FromStr;

/// Parses a [`Named`] enum by its names; `--help` lists every value with its help, and a
/// bad value gets clap's usual "invalid value … [possible values: …]" message.
#[derive(Clone, Copy)]
pub struct NamedParser<T> {
    /// What else is accepted besides the names (aliases), if anything.
    others: fn(&str) -> Option<T>,
}

/// The parser of `T`'s names, exactly.
pub fn named<T: Named>() -> NamedParser<T> {
    NamedParser { others: |_| None }
}

/// The parser of `T`'s names and of whatever else `T`'s `FromStr` takes (aliases such as
/// `equirectangular`, or projection names in any case).
pub fn named_or_parse<T: Named + FromStr>() -> NamedParser<T> {
    NamedParser {
        others: |s| s.parse().ok(),
    }
}

/// `T`'s values as clap's possible values: name, and help where there is one.
fn possible_values<T: Named>() -> impl Iterator<Item = PossibleValue> {
    T::ALL.iter().map(|v| match v.help() {
        "" => PossibleValue::new(v.name()),
        help => PossibleValue::new(v.name()).help(help),
    })
}

impl<T: Named + Send + Sync> TypedValueParser for NamedParser<T> {
    type Value = T;

    fn parse_ref(
        &self,
        cmd: &clap::Command,
        arg: Option<&clap::Arg>,
        value: &OsStr,
    ) -> Result<T, clap::Error> {
        let parsed = value
            .to_str()
            .and_then(|s| lut_core::parse_name(s).or_else(|| (self.others)(s)));
        if let Some(v) = parsed {
            return Ok(v);
        }
        // Not a value: let clap word the error, listing the names.
        Err(PossibleValuesParser::new(possible_values::<T>())
            .parse_ref(cmd, arg, value)
            .err()
            .unwrap_or_else(|| clap::Error::new(ErrorKind::InvalidValue).with_cmd(cmd)))
    }

    fn possible_values(&self) -> Option<Box<dyn Iterator<Item = PossibleValue> + '_>> {
        Some(Box::new(possible_values::<T>()))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use lut_core::{Projection, Sampler};

    fn parse<T: Named + Send + Sync>(p: NamedParser<T>, s: &str) -> Result<T, String> {
        let cmd = clap::Command::new("t");
        p.parse_ref(&cmd, None, OsStr::new(s))
            .map_err(|e| e.to_string())
    }

    #[test]
    fn names_parse_and_others_only_when_asked() {
        assert_eq!(parse(named::<Sampler>(), "nearest"), Ok(Sampler::Nearest));
        assert_eq!(
            parse(named_or_parse::<Projection>(), "Spherical"),
            Ok(Projection::Equirect)
        );
        assert!(parse(named::<Projection>(), "spherical").is_err());
        let e = parse(named::<Sampler>(), "cubic").unwrap_err();
        assert!(
            e.contains("'cubic'") && e.contains("nearest, bilinear, trilinear"),
            "{e}"
        );
    }

    #[test]
    fn help_lists_every_value() {
        let names: Vec<String> = named::<Sampler>()
            .possible_values()
            .unwrap()
            .map(|v| v.get_name().to_string())
            .collect();
        assert_eq!(names, ["nearest", "bilinear", "trilinear"]);
    }
}
