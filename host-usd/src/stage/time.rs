//! The time a stage's values are read at, as USD's `UsdTimeCode` names it: a number, or one
//! of its two sentinels.

use std::fmt;

/// The time code attribute values are resolved at.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum TimeCode {
    /// `UsdTimeCode::Default()`: each attribute's default value; time samples are not
    /// consulted (an attribute with samples only has no value).
    Default,
    /// `UsdTimeCode::EarliestTime()`: each attribute's first time sample, else its default
    /// value. What Pixar's `usdrecord` renders when no frame is given, so an animated stage
    /// shows its first pose rather than whatever its default values hold.
    Earliest,
    /// A numeric time code: samples interpolated linearly between the bracketing ones
    /// (quaternions spherically), held before the first and after the last; the default value
    /// where the attribute has no samples.
    At(f64),
}

impl TimeCode {
    /// openusd's time for a query, `None` for the default value.
    pub(super) fn query(self) -> Option<openusd::usd::TimeCode> {
        match self {
            TimeCode::Default => None,
            TimeCode::Earliest => Some(openusd::usd::TimeCode::EARLIEST),
            TimeCode::At(t) => Some(openusd::usd::TimeCode::new(t)),
        }
    }
}

impl fmt::Display for TimeCode {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            TimeCode::Default => f.write_str("default"),
            TimeCode::Earliest => f.write_str("earliest"),
            TimeCode::At(t) => write!(f, "{t}"),
        }
    }
}

impl std::str::FromStr for TimeCode {
    type Err = String;

    /// A finite number, `default` or `earliest`.
    fn from_str(text: &str) -> Result<Self, String> {
        match text {
            "default" => Ok(TimeCode::Default),
            "earliest" => Ok(TimeCode::Earliest),
            _ => match text.parse::<f64>() {
                Ok(t) if t.is_finite() => Ok(TimeCode::At(t)),
                _ => Err(format!("{text:?} is not a time code (a finite number, `default` or `earliest`)")),
            },
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_numbers_and_the_sentinels() {
        assert_eq!("12.5".parse::<TimeCode>(), Ok(TimeCode::At(12.5)));
        assert_eq!("-3".parse::<TimeCode>(), Ok(TimeCode::At(-3.0)));
        assert_eq!("default".parse::<TimeCode>(), Ok(TimeCode::Default));
        assert_eq!("earliest".parse::<TimeCode>(), Ok(TimeCode::Earliest));
        for bad in ["", "nan", "inf", "1e999", "frame1"] {
            assert!(bad.parse::<TimeCode>().is_err(), "{bad}");
        }
        assert_eq!(TimeCode::At(10.0).to_string(), "10");
        assert_eq!(TimeCode::At(1.5).to_string(), "1.5");
    }
}
