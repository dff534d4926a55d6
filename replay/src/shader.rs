//! WGSL front end: parse and validate a shader with naga before wgpu sees it, so an error is
//! reported as `file:line:col` with the offending source line instead of a driver message.
//! The validated module is also what binding reflection reads.

use std::fmt;

/// A WGSL error located in its file.
#[derive(Debug)]
pub struct ShaderError {
    pub file: String,
    pub line: u32,
    pub column: u32,
    pub message: String,
    /// The source line the error points at.
    pub source_line: String,
    /// naga's full report with labels and notes.
    pub report: String,
}

impl fmt::Display for ShaderError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        writeln!(
            f,
            "{}:{}:{}: {}",
            self.file, self.line, self.column, self.message
        )?;
        writeln!(f, "    {}", self.source_line)?;
        write!(
            f,
            "    {}^",
            " ".repeat(self.column.saturating_sub(1) as usize)
        )
    }
}

impl std::error::Error for ShaderError {}

/// A parsed and validated shader.
#[derive(Debug)]
pub struct ValidatedShader {
    pub module: naga::Module,
    pub info: naga::valid::ModuleInfo,
}

fn locate(
    file: &str,
    source: &str,
    location: Option<naga::SourceLocation>,
    message: String,
    report: String,
) -> ShaderError {
    let (line, column) = location.map_or((1, 1), |l| (l.line_number, l.line_position));
    let source_line = source
        .lines()
        .nth(line.saturating_sub(1) as usize)
        .unwrap_or_default()
        .to_owned();
    ShaderError {
        file: file.to_owned(),
        line,
        column,
        message,
        source_line,
        report,
    }
}

/// Where `fn name` is declared in `source`.
fn entry_point_location(source: &str, name: &str) -> Option<naga::SourceLocation> {
    let needle = format!("fn {name}");
    source.lines().enumerate().find_map(|(i, line)| {
        let column = line.find(&needle)?;
        let rest = &line[column + needle.len()..];
        // A whole name, not a prefix of a longer one.
        if rest.starts_with(|c: char| c.is_alphanumeric() || c == '_') {
            return None;
        }
        Some(naga::SourceLocation {
            line_number: u32::try_from(i + 1).ok()?,
            line_position: u32::try_from(column + 1).ok()?,
            offset: 0,
            length: 0,
        })
    })
}

/// Parses and validates WGSL; `file` names the shader in messages.
pub fn validate_wgsl(file: &str, source: &str) -> Result<ValidatedShader, ShaderError> {
    let module = naga::front::wgsl::parse_str(source).map_err(|e| {
        locate(
            file,
            source,
            e.location(source),
            e.message().to_owned(),
            e.emit_to_string_with_path(source, file),
        )
    })?;
    let mut validator = naga::valid::Validator::new(
        naga::valid::ValidationFlags::all(),
        naga::valid::Capabilities::default(),
    );
    let info = validator.validate(&module).map_err(|e| {
        // The top error only names the entry point; the cause is further down the chain.
        let mut message = e.as_inner().to_string();
        let mut cause = std::error::Error::source(e.as_inner());
        while let Some(c) = cause {
            message.push_str(": ");
            message.push_str(&c.to_string());
            cause = c.source();
        }
        // Some validation errors carry no span: point at the entry point they name.
        let location = e.location(source).or_else(|| match e.as_inner() {
            naga::valid::ValidationError::EntryPoint { name, .. } => {
                entry_point_location(source, name)
            }
            _ => None,
        });
        locate(
            file,
            source,
            location,
            message,
            e.emit_to_string_with_path(source, file),
        )
    })?;
    Ok(ValidatedShader { module, info })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parse_errors_point_at_line_and_column() {
        let src = "@compute @workgroup_size(1)\nfn main() {\n    let x: f32 = 1.0 +;\n}\n";
        let err = validate_wgsl("bad.wgsl", src).unwrap_err();
        assert_eq!(err.line, 3);
        assert!(err.source_line.contains("let x"), "{err}");
        assert!(err.to_string().starts_with("bad.wgsl:3:"), "{err}");
    }

    #[test]
    fn validation_errors_give_the_whole_chain_at_the_entry_point() {
        let src = "@vertex fn vs() -> @builtin(position) vec4<f32> { return vec4<f32>(0.0); }\n\n@fragment\nfn fs() -> @location(0) vec4<f32> {\n    workgroupBarrier();\n    return vec4<f32>(1.0);\n}\n";
        let err = validate_wgsl("fs.wgsl", src).unwrap_err();
        assert!(
            err.message
                .starts_with("Entry point fs at Fragment is invalid: "),
            "{err}"
        );
        assert!(
            err.message.len() > "Entry point fs at Fragment is invalid: ".len() + 10,
            "{err}"
        );
        assert_eq!((err.line, err.column), (4, 1), "{err}");
    }

    #[test]
    fn validation_errors_are_located_too() {
        let src = "@compute @workgroup_size(1)\nfn main() {\n    let x: u32 = 1.0;\n}\n";
        let err = validate_wgsl("types.wgsl", src).unwrap_err();
        assert_eq!(err.line, 3, "{err}");
    }
}

impl ValidatedShader {
    /// Names of the global variables entry point `entry` uses (directly or through functions it
    /// calls), or `None` when the shader has no such entry point.
    pub fn globals_used_by(&self, entry: &str) -> Option<std::collections::BTreeSet<String>> {
        let index = self
            .module
            .entry_points
            .iter()
            .position(|e| e.name == entry)?;
        let info = self.info.get_entry_point(index);
        Some(
            self.module
                .global_variables
                .iter()
                .filter(|(handle, _)| !info[*handle].is_empty())
                .filter_map(|(_, var)| var.name.clone())
                .collect(),
        )
    }
}

#[cfg(test)]
mod reflection_tests {
    use super::*;

    #[test]
    fn entry_points_report_the_globals_they_touch() {
        let src = "
            @group(0) @binding(0) var<storage, read> positions: array<vec4<f32>>;
            @group(0) @binding(1) var albedo: texture_2d<f32>;
            fn fetch(i: u32) -> vec4<f32> { return positions[i]; }
            @vertex fn vs(@builtin(vertex_index) i: u32) -> @builtin(position) vec4<f32> { return fetch(i); }
            @fragment fn fs() -> @location(0) vec4<f32> { return textureLoad(albedo, vec2<i32>(0, 0), 0); }
        ";
        let shader = validate_wgsl("s.wgsl", src).unwrap();
        assert_eq!(
            shader
                .globals_used_by("vs")
                .unwrap()
                .into_iter()
                .collect::<Vec<_>>(),
            ["positions"]
        );
        assert_eq!(
            shader
                .globals_used_by("fs")
                .unwrap()
                .into_iter()
                .collect::<Vec<_>>(),
            ["albedo"]
        );
        assert!(shader.globals_used_by("missing").is_none());
    }
}
