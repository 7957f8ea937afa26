//! Text file format (`usda`) reader and writer.

use std::fs;
use std::path::Path;

use anyhow::{Context, Result};

#[cfg(unix)]
mod mapped;
pub(crate) mod names;
pub mod parser;
pub mod token;
mod writer;

use parser::Parser;

pub use writer::TextWriter;

use crate::{ar, sdf, tf};

/// Parse `usda` text into an in-memory [`sdf::Data`] store.
pub fn parse(text: &str) -> Result<sdf::Data> {
    let mut parser = Parser::new(text);
    parse_on_own_stack(&mut parser)
}

/// Runs the recursive-descent parser on a thread whose stack holds
/// [`parser::MAX_NESTING`] levels (ppis patch, see PATCHED.md), so the depth a layer
/// may nest does not depend on the caller's stack.
fn parse_on_own_stack(parser: &mut Parser) -> Result<sdf::Data> {
    std::thread::scope(|scope| {
        let worker = std::thread::Builder::new()
            .name("usda-parser".into())
            .stack_size(parser::PARSER_STACK_BYTES)
            .spawn_scoped(scope, || parser.parse())
            .context("Unable to start the usda parser thread")?;
        worker.join().unwrap_or_else(|panic| std::panic::resume_unwind(panic))
    })
}

/// Read a `usda` file from disk into an in-memory [`sdf::Data`] store.
pub fn read_file(path: impl AsRef<Path>) -> Result<sdf::Data> {
    let path = path.as_ref();
    let text = fs::read_to_string(path).with_context(|| format!("Unable to read file: {}", path.display()))?;

    let mut parser = Parser::new(&text);
    parse_on_own_stack(&mut parser).map_err(|e| match parser.last_error_highlight() {
        Some(h) => e.context(format!("{}:{}: {}", path.display(), h.line, h.column)),
        None => e.context(format!("{}: parse error", path.display())),
    })
}

/// Text format (`.usda`) as an [`sdf::FileFormat`], wrapping [`parse`] and
/// [`TextWriter`].
pub struct UsdaFileFormat;

impl sdf::FileFormat for UsdaFileFormat {
    fn format_id(&self) -> tf::Token {
        tf::Token::new("usda")
    }

    fn extensions(&self) -> &[&str] {
        &["usda"]
    }

    fn read(&self, resolver: &dyn ar::Resolver, resolved: &ar::ResolvedPath) -> Result<sdf::LayerData> {
        let mut asset = resolver.open_asset(resolved)?;
        #[cfg(unix)]
        if let Some(map) = asset.file_region().map(mapped::MappedText::map).transpose()?.flatten() {
            let text = map.text()?;
            let release = |offset: usize| map.release_before(offset);
            let mut parser = Parser::with_release(text, &release);
            return Ok(Box::new(parse_on_own_stack(&mut parser).context("failed to parse USDA layer")?));
        }
        let bytes = asset.read_all()?;
        let text = String::from_utf8(bytes).context("layer is not valid UTF-8")?;
        Ok(Box::new(parse(&text).context("failed to parse USDA layer")?))
    }

    fn write(&self, data: &dyn sdf::AbstractData, mut sink: &mut dyn sdf::WriteSeek) -> Result<()> {
        TextWriter::write(data, &mut sink)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sdf::{AbstractData, SpecType};

    #[test]
    fn parse_builds_data() {
        let data = parse("#usda 1.0\ndef \"Root\"\n{\n    float size = 2.5\n}\n").expect("parse");

        let root = sdf::path("/Root").unwrap();
        assert_eq!(data.spec_type(&root), Some(SpecType::Prim));

        let size = root.append_property("size").unwrap();
        assert_eq!(data.spec_type(&size), Some(SpecType::Attribute));
        assert_eq!(
            data.get_field(&size, "default").unwrap().into_owned(),
            sdf::Value::Float(2.5)
        );
    }
}
