//! IES photometric files (`host-usd/tests/fixtures/ies/`, written by hand): each format variant
//! parses to its table with the multipliers applied; each horizontal symmetry reads back the
//! table at its stored angles and mirrors as LM-63 says; a profile is interned once; and
//! malformed or hostile files are errors naming the problem, never a panic, in bounded time.

use host_std::scene::ies::{self, IesFile, MAX_ANGLES};
use sampler_core::light::HorizontalSymmetry;
use sampler_core::rng::Pcg32;
use std::path::PathBuf;

fn fixture(name: &str) -> Vec<u8> {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../host-usd/tests/fixtures/ies").join(name);
    std::fs::read(path).unwrap()
}

fn parsed(name: &str) -> IesFile {
    ies::parse(&fixture(name)).unwrap_or_else(|e| panic!("{name}: {e}"))
}

#[test]
fn each_format_parses_with_its_multipliers() {
    let down = parsed("downlight_2002.ies");
    assert_eq!(down.format, "LM-63-2002");
    assert_eq!(down.vertical_deg, [0.0, 15.0, 30.0, 45.0, 60.0, 75.0, 90.0]);
    assert_eq!(down.horizontal_deg, [0.0]);
    // Candela multiplier 2 × ballast 1 × ballast-lamp factor 1.
    assert_eq!(down.candela[0], 800.0);
    let bi = parsed("bilateral_1995.ies");
    assert_eq!(bi.format, "LM-63-1995");
    // Multiplier 1 × ballast 0.5 × 2.0; CRLF line ends and commas.
    assert_eq!((bi.candela[0], bi.candela[24]), (100.0, 20.0));
    let quad = parsed("quadrant_1986.ies");
    assert_eq!((quad.format.as_str(), quad.candela.len()), ("LM-63-1986", 12));
    assert_eq!(parsed("full_1991.ies").format, "LM-63-1991");
    assert_eq!(parsed("wall_90_270.ies").horizontal_deg, [90.0, 180.0, 270.0]);
    assert!(down.describe().contains("7 vertical angles 0°–90° × 1 horizontal"), "{}", down.describe());
}

#[test]
fn symmetries_read_back_the_table_and_mirror() {
    let d = |x: f32| x.to_radians();
    let close = |a: f32, b: f32| (a - b).abs() <= 1e-3 * b.abs().max(1.0);
    let cases = [
        ("downlight_2002.ies", HorizontalSymmetry::Rotational),
        ("bilateral_1995.ies", HorizontalSymmetry::Bilateral),
        ("quadrant_1986.ies", HorizontalSymmetry::Quadrant),
        ("full_1991.ies", HorizontalSymmetry::Full),
        ("wall_90_270.ies", HorizontalSymmetry::Bilateral90),
    ];
    for (name, symmetry) in cases {
        let file = parsed(name);
        let p = file.profile();
        assert_eq!(p.symmetry(), symmetry, "{name}");
        let nv = file.vertical_deg.len();
        for (j, &h) in file.horizontal_deg.iter().enumerate() {
            for (k, &v) in file.vertical_deg.iter().enumerate() {
                let want = file.candela[j * nv + k];
                assert!(close(p.eval(d(v), d(h)), want), "{name} at {v}°, {h}°: {} against {want}", p.eval(d(v), d(h)));
            }
        }
        // The mirror images of 30° about each symmetry's planes.
        let mirrors: &[f32] = match symmetry {
            HorizontalSymmetry::Rotational => &[30.0, 123.0, 300.0],
            HorizontalSymmetry::Quadrant => &[30.0, 150.0, 210.0, 330.0],
            HorizontalSymmetry::Bilateral => &[30.0, 330.0],
            HorizontalSymmetry::Bilateral90 => &[150.0, 30.0],
            HorizontalSymmetry::Full => &[30.0],
        };
        for &m in mirrors {
            assert!(
                close(p.eval(d(40.0), d(m)), p.eval(d(40.0), d(mirrors[0]))),
                "{name}: {m}° mirrors {}°",
                mirrors[0]
            );
        }
    }
    // No symmetry: between 270° and 360° the table runs back to its 0° row.
    let full = parsed("full_1991.ies").profile();
    assert!(close(full.eval(d(90.0), d(315.0)), 50.0), "{}", full.eval(d(90.0), d(315.0)));
    // A downlight sends nothing above the horizon.
    assert_eq!(parsed("downlight_2002.ies").profile().eval(d(91.0), 0.0), 0.0);
}

#[test]
fn a_table_is_interned_once() {
    let a = parsed("quadrant_1986.ies").profile();
    let b = parsed("quadrant_1986.ies").profile();
    assert!(std::ptr::eq(a, b));
    assert!(!std::ptr::eq(a, parsed("full_1991.ies").profile()));
}

/// A valid body after `TILT=NONE`, to break one field at a time.
const BODY: &str = "1 1000 1 3 1 1 1 0 0 0\n1 1 10\n0 45 90\n0\n100 50 0\n";

#[test]
fn malformed_files_are_errors_that_say_what_is_wrong() {
    let with = |body: &str| format!("IESNA:LM-63-2002\nTILT=NONE\n{body}");
    let cases: Vec<(String, &str)> = vec![
        ("IESNA:LM-63-2002\n[TEST] x\n1 2 3".into(), "no TILT= line"),
        (format!("IESNA:LM-63-2002\nTILT=INCLUDE\n{BODY}"), "TILT=INCLUDE"),
        (format!("IESNA:LM-63-2002\nTILT=lamp.tlt\n{BODY}"), "only TILT=NONE"),
        (with(&BODY.replace("3 1 1 1 0", "3 1 2 1 0")), "type B photometry is not supported"),
        (with(&BODY.replace("3 1 1 1 0", "3 1 3 1 0")), "type A photometry is not supported"),
        (with(&BODY.replace("3 1 1 1 0", "3 1 7 1 0")), "photometric type 7"),
        (with(&BODY.replace("100 50 0", "100 -50 0")), "at 45° vertical, 0° horizontal is negative"),
        (with(&BODY.replace("100 50 0", "100 50")), "the file ends before the candela value at 90°"),
        (with(&format!("{BODY}7 8\n")), "2 values after the candela table"),
        (with(&BODY.replace("100 50 0", "100 abc 0")), "is `abc`, not a finite number"),
        (with(&BODY.replace("100 50 0", "100 nan 0")), "is `nan`, not a finite number"),
        (with(&BODY.replace("0 45 90", "0 90 45")), "vertical angles do not increase"),
        (with(&BODY.replace("0 45 90", "0 45 190")), "outside 0°–180°"),
        (with(&BODY.replace("\n0\n", "\n30\n")), "none of type C's ranges"),
        (with(&BODY.replace("1000 1 3 1", "1000 1 3.5 1")), "not a whole number"),
        (with(&BODY.replace("1000 1 3 1", "1000 1 1 1")), "the number of vertical angles is 1"),
        (with(&BODY.replace("1000 1 3 1", "1000 -2 3 1")), "the candela multiplier is negative"),
        (with(&BODY.replace("1000 1 3 1", &format!("1000 1 {} 1", MAX_ANGLES + 1))), "not a whole number from 2"),
        (with(&BODY.replace("1000 1 3 1", "1000 1 4000 4000")), "more than the 1048576 read here"),
        (with(&BODY.replace("100 50 0", "1e30 0 0").replace("1000 1 3", "1000 1e20 3")), "overflows"),
        (String::new(), "no TILT= line"),
    ];
    for (text, expected) in cases {
        match ies::parse(text.as_bytes()) {
            Ok(_) => panic!("accepted: {text:?}"),
            Err(e) => assert!(e.contains(expected), "{text:?}: `{e}` does not say `{expected}`"),
        }
    }
    let huge = vec![b' '; ies::MAX_BYTES + 1];
    assert!(ies::parse(&huge).unwrap_err().contains("MiB"));
}

/// Mutated copies of every fixture (bytes flipped, dropped, duplicated, digits changed) parse
/// or fail with a message; none panics or takes long.
#[test]
fn mutated_files_never_panic() {
    let mut rng = Pcg32::new(21, 7);
    let names = ["downlight_2002.ies", "bilateral_1995.ies", "quadrant_1986.ies", "full_1991.ies", "wall_90_270.ies"];
    let start = std::time::Instant::now();
    let mut errors = 0;
    for round in 0..4000 {
        let mut bytes = fixture(names[round % names.len()]);
        for _ in 0..1 + rng.next_u32() % 4 {
            let at = rng.next_u32() as usize % bytes.len().max(1);
            match rng.next_u32() % 4 {
                0 => bytes[at] = rng.next_u32() as u8,
                1 => {
                    bytes.remove(at);
                }
                2 => bytes.insert(at, b"0123456789-.e ,\n"[rng.next_u32() as usize % 16]),
                _ => bytes.truncate(at),
            }
            if bytes.is_empty() {
                break;
            }
        }
        match ies::parse(&bytes) {
            Ok(f) => {
                let _ = f.profile().mean_intensity();
            }
            Err(e) => {
                errors += 1;
                assert!(!e.is_empty());
            }
        }
    }
    assert!(errors > 1000, "{errors} of 4000 mutations refused");
    assert!(start.elapsed().as_secs_f64() < 20.0);
}
