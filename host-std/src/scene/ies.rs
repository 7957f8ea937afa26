//! IES photometric files (ANSI/IESNA LM-63): the 1986 and 1991 variants and LM-63-1995, -2002
//! and -2019, with `TILT=NONE` and type C photometry (types A and B are refused by name). The
//! candela table becomes the core's [`IntensityProfile`] (angles in radians, every value times
//! the candela multiplier, the ballast factor and the ballast-lamp factor), held for the rest of
//! the program: a profile is interned once per distinct table ([`IesFile::profile`]).
//!
//! A file that is not one is an error naming what is wrong and where; sizes are bounded
//! ([`MAX_BYTES`], [`MAX_ANGLES`], [`MAX_VALUES`]), so a hostile file costs at most a linear read.

use sampler_core::light::IntensityProfile;
use std::sync::Mutex;

/// The largest file read.
pub const MAX_BYTES: usize = 16 << 20;
/// The most vertical or horizontal angles.
pub const MAX_ANGLES: usize = 4096;
/// The most candela values.
pub const MAX_VALUES: usize = 1 << 20;

/// A parsed IES file.
#[derive(Clone, Debug, PartialEq)]
pub struct IesFile {
    /// The format the first line names (`LM-63-2002`, …, or `LM-63-1986` without one).
    pub format: String,
    /// Vertical angles in degrees.
    pub vertical_deg: Vec<f32>,
    /// Horizontal angles in degrees.
    pub horizontal_deg: Vec<f32>,
    /// Candela, times the file's multipliers: `candela[h · vertical + v]`.
    pub candela: Vec<f32>,
}

/// The numbers of the file, read in order, each an error naming it when missing or malformed.
struct Numbers<'a> {
    tokens: std::str::Split<'a, [char; 5]>,
}

impl<'a> Numbers<'a> {
    fn new(text: &'a str) -> Self {
        Self { tokens: text.split([' ', '\t', '\r', '\n', ',']) }
    }

    fn next_token(&mut self) -> Option<&'a str> {
        loop {
            let t = self.tokens.next()?;
            if !t.is_empty() {
                return Some(t);
            }
        }
    }

    fn number(&mut self, what: &str) -> Result<f64, String> {
        self.number_or_else(|| what.to_string())
    }

    /// The next number; `what` names it only when it is missing or malformed.
    fn number_or_else(&mut self, what: impl FnOnce() -> String) -> Result<f64, String> {
        let Some(t) = self.next_token() else {
            return Err(format!("the file ends before {}", what()));
        };
        match t.parse::<f64>() {
            Ok(v) if v.is_finite() => Ok(v),
            _ => Err(format!("{} is `{}`, not a finite number", what(), t.chars().take(40).collect::<String>())),
        }
    }

    fn count(&mut self, what: &str, min: usize, max: usize) -> Result<usize, String> {
        let v = self.number(what)?;
        if v.fract() != 0.0 || v < min as f64 || v > max as f64 {
            return Err(format!("{what} is {v}, not a whole number from {min} to {max}"));
        }
        Ok(v as usize)
    }

    fn factor(&mut self, what: &str) -> Result<f64, String> {
        let v = self.number(what)?;
        if v < 0.0 { Err(format!("{what} is negative ({v})")) } else { Ok(v) }
    }

    fn remaining(&mut self) -> usize {
        let mut n = 0;
        while self.next_token().is_some() {
            n += 1;
        }
        n
    }
}

/// Parses an IES file's bytes (text; bytes that are not UTF-8 only matter in its keywords).
pub fn parse(bytes: &[u8]) -> Result<IesFile, String> {
    if bytes.len() > MAX_BYTES {
        return Err(format!("{} bytes: more than the {} MiB an IES file may hold here", bytes.len(), MAX_BYTES >> 20));
    }
    let text = String::from_utf8_lossy(bytes);
    let first = text.lines().next().unwrap_or("").trim();
    let format = match first {
        f if f.starts_with("IESNA:LM-63-") || f.starts_with("IES:LM-63-") => {
            f.split_once("LM-63-").map_or("", |(_, y)| y).chars().take(4).collect::<String>()
        }
        f if f.starts_with("IESNA91") => "1991".into(),
        _ => "1986".into(),
    };
    let format = format!("LM-63-{format}");
    let (tilt_at, tilt) = tilt_line(&text).ok_or("no TILT= line: not an IES LM-63 photometric file")?;
    if !tilt.eq_ignore_ascii_case("NONE") {
        return Err(format!("TILT={tilt}: lamp-tilt data is not supported (only TILT=NONE)"));
    }
    let mut n = Numbers::new(&text[tilt_at..]);
    table(&mut n, format)
}

/// Where the first line that starts with `TILT=` ends, and its value.
fn tilt_line(text: &str) -> Option<(usize, &str)> {
    let mut at = 0;
    for line in text.split_inclusive('\n') {
        at += line.len();
        if let Some(rest) = line.trim_start().strip_prefix("TILT")
            && let Some(value) = rest.trim_start().strip_prefix('=')
        {
            return Some((at, value.trim()));
        }
    }
    None
}

/// The numbers after the TILT line: the two header lines, the angles and the candela table.
fn table(n: &mut Numbers<'_>, format: String) -> Result<IesFile, String> {
    n.count("the number of lamps", 1, usize::MAX >> 12)?;
    n.number("the lumens per lamp")?;
    let multiplier = n.factor("the candela multiplier")?;
    let v = n.count("the number of vertical angles", 2, MAX_ANGLES)?;
    let h = n.count("the number of horizontal angles", 1, MAX_ANGLES)?;
    if v * h > MAX_VALUES {
        return Err(format!("{v} × {h} candela values: more than the {MAX_VALUES} read here"));
    }
    match n.number("the photometric type")? {
        1.0 => {}
        2.0 => return Err("type B photometry is not supported (type C only)".into()),
        3.0 => return Err("type A photometry is not supported (type C only)".into()),
        t => return Err(format!("photometric type {t} is none of 1 (C), 2 (B), 3 (A)")),
    }
    for what in ["the units type", "the width", "the length", "the height"] {
        n.number(what)?;
    }
    let ballast = n.factor("the ballast factor")?;
    let lamp_factor = n.factor("the ballast-lamp photometric factor")?;
    n.number("the input watts")?;
    let scale = multiplier * ballast * lamp_factor;
    let mut angles = |count: usize, what: &str, max: f64| -> Result<Vec<f32>, String> {
        let mut out: Vec<f32> = Vec::with_capacity(count);
        for i in 0..count {
            let a = n.number(&format!("{what} angle {}", i + 1))?;
            if !(0.0..=max).contains(&a) {
                return Err(format!("{what} angle {a}° is outside 0°–{max}°"));
            }
            if out.last().is_some_and(|&p| f64::from(p) >= a) {
                return Err(format!("{what} angles do not increase ({} then {a})", out[out.len() - 1]));
            }
            out.push(a as f32);
        }
        Ok(out)
    };
    let vertical_deg = angles(v, "vertical", 180.0)?;
    let horizontal_deg = angles(h, "horizontal", 360.0)?;
    let mut candela = Vec::with_capacity(v * h);
    for hd in &horizontal_deg {
        for vd in &vertical_deg {
            let at = || format!("the candela value at {vd}° vertical, {hd}° horizontal");
            let c = n.number_or_else(at)?;
            if c < 0.0 {
                return Err(format!("{} is negative ({c})", at()));
            }
            let scaled = (c * scale) as f32;
            if !scaled.is_finite() {
                return Err(format!("{} times the multipliers overflows", at()));
            }
            candela.push(scaled);
        }
    }
    let extra = n.remaining();
    if extra > 0 {
        return Err(format!("{extra} values after the candela table (expected {v} × {h})"));
    }
    let file = IesFile { format, vertical_deg, horizontal_deg, candela };
    file.check()?;
    Ok(file)
}

/// The interned profiles: each distinct table is leaked once and shared by every light that
/// uses it, for the rest of the program.
static PROFILES: Mutex<Vec<&'static IntensityProfile<'static>>> = Mutex::new(Vec::new());

impl IesFile {
    /// The angles in radians, as the core takes them.
    fn radians(&self) -> (Vec<f32>, Vec<f32>) {
        let rad = |a: &[f32]| a.iter().map(|d| d.to_radians()).collect::<Vec<_>>();
        (rad(&self.vertical_deg), rad(&self.horizontal_deg))
    }

    /// The table is a profile the core accepts (its horizontal angles one of type C's ranges).
    fn check(&self) -> Result<(), String> {
        let (v, h) = self.radians();
        IntensityProfile::new(&v, &h, &self.candela).map(|_| ()).map_err(|e| match e {
            sampler_core::light::ProfileError::BadHorizontal => format!(
                "horizontal angles {}°–{}° are none of type C's ranges (0°, 0°–90°, 0°–180°, 90°–270°, 0°–360°)",
                self.horizontal_deg[0],
                self.horizontal_deg[self.horizontal_deg.len() - 1]
            ),
            other => other.to_string(),
        })
    }

    /// The core's profile of this table, interned.
    #[must_use]
    pub fn profile(&self) -> &'static IntensityProfile<'static> {
        let (v, h) = self.radians();
        let mut store = PROFILES.lock().unwrap_or_else(std::sync::PoisonError::into_inner);
        let same = |p: &&IntensityProfile<'_>| {
            let eq =
                |a: &[f32], b: &[f32]| a.len() == b.len() && a.iter().zip(b).all(|(x, y)| x.to_bits() == y.to_bits());
            eq(p.vertical(), &v) && eq(p.horizontal(), &h) && eq(p.intensities(), &self.candela)
        };
        if let Some(p) = store.iter().find(|p| same(p)) {
            return p;
        }
        let leak = |a: Vec<f32>| -> &'static [f32] { Box::leak(a.into_boxed_slice()) };
        let (v, h, c) = (leak(v), leak(h), leak(self.candela.clone()));
        let profile = IntensityProfile::new(v, h, c).expect("checked when parsed");
        let p: &'static IntensityProfile<'static> = Box::leak(Box::new(profile));
        store.push(p);
        p
    }

    /// One line for `ppis info`: format, grid, symmetry and peak.
    #[must_use]
    pub fn describe(&self) -> String {
        let (v, h) = (&self.vertical_deg, &self.horizontal_deg);
        let peak = self.candela.iter().fold(0.0f32, |m, &c| m.max(c));
        format!(
            "{}, type C, {} vertical angles {}°–{}° × {} horizontal {}°–{}°, peak {peak} cd",
            self.format,
            v.len(),
            v[0],
            v[v.len() - 1],
            h.len(),
            h[0],
            h[h.len() - 1]
        )
    }
}
