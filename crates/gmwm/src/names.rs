//! Closed sets of values known by name: an option's choices (`rule = navigation`, `--format
//! f64`). Each set declares its names once, with [`named_values!`](crate::names), in the order
//! lists show them; the list, the parsing and the display come from that one declaration, so a
//! front end (the CLI's choices, the Python keywords) never copies them.

use crate::error::ParamError;

/// A closed set of values, each known by one name.
///
/// # Examples
/// ```
/// use gmwm::Named;
/// use gmwm::SelectionRule;
///
/// assert_eq!(SelectionRule::names(), ["navigation", "parsimonious", "wic-minimum"]);
/// assert_eq!(SelectionRule::from_name("Parsimonious"), Ok(SelectionRule::Parsimonious));
/// assert_eq!(
///     SelectionRule::from_name("best").unwrap_err().to_string(),
///     "invalid rule = best: one of navigation, parsimonious, wic-minimum"
/// );
/// ```
pub trait Named: Copy + PartialEq + 'static {
    /// What a value of the set is, as messages call it (`rule`, `format`).
    const WHAT: &'static str;
    /// Every value, in the order lists show them (the default first where there is one).
    const VALUES: &'static [Self];

    /// The value's name.
    fn name(self) -> &'static str;

    /// Every name, in the order of [`VALUES`](Self::VALUES).
    fn names() -> Vec<&'static str> {
        Self::VALUES.iter().map(|v| v.name()).collect()
    }

    /// The value named `text`, ignoring ASCII case and surrounding white space.
    ///
    /// # Errors
    /// [`ParamError`] naming the set ([`WHAT`](Self::WHAT)) and listing its names.
    fn from_name(text: &str) -> Result<Self, ParamError> {
        let t = text.trim();
        Self::VALUES
            .iter()
            .copied()
            .find(|v| v.name().eq_ignore_ascii_case(t))
            .ok_or_else(|| {
                ParamError::new(
                    Self::WHAT,
                    text,
                    format!("one of {}", Self::names().join(", ")),
                )
            })
    }
}

/// Declares the names of an enum's values once: implements [`Named`] (its `match` is
/// exhaustive: every value has a name) and, when listed in `derive(...)`, `FromStr`
/// ([`Named::from_name`]) and `Display` (the name).
///
/// ```text
/// named_values!(Weighting, "weights", { Fast => "fast", Diag => "diag" }, derive(FromStr, Display));
/// named_values!(InputFormat, "format", { Auto => "auto", ImuRecord(ImuRecordType::Imar) => "imar", ... });
/// ```
macro_rules! named_values {
    (
        $ty:ident, $what:literal,
        { $($v:ident $(($($inner:tt)*))? => $name:literal),+ $(,)? }
        $(, derive($($derive:ident),+))?
    ) => {
        impl $crate::names::Named for $ty {
            const WHAT: &'static str = $what;
            const VALUES: &'static [Self] = &[$(Self::$v $(($($inner)*))?),+];

            fn name(self) -> &'static str {
                match self {
                    $(Self::$v $(($($inner)*))? => $name),+
                }
            }
        }
        $($($crate::names::named_values!(@$derive $ty);)+)?
    };
    (@FromStr $ty:ident) => {
        impl ::std::str::FromStr for $ty {
            type Err = $crate::error::ParamError;

            /// The value of that name ([`Named::from_name`](crate::names::Named::from_name)).
            fn from_str(s: &str) -> Result<Self, Self::Err> {
                <Self as $crate::names::Named>::from_name(s)
            }
        }
    };
    (@Display $ty:ident) => {
        impl ::std::fmt::Display for $ty {
            /// The value's name ([`Named::name`](crate::names::Named::name)).
            fn fmt(&self, f: &mut ::std::fmt::Formatter<'_>) -> ::std::fmt::Result {
                f.write_str(<Self as $crate::names::Named>::name(*self))
            }
        }
    };
}
pub(crate) use named_values;

#[cfg(test)]
mod tests {
    use super::*;

    #[derive(Debug, Clone, Copy, PartialEq)]
    enum Shade {
        Light,
        Dark,
    }

    named_values!(Shade, "shade", { Light => "light", Dark => "dark" }, derive(FromStr, Display));

    #[test]
    fn named_values_give_names_parsing_and_display() {
        assert_eq!(Shade::names(), ["light", "dark"]);
        assert_eq!(Shade::VALUES, [Shade::Light, Shade::Dark]);
        assert_eq!(" DARK ".parse::<Shade>(), Ok(Shade::Dark));
        assert_eq!(Shade::Light.to_string(), "light");
        assert_eq!(
            "grey".parse::<Shade>().unwrap_err(),
            ParamError::new("shade", "grey", "one of light, dark")
        );
    }

    #[test]
    fn every_option_set_reads_back_its_names() {
        fn check<T: Named + std::fmt::Debug + std::fmt::Display + std::str::FromStr>() {
            for v in T::VALUES {
                assert_eq!(T::from_name(v.name()).ok(), Some(*v), "{}", T::WHAT);
                assert_eq!(v.name().parse::<T>().ok(), Some(*v), "{}", T::WHAT);
                assert_eq!(v.to_string(), v.name(), "{}", T::WHAT);
            }
        }
        check::<crate::calib::AxisPolicy>();
        check::<crate::selection::SelectionRule>();
        check::<crate::selection::OptimismMethod>();
        check::<crate::selection::OptimismConvention>();
        check::<crate::inference::CovarianceMethod>();
        check::<crate::Weighting>();
        check::<crate::imu::TimeUnit>();
        check::<crate::imu::InputFormat>();
        check::<crate::imu::HeaderMode>();
        check::<crate::Transform>();
        check::<crate::RobustConvention>();
        check::<crate::AllanKind>();
        check::<crate::AvConvention>();
    }
}
