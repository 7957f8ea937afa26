//! A line of the report: a method, and its K where the sweep varies K.

use crate::plan::Method;
use std::fmt;

/// A method at one K (BRDF samples per product sampler): the renders of one line of the
/// report's plots and one column of its tables. `brdf_samples` is `None` where the sweep has
/// one K or the method builds no product sampler, so a report of one K names its lines by
/// their methods alone.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Series {
    /// The method.
    pub method: Method,
    /// Its K, where the sweep varies K and the method reads it.
    pub brdf_samples: Option<usize>,
}

impl Series {
    /// The series of `method` in a sweep over `ks`: with its K when there is more than one and
    /// the method reads it.
    #[must_use]
    pub fn of(method: Method, ks: &[usize], k: usize) -> Self {
        let swept = ks.len() > 1 && method.reads_brdf_samples();
        Self { method, brdf_samples: swept.then_some(k) }
    }
}

impl From<Method> for Series {
    fn from(method: Method) -> Self {
        Self { method, brdf_samples: None }
    }
}

impl fmt::Display for Series {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.brdf_samples {
            Some(k) => write!(f, "{} K={k}", self.method),
            None => write!(f, "{}", self.method),
        }
    }
}
