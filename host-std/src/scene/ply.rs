//! PLY meshes (ASCII, binary little- and big-endian): the `vertex` element's `x`, `y`, `z` and
//! the `face` element's `vertex_indices` (or `vertex_index`) lists, fan-triangulated; every
//! other element and property is read past. The body is decoded straight into positions and
//! triangles, so a mesh of millions of faces costs what its arrays cost. Counts in the header
//! are checked against the bytes that follow before anything is sized by them.

use sampler_core::glam::Vec3;

/// A scalar property type and its size in bytes.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Scalar {
    I8,
    U8,
    I16,
    U16,
    I32,
    U32,
    F32,
    F64,
}

impl Scalar {
    fn parse(name: &str) -> Result<Self, String> {
        Ok(match name {
            "char" | "int8" => Self::I8,
            "uchar" | "uint8" => Self::U8,
            "short" | "int16" => Self::I16,
            "ushort" | "uint16" => Self::U16,
            "int" | "int32" => Self::I32,
            "uint" | "uint32" => Self::U32,
            "float" | "float32" => Self::F32,
            "double" | "float64" => Self::F64,
            _ => return Err(format!("unknown property type {name:?}")),
        })
    }

    fn size(self) -> usize {
        match self {
            Self::I8 | Self::U8 => 1,
            Self::I16 | Self::U16 => 2,
            Self::I32 | Self::U32 | Self::F32 => 4,
            Self::F64 => 8,
        }
    }

    fn decode(self, b: &[u8], big: bool) -> f64 {
        macro_rules! num {
            ($t:ty, $n:expr) => {{
                let a: [u8; $n] = b[..$n].try_into().unwrap();
                (if big { <$t>::from_be_bytes(a) } else { <$t>::from_le_bytes(a) }) as f64
            }};
        }
        match self {
            Self::I8 => b[0] as i8 as f64,
            Self::U8 => b[0] as f64,
            Self::I16 => num!(i16, 2),
            Self::U16 => num!(u16, 2),
            Self::I32 => num!(i32, 4),
            Self::U32 => num!(u32, 4),
            Self::F32 => num!(f32, 4),
            Self::F64 => num!(f64, 8),
        }
    }
}

#[derive(Debug)]
struct Property {
    name: String,
    /// `Some(count type)` for a list property.
    list: Option<Scalar>,
    kind: Scalar,
}

#[derive(Debug)]
struct Element {
    name: String,
    count: usize,
    properties: Vec<Property>,
}

#[derive(Clone, Copy, Debug, PartialEq)]
enum Format {
    Ascii,
    Binary { big: bool },
}

/// The header's elements and format, and where the body starts.
fn header(bytes: &[u8]) -> Result<(Format, Vec<Element>, usize), String> {
    let end = bytes.windows(10).position(|w| w == b"end_header").ok_or("no end_header line")?;
    let body = bytes[end..].iter().position(|&b| b == b'\n').map(|p| end + p + 1).ok_or("no body after the header")?;
    let text = std::str::from_utf8(&bytes[..end]).map_err(|_| "the header is not text")?;
    let mut lines = text.lines().map(str::trim);
    if lines.next() != Some("ply") {
        return Err("not a PLY file (no 'ply' line)".into());
    }
    let (mut format, mut elements) = (None, Vec::<Element>::new());
    for line in lines {
        let words: Vec<&str> = line.split_whitespace().collect();
        match words.as_slice() {
            [] | ["comment", ..] | ["obj_info", ..] => {}
            ["format", f, _] => {
                format = Some(match *f {
                    "ascii" => Format::Ascii,
                    "binary_little_endian" => Format::Binary { big: false },
                    "binary_big_endian" => Format::Binary { big: true },
                    _ => return Err(format!("unknown format {f:?}")),
                })
            }
            ["element", name, count] => {
                let count = count.parse().map_err(|_| format!("element {name}: bad count {count:?}"))?;
                elements.push(Element { name: name.to_string(), count, properties: Vec::new() });
            }
            ["property", "list", count, item, name] => {
                let e = elements.last_mut().ok_or("a property before any element")?;
                let (list, kind) = (Some(Scalar::parse(count)?), Scalar::parse(item)?);
                e.properties.push(Property { name: name.to_string(), list, kind });
            }
            ["property", kind, name] => {
                let e = elements.last_mut().ok_or("a property before any element")?;
                e.properties.push(Property { name: name.to_string(), list: None, kind: Scalar::parse(kind)? });
            }
            _ => return Err(format!("unknown header line {line:?}")),
        }
    }
    Ok((format.ok_or("no format line")?, elements, body))
}

/// The body's numbers, one at a time, in either encoding.
struct Reader<'a> {
    bytes: &'a [u8],
    pos: usize,
    format: Format,
}

impl Reader<'_> {
    fn next(&mut self, kind: Scalar) -> Result<f64, String> {
        match self.format {
            Format::Binary { big } => {
                let b = self.bytes.get(self.pos..self.pos + kind.size()).ok_or("the file ends inside its body")?;
                self.pos += kind.size();
                Ok(kind.decode(b, big))
            }
            Format::Ascii => {
                let rest = &self.bytes[self.pos..];
                let start =
                    rest.iter().position(|b| !b.is_ascii_whitespace()).ok_or("the file ends inside its body")?;
                let len = rest[start..].iter().position(|b| b.is_ascii_whitespace()).unwrap_or(rest.len() - start);
                self.pos += start + len;
                let word = std::str::from_utf8(&rest[start..start + len]).unwrap_or("");
                word.parse().map_err(|_| format!("not a number: {word:?}"))
            }
        }
    }

    /// The fewest bytes an element of `e` can take (a list at least its count).
    fn min_size(&self, e: &Element) -> usize {
        match self.format {
            Format::Ascii => e.properties.len().max(1) * 2,
            Format::Binary { .. } => e.properties.iter().map(|p| p.list.unwrap_or(p.kind).size()).sum::<usize>().max(1),
        }
    }
}

/// Positions and triangles of a PLY file's bytes.
pub fn parse(bytes: &[u8]) -> Result<(Vec<Vec3>, Vec<[u32; 3]>), String> {
    let (format, elements, body) = header(bytes)?;
    let mut r = Reader { bytes, pos: body, format };
    let (mut positions, mut triangles) = (Vec::new(), Vec::new());
    let mut corners: Vec<u32> = Vec::new();
    for e in &elements {
        let remaining = bytes.len() - r.pos.min(bytes.len());
        if e.count > remaining / r.min_size(e) + 1 {
            return Err(format!("element {} claims {} entries, more than the file holds", e.name, e.count));
        }
        let xyz = ["x", "y", "z"].map(|n| e.properties.iter().position(|p| p.name == n && p.list.is_none()));
        let list = e
            .properties
            .iter()
            .position(|p| p.list.is_some() && matches!(p.name.as_str(), "vertex_indices" | "vertex_index"));
        let is_vertex = e.name == "vertex";
        if is_vertex {
            if xyz.iter().any(Option::is_none) {
                return Err("the vertex element lacks x, y or z".into());
            }
            positions.reserve(e.count);
        }
        for _ in 0..e.count {
            let mut p = [0.0f32; 3];
            for (k, prop) in e.properties.iter().enumerate() {
                match prop.list {
                    None => {
                        let v = r.next(prop.kind)?;
                        if let Some(axis) = xyz.iter().position(|&i| i == Some(k)) {
                            p[axis] = v as f32;
                        }
                    }
                    Some(count_kind) => {
                        let n = r.next(count_kind)?;
                        if !(0.0..=1e6).contains(&n) || n.fract() != 0.0 {
                            return Err(format!("element {}: a list of {n} entries", e.name));
                        }
                        corners.clear();
                        for _ in 0..n as usize {
                            let i = r.next(prop.kind)?;
                            if !(0.0..=u32::MAX as f64).contains(&i) || i.fract() != 0.0 {
                                return Err(format!("a face has the vertex index {i}"));
                            }
                            corners.push(i as u32);
                        }
                        if e.name == "face" && list == Some(k) {
                            triangles.extend((2..corners.len()).map(|j| [corners[0], corners[j - 1], corners[j]]));
                        }
                    }
                }
            }
            if is_vertex {
                positions.push(Vec3::from_array(p));
            }
        }
    }
    if elements.iter().any(|e| e.name == "face" && e.count > 0) && list_missing(&elements) {
        return Err("the face element lacks a vertex_indices list".into());
    }
    Ok((positions, triangles))
}

fn list_missing(elements: &[Element]) -> bool {
    let face = elements.iter().find(|e| e.name == "face");
    face.is_some_and(|f| {
        !f.properties.iter().any(|p| p.list.is_some() && matches!(p.name.as_str(), "vertex_indices" | "vertex_index"))
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn header_text(format: &str, vertices: usize, faces: usize) -> String {
        format!(
            "ply\nformat {format} 1.0\ncomment made by a test\nelement vertex {vertices}\nproperty float x\n\
             property float y\nproperty float z\nproperty uchar red\nelement face {faces}\n\
             property list uchar int vertex_indices\nproperty float quality\nend_header\n"
        )
    }

    const QUAD: [[f32; 3]; 4] = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]];

    fn binary(big: bool) -> Vec<u8> {
        let name = if big { "binary_big_endian" } else { "binary_little_endian" };
        let mut b = header_text(name, 4, 2).into_bytes();
        let f32b = |v: f32| if big { v.to_be_bytes() } else { v.to_le_bytes() };
        let i32b = |v: i32| if big { v.to_be_bytes() } else { v.to_le_bytes() };
        for p in QUAD {
            p.iter().for_each(|&v| b.extend(f32b(v)));
            b.push(200);
        }
        b.push(4);
        [0, 1, 2, 3].iter().for_each(|&i| b.extend(i32b(i)));
        b.extend(f32b(0.5));
        b.push(3);
        [0, 2, 3].iter().for_each(|&i| b.extend(i32b(i)));
        b.extend(f32b(0.5));
        b
    }

    #[test]
    fn ascii_and_both_binary_orders_read_alike() {
        let ascii =
            header_text("ascii", 4, 2) + "0 0 0 200\n1 0 0 200\n1 1 0 200\n0 1 0 200\n4 0 1 2 3 0.5\n3 0 2 3 0.5\n";
        for bytes in [ascii.into_bytes(), binary(false), binary(true)] {
            let (p, t) = parse(&bytes).unwrap();
            assert_eq!(p, QUAD.map(Vec3::from_array).to_vec());
            assert_eq!(t, vec![[0, 1, 2], [0, 2, 3], [0, 2, 3]], "the quad fan-triangulated, then the triangle");
        }
    }

    #[test]
    fn bad_files_are_errors_not_panics_or_huge_allocations() {
        let good = binary(false);
        let cases: Vec<(Vec<u8>, &str)> = vec![
            (b"plx\nformat ascii 1.0\nend_header\n".to_vec(), "not a PLY"),
            (b"ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\n".to_vec(), "end_header"),
            (header_text("binary_little_endian", 4_000_000_000, 0).into_bytes(), "more than the file holds"),
            (good[..good.len() - 3].to_vec(), "ends inside"),
            (b"ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nend_header\n1\n".to_vec(), "lacks x, y or z"),
            (
                b"ply\nformat ascii 1.0\nelement vertex 1\nproperty quad x\nend_header\n".to_vec(),
                "unknown property type",
            ),
        ];
        for (bytes, needle) in cases {
            let e = parse(&bytes).unwrap_err();
            assert!(e.contains(needle), "{needle}: {e}");
        }
        // Every truncation and every single flipped byte of a valid file fails or parses, without a panic.
        for n in 0..good.len() {
            let _ = parse(&good[..n]);
            let mut flipped = good.clone();
            flipped[n] ^= 0xff;
            let _ = parse(&flipped);
        }
    }
}
