//! Import time grows no faster than linear-ish in a hostile file's size.
//!
//! Each shape puts `n` of one thing on one prim where a real asset has a few: properties,
//! children, time samples, relationship targets, connections, dictionary entries, variants,
//! variant sets (each selected), inherited and specialized classes, internal references,
//! apiSchemas entries, sublayers, references, a PointInstancer's prototypes (each a root prim
//! beside it). Importing the shape at `8n` once must take less than 3.75 times the CPU time
//! of importing it at `n` eight times (a ratio under 30 for 8× the size): linear growth
//! gives about 1, quadratic 8. Only user CPU time of the import itself counts (not writing
//! the files, not the kernel's file opens), summed over the process's threads since the
//! usda parser runs on a thread of its own; this test is alone in its binary so no other
//! test adds to it. Noise only slows one side, so a shape passes if any of three attempts
//! does; a quadratic path fails all three. The sizes and the growth
//! before and after the fixes are in docs/usd.md ("Hostile files: time linear in size").

#![cfg(target_os = "linux")]

use std::fmt::Write as _;
use std::path::Path;

/// The size factor between the two imports, and the bound on the CPU-time ratio of one
/// import at `GROWTH · n` to `GROWTH` imports at `n`.
const GROWTH: usize = 8;
const MAX_RATIO: f64 = 30.0 / GROWTH as f64;

/// User CPU time of this process so far, in clock ticks (`utime` of `/proc/self/stat`).
fn user_ticks() -> u64 {
    let stat = std::fs::read_to_string("/proc/self/stat").expect("/proc/self/stat");
    // Fields after the command name, which is in parentheses and may hold spaces.
    let rest = &stat[stat.rfind(')').expect("a command name") + 2..];
    rest.split(' ').nth(11).and_then(|t| t.parse().ok()).expect("utime")
}

/// One prim `P` with `body` inside and `meta` in its metadata.
fn prim(meta: &str, body: &str) -> String {
    format!("#usda 1.0\ndef Xform \"P\" (\n{meta}\n)\n{{\n{body}}}\n")
}

fn list(n: usize, item: impl Fn(usize) -> String) -> String {
    (0..n).map(item).collect::<Vec<_>>().join(", ")
}

fn lines(n: usize, line: impl Fn(usize) -> String) -> String {
    (0..n).fold(String::new(), |mut s, i| {
        let _ = writeln!(s, "{}", line(i));
        s
    })
}

/// Writes the shape's root layer (and the small files it names) into `dir`; returns the root.
fn write_shape(shape: &str, n: usize, dir: &Path) -> std::path::PathBuf {
    let text = match shape {
        "properties" => prim("", &lines(n, |i| format!("    float a{i} = {i}"))),
        "children" => prim("", &lines(n, |i| format!("    def Xform \"c{i}\"\n    {{\n    }}"))),
        "time samples" => prim(
            "",
            &format!(
                "    double3 xformOp:translate.timeSamples = {{ {} }}\n    uniform token[] xformOpOrder = [\"xformOp:translate\"]\n",
                list(n, |i| format!("{i}: ({i}, 0, 0)"))
            ),
        ),
        "targets" => prim("", &format!("    rel r = [{}]\n", list(n, |i| format!("</P/c{i}>")))),
        "connections" => prim("", &format!("    float x.connect = [{}]\n", list(n, |i| format!("</P.a{i}>")))),
        "dictionary" => {
            prim(&format!("    customData = {{\n{}    }}", lines(n, |i| format!("        int k{i} = {i}"))), "")
        }
        "variants" => prim(
            "    variants = { string s = \"v0\" }\n    prepend variantSets = \"s\"",
            &format!("    variantSet \"s\" = {{\n{}    }}\n", lines(n, |i| format!("        \"v{i}\" {{\n        }}"))),
        ),
        "variant sets" => prim(
            &format!(
                "    variants = {{ {} }}\n    prepend variantSets = [{}]",
                list(n, |i| format!("string s{i} = \"v\"")).replace(", ", "; "),
                list(n, |i| format!("\"s{i}\""))
            ),
            &lines(n, |i| {
                format!(
                    "    variantSet \"s{i}\" = {{\n        \"v\" {{\n            float a{i} = {i}\n        }}\n    }}"
                )
            }),
        ),
        "inherits" => format!(
            "#usda 1.0\n{}def Xform \"P\" (\n    prepend inherits = [{}]\n)\n{{\n}}\n",
            lines(n, |i| format!("class \"C{i}\"\n{{\n    float a{i} = {i}\n}}")),
            list(n, |i| format!("</C{i}>"))
        ),
        "prototypes" => format!(
            "#usda 1.0\ndef PointInstancer \"P\"\n{{\n    rel prototypes = [{}]\n    int[] protoIndices = [{}]\n    \
             point3f[] positions = [{}]\n}}\n{}",
            list(n, |i| format!("</s{i}>")),
            list(n, |i| i.to_string()),
            list(n, |i| format!("({i}, 0, 0)")),
            lines(n, |i| format!("def Sphere \"s{i}\"\n{{\n}}"))
        ),
        "specializes" => format!(
            "#usda 1.0\n{}def Xform \"P\" (\n    prepend specializes = [{}]\n)\n{{\n}}\n",
            lines(n, |i| format!("class \"C{i}\"\n{{\n    float a{i} = {i}\n}}")),
            list(n, |i| format!("</C{i}>"))
        ),
        "internal references" => format!(
            "#usda 1.0\n{}def Xform \"P\" (\n    prepend references = [{}]\n)\n{{\n}}\n",
            lines(n, |i| format!("def Xform \"R{i}\"\n{{\n    float a{i} = {i}\n}}")),
            list(n, |i| format!("</R{i}>"))
        ),
        "apiSchemas" => prim(&format!("    prepend apiSchemas = [{}]", list(n, |i| format!("\"S{i}API\""))), ""),
        "sublayers" => {
            for i in 0..n {
                let layer = format!("#usda 1.0\nover \"P\"\n{{\n    float a{i} = {i}\n}}\n");
                std::fs::write(dir.join(format!("l{i}.usda")), layer).unwrap();
            }
            format!(
                "#usda 1.0\n(\n    subLayers = [{}]\n)\ndef Xform \"P\"\n{{\n}}\n",
                list(n, |i| format!("@./l{i}.usda@"))
            )
        }
        "references" => {
            for i in 0..n {
                let layer = format!("#usda 1.0\ndef Xform \"R\"\n{{\n    float a{i} = {i}\n}}\n");
                std::fs::write(dir.join(format!("r{i}.usda")), layer).unwrap();
            }
            prim(&format!("    prepend references = [{}]", list(n, |i| format!("@./r{i}.usda@</R>"))), "")
        }
        other => panic!("no shape {other}"),
    };
    let root = dir.join("root.usda");
    std::fs::write(&root, text).unwrap();
    root
}

/// User CPU ticks of `times` imports of `root`.
fn import_ticks(root: &Path, times: usize) -> u64 {
    let start = user_ticks();
    for _ in 0..times {
        host_usd::load(root).unwrap_or_else(|e| panic!("{}: {e}", root.display()));
    }
    user_ticks() - start
}

/// The CPU-time ratio of one import at `GROWTH · n` to `GROWTH` imports at `n`.
fn growth_ratio(shape: &str, n: usize) -> (f64, u64, u64) {
    let small_dir = tempfile::Builder::new().prefix("ppis-usd-hostile-").tempdir().unwrap();
    let large_dir = tempfile::Builder::new().prefix("ppis-usd-hostile-").tempdir().unwrap();
    let small = write_shape(shape, n, small_dir.path());
    let large = write_shape(shape, GROWTH * n, large_dir.path());
    import_ticks(&small, 1); // warm the allocator and the file cache
    let small_ticks = import_ticks(&small, GROWTH);
    let large_ticks = import_ticks(&large, 1);
    (large_ticks as f64 / small_ticks.max(1) as f64, small_ticks, large_ticks)
}

/// Each shape at `n` and `8n` (a quarter of that in a debug build), sized so that the `8n`
/// import takes a tenth of a second or more in a release build.
#[test]
fn import_time_grows_linearly_with_hostile_sizes() {
    let scale = if cfg!(debug_assertions) { 4 } else { 1 };
    let shapes = [
        ("properties", 6_000),
        ("children", 4_000),
        ("time samples", 40_000),
        ("targets", 40_000),
        ("connections", 40_000),
        ("dictionary", 20_000),
        ("variants", 4_000),
        ("variant sets", 1_000),
        ("inherits", 1_000),
        ("specializes", 1_000),
        ("internal references", 1_000),
        ("apiSchemas", 40_000),
        ("prototypes", 500),
        ("sublayers", 500),
        ("references", 500),
    ];
    let mut failures = Vec::new();
    for (shape, n) in shapes {
        let n = n / scale;
        let attempts: Vec<(f64, u64, u64)> =
            (0..3).map(|_| growth_ratio(shape, n)).take_while(|(r, ..)| *r >= MAX_RATIO).collect();
        if attempts.len() == 3 {
            failures
                .push(format!("{shape} (n = {n}): 8n takes {attempts:?} × (ratio, ticks of 8 at n, ticks of 1 at 8n)"));
        }
    }
    assert!(failures.is_empty(), "super-linear import time, ratio bound {MAX_RATIO}:\n{}", failures.join("\n"));
}
