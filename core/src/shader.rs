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
    let whole = source
        .lines()
        .nth(line.saturating_sub(1) as usize)
        .unwrap_or_default();
    // Control characters would move or erase what a terminal shows: quoted as U+FFFD.
    let mut source_line: String = whole
        .chars()
        .take(QUOTED_LINE)
        .map(|c| {
            if c.is_control() && c != '\t' {
                '\u{fffd}'
            } else {
                c
            }
        })
        .collect();
    if whole.chars().nth(QUOTED_LINE).is_some() {
        source_line.push_str("...");
    }
    ShaderError {
        file: file.to_owned(),
        line,
        column,
        message,
        source_line,
        report,
    }
}

/// naga's rendered report of an error, unless `source` holds control characters: its renderer
/// replaces them one at a time in the whole source, which takes minutes for a file of many
/// NUL bytes (a sparse file, a binary named as a shader). The message and location stand
/// without it.
fn report(source: &str, render: impl FnOnce() -> String) -> String {
    if source
        .bytes()
        .any(|b| (b < 0x20 && !matches!(b, b'\t' | b'\n' | b'\r')) || b == 0x7f)
    {
        return String::new();
    }
    render()
}

/// The most of the offending line an error quotes: a shader on one line (minified, or a
/// binary file) would otherwise be quoted whole.
const QUOTED_LINE: usize = 120;

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

/// Most operands one statement may have. naga's front end and validator recurse once per
/// operator of an expression, so a chain of tens of thousands of `+` overflows any stack; no
/// real shader statement comes near this.
pub const MAX_STATEMENT_OPERANDS: usize = 4096;

/// Stack for parsing and validating: expressions up to [`MAX_STATEMENT_OPERANDS`] deep fit
/// with room to spare.
const PARSER_STACK: usize = 64 << 20;

/// Deepest nesting of parentheses and brackets accepted (naga gives up past its own limit
/// with an unlocated "internal error").
pub const MAX_NESTING: usize = 128;

/// Where a shader exceeds a size limit: line and column.
enum Oversized {
    Operands(u32, u32),
    Nesting(u32, u32),
}

/// The first statement (text between `;`, `{` and `}`, comments skipped) with more operands
/// (identifier and number runs) than the limit, or the first bracket nested too deep.
fn oversized_statement(source: &str) -> Option<Oversized> {
    let bytes = source.as_bytes();
    let (mut i, mut line, mut column) = (0usize, 1u32, 1u32);
    let mut start = (1u32, 1u32);
    let mut operands = 0usize;
    let mut in_word = false;
    let mut block_depth = 0u32;
    let mut nesting = 0usize;
    while i < bytes.len() {
        let b = bytes[i];
        let next = bytes.get(i + 1).copied();
        if block_depth > 0 {
            // Inside a block comment (they nest in WGSL).
            if b == b'*' && next == Some(b'/') {
                block_depth -= 1;
                i += 1;
            } else if b == b'/' && next == Some(b'*') {
                block_depth += 1;
                i += 1;
            }
        } else if b == b'/' && next == Some(b'/') {
            while i < bytes.len() && bytes[i] != b'\n' {
                i += 1;
            }
            continue;
        } else if b == b'/' && next == Some(b'*') {
            block_depth = 1;
            i += 1;
        } else if matches!(b, b';' | b'{' | b'}') {
            operands = 0;
        } else if matches!(b, b'(' | b'[') {
            nesting += 1;
            if nesting > MAX_NESTING {
                return Some(Oversized::Nesting(line, column));
            }
        } else if matches!(b, b')' | b']') {
            nesting = nesting.saturating_sub(1);
        } else if b.is_ascii_alphanumeric() || b == b'_' || b >= 0x80 {
            if !in_word {
                operands += 1;
                if operands == 1 {
                    start = (line, column);
                }
                if operands > MAX_STATEMENT_OPERANDS {
                    return Some(Oversized::Operands(start.0, start.1));
                }
            }
            in_word = true;
            i += 1;
            column += 1;
            continue;
        }
        in_word = false;
        if b == b'\n' {
            line += 1;
            column = 1;
        } else {
            column += 1;
        }
        i += 1;
    }
    None
}

/// Parses and validates WGSL; `file` names the shader in messages. Runs on a thread with a
/// stack sized for the deepest expression the statement limit lets through.
pub fn validate_wgsl(file: &str, source: &str) -> Result<ValidatedShader, ShaderError> {
    if let Some(o) = oversized_statement(source) {
        let ((line, column), message) = match o {
            Oversized::Operands(l, c) => (
                (l, c),
                format!(
                    "this statement has more than {MAX_STATEMENT_OPERANDS} operands: expressions this long are refused before parsing"
                ),
            ),
            Oversized::Nesting(l, c) => (
                (l, c),
                format!("brackets nested more than {MAX_NESTING} deep"),
            ),
        };
        let location = naga::SourceLocation {
            line_number: line,
            line_position: column,
            offset: 0,
            length: 0,
        };
        return Err(locate(file, source, Some(location), message, String::new()));
    }
    std::thread::scope(|scope| {
        std::thread::Builder::new()
            .name("wgsl".into())
            .stack_size(PARSER_STACK)
            .spawn_scoped(scope, || parse_and_validate(file, source))
            .map_err(|e| {
                locate(
                    file,
                    source,
                    None,
                    format!("cannot start the shader parser thread: {e}"),
                    String::new(),
                )
            })?
            .join()
            .unwrap_or_else(|_| {
                Err(locate(
                    file,
                    source,
                    None,
                    "the WGSL front end failed on this shader".to_owned(),
                    String::new(),
                ))
            })
    })
}

fn parse_and_validate(file: &str, source: &str) -> Result<ValidatedShader, ShaderError> {
    let module = naga::front::wgsl::parse_str(source).map_err(|e| {
        locate(
            file,
            source,
            e.location(source),
            e.message().to_owned(),
            report(source, || e.emit_to_string_with_path(source, file)),
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
            report(source, || e.emit_to_string_with_path(source, file)),
        )
    })?;
    Ok(ValidatedShader { module, info })
}

#[cfg(test)]
mod tests {
    /// A shader file of NUL bytes (a sparse file, a binary named as a shader) is refused
    /// with a short quote and no rendered report: naga's renderer replaces control
    /// characters one at a time, minutes for a file this size.
    #[test]
    fn control_characters_are_quoted_short_and_not_rendered() {
        let source = "\0".repeat(4 << 20);
        let err = validate_wgsl("zeros.wgsl", &source).expect_err("NUL bytes are no WGSL");
        assert!(err.report.is_empty(), "{}", err.report.len());
        assert!(err.source_line.chars().count() <= QUOTED_LINE + 3);
        assert!(
            err.source_line.starts_with('\u{fffd}'),
            "{}",
            err.source_line
        );
    }

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
    fn very_long_expressions_are_refused_before_parsing() {
        let chain = vec!["1.0"; 20_000].join(" + ");
        let src = format!(
            "// a comment; with {{ braces }}\n@compute @workgroup_size(1)\nfn main() {{\n    let x = {chain};\n}}\n"
        );
        let err = validate_wgsl("deep.wgsl", &src).unwrap_err();
        assert_eq!((err.line, err.column), (4, 5), "{err}");
        assert!(err.message.contains("more than 4096 operands"), "{err}");
        let nest = format!("{}1.0{}", "(".repeat(500), ")".repeat(500));
        let src = format!("@compute @workgroup_size(1)\nfn main() {{\n    let x = {nest};\n}}\n");
        let err = validate_wgsl("nest.wgsl", &src).unwrap_err();
        assert_eq!(err.line, 3, "{err}");
        assert!(err.message.contains("nested more than 128 deep"), "{err}");
        // Just under the limit parses (on the parser's own stack).
        let chain = vec!["a"; 4000].join(" + ");
        let src = format!(
            "@compute @workgroup_size(1)\nfn main() {{\n    let a = 1.0;\n    let x = {chain};\n}}\n"
        );
        assert!(validate_wgsl("ok.wgsl", &src).is_ok());
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

impl ValidatedShader {
    /// Why compute entry point `entry` cannot run within `limits` (workgroup size per
    /// dimension, invocations per workgroup, workgroup storage), if it cannot. Drivers are not
    /// required to reject such a pipeline cleanly: one crashed creating it.
    pub fn compute_limits_exceeded(
        &self,
        entry: &str,
        limits: &wgpu_types::Limits,
    ) -> Option<String> {
        let (index, ep) = self
            .module
            .entry_points
            .iter()
            .enumerate()
            .find(|(_, e)| e.name == entry && e.stage == naga::ShaderStage::Compute)?;
        let [x, y, z] = ep.workgroup_size;
        let max = [
            limits.max_compute_workgroup_size_x,
            limits.max_compute_workgroup_size_y,
            limits.max_compute_workgroup_size_z,
        ];
        for (axis, (size, max)) in ["x", "y", "z"].iter().zip([x, y, z].into_iter().zip(max)) {
            if size > max {
                return Some(format!(
                    "`{entry}` has workgroup size {size} in {axis}; the device allows {max}"
                ));
            }
        }
        let invocations = u64::from(x) * u64::from(y) * u64::from(z);
        if invocations > u64::from(limits.max_compute_invocations_per_workgroup) {
            return Some(format!(
                "`{entry}` has {invocations} invocations per workgroup; the device allows {}",
                limits.max_compute_invocations_per_workgroup
            ));
        }
        let info = self.info.get_entry_point(index);
        let storage: u64 = self
            .module
            .global_variables
            .iter()
            .filter(|(h, v)| v.space == naga::AddressSpace::WorkGroup && !info[*h].is_empty())
            .map(|(_, v)| u64::from(self.module.types[v.ty].inner.size(self.module.to_ctx())))
            .sum();
        (storage > u64::from(limits.max_compute_workgroup_storage_size)).then(|| {
            format!(
                "`{entry}` uses {storage} bytes of workgroup storage; the device allows {}",
                limits.max_compute_workgroup_storage_size
            )
        })
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

    #[test]
    fn compute_entry_points_are_checked_against_device_limits() {
        let src = "
            var<workgroup> tile: array<vec4<f32>, 4096>;
            @compute @workgroup_size(512, 1, 1) fn wide() {}
            @compute @workgroup_size(8, 8, 1) fn heavy() { tile[0] = vec4<f32>(1.0); }
            @compute @workgroup_size(8, 8, 1) fn fine() {}
        ";
        let shader = validate_wgsl("l.wgsl", src).unwrap();
        let limits = wgpu_types::Limits::default();
        let wide = shader.compute_limits_exceeded("wide", &limits).unwrap();
        assert!(wide.contains("workgroup size 512 in x"), "{wide}");
        let heavy = shader.compute_limits_exceeded("heavy", &limits).unwrap();
        assert!(
            heavy.contains("65536 bytes of workgroup storage"),
            "{heavy}"
        );
        assert_eq!(shader.compute_limits_exceeded("fine", &limits), None);
    }
}
