//! Diagnostics: one problem found in a capture, located by its JSON path, with a suggestion for
//! misspelled names. Validation collects all of them before reporting, so a user fixes a capture
//! in one round instead of one error per run.

use std::fmt;

use serde::Serialize;

#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Severity {
    Error,
    Warning,
}

/// One problem in a capture.
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
pub struct Diagnostic {
    pub severity: Severity,
    /// Stable kebab-case code, e.g. `unknown-resource`, `heap-tier`.
    pub code: &'static str,
    /// JSON path of the offending value, e.g. `$.passes[3].bindings.albedo.resource`.
    pub path: String,
    pub message: String,
    /// The name the user probably meant, for unknown names.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub suggestion: Option<String>,
}

impl fmt::Display for Diagnostic {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let level = match self.severity {
            Severity::Error => "error",
            Severity::Warning => "warning",
        };
        write!(f, "{level}[{}] {}: {}", self.code, self.path, self.message)?;
        if let Some(s) = &self.suggestion {
            write!(f, " (did you mean \"{s}\"?)")?;
        }
        Ok(())
    }
}

/// Edit-distance work (character pairs compared) one validation may spend on suggestions:
/// a capture with thousands of misspelled names among thousands of candidates would otherwise
/// cost minutes. Past it, diagnostics simply come without a suggestion.
pub const SUGGESTION_BUDGET: u64 = 50_000_000;

/// Names longer than this get no suggestion (and cost nothing).
const MAX_SUGGESTED_LEN: usize = 128;

thread_local! {
    static BUDGET: std::cell::Cell<u64> = const { std::cell::Cell::new(SUGGESTION_BUDGET) };
}

/// Gives this thread's next validation the whole suggestion budget again.
pub fn reset_suggestion_budget() {
    BUDGET.with(|b| b.set(SUGGESTION_BUDGET));
}

/// The closest candidate to a misspelled name, if one is close enough to be a likely typo
/// (normalised Damerau-Levenshtein similarity of at least 0.6, ignoring case).
pub fn suggest<'a>(name: &str, candidates: impl IntoIterator<Item = &'a str>) -> Option<String> {
    let len = name.chars().count();
    if len > MAX_SUGGESTED_LEN {
        return None;
    }
    let lowered = name.to_ascii_lowercase();
    let mut best: Option<(f64, &str)> = None;
    for c in candidates {
        let clen = c.chars().count();
        // Similarity is at most 1 - |len difference| / longer length: skip candidates that
        // cannot reach 0.6 without computing anything.
        let longer = len.max(clen).max(1);
        if clen > MAX_SUGGESTED_LEN || len.abs_diff(clen) * 5 > longer * 2 {
            continue;
        }
        let cost = (len * clen) as u64;
        let affordable = BUDGET.with(|b| {
            let left = b.get();
            b.set(left.saturating_sub(cost));
            left >= cost
        });
        if !affordable {
            return None;
        }
        let score = strsim::normalized_damerau_levenshtein(&lowered, &c.to_ascii_lowercase());
        let better = match best {
            None => true,
            Some((s, b)) => score > s || (score == s && c < b),
        };
        if score >= 0.6 && better {
            best = Some((score, c));
        }
    }
    best.map(|(_, c)| c.to_owned())
}

/// A JSON path under construction: `$`, `.field`, `[index]`, `["odd key"]`.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct JsonPath(String);

impl JsonPath {
    pub fn root() -> Self {
        Self("$".to_owned())
    }
    pub fn field(&self, name: &str) -> Self {
        let plain = !name.is_empty()
            && name.chars().all(|c| c.is_ascii_alphanumeric() || c == '_')
            && !name.starts_with(|c: char| c.is_ascii_digit());
        if plain {
            Self(format!("{}.{name}", self.0))
        } else {
            Self(format!("{}[{name:?}]", self.0))
        }
    }
    pub fn index(&self, i: usize) -> Self {
        Self(format!("{}[{i}]", self.0))
    }
    pub fn as_str(&self) -> &str {
        &self.0
    }
}

impl fmt::Display for JsonPath {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.0)
    }
}

/// The most characters of one diagnostic's message (or suggestion).
pub const MAX_MESSAGE_CHARS: usize = 2_000;

/// Collects diagnostics during validation.
#[derive(Debug, Default)]
pub struct Diagnostics {
    items: Vec<Diagnostic>,
}

impl Diagnostics {
    pub fn error(&mut self, code: &'static str, path: &JsonPath, message: impl Into<String>) {
        self.push(Severity::Error, code, path, message.into(), None);
    }
    pub fn warning(&mut self, code: &'static str, path: &JsonPath, message: impl Into<String>) {
        self.push(Severity::Warning, code, path, message.into(), None);
    }
    pub fn error_with_suggestion(
        &mut self,
        code: &'static str,
        path: &JsonPath,
        message: impl Into<String>,
        suggestion: Option<String>,
    ) {
        self.push(Severity::Error, code, path, message.into(), suggestion);
    }
    fn push(
        &mut self,
        severity: Severity,
        code: &'static str,
        path: &JsonPath,
        message: String,
        suggestion: Option<String>,
    ) {
        // Messages quote names and values from the capture; a megabyte-long one is cut
        // here, once for every message, rather than echoed whole.
        self.items.push(Diagnostic {
            severity,
            code,
            path: path.0.clone(),
            message: crate::text::cut(&message, MAX_MESSAGE_CHARS).into_owned(),
            suggestion: suggestion.map(|s| crate::text::cut(&s, MAX_MESSAGE_CHARS).into_owned()),
        });
    }
    pub fn error_count(&self) -> usize {
        self.items
            .iter()
            .filter(|d| d.severity == Severity::Error)
            .count()
    }
    pub fn has_errors(&self) -> bool {
        self.items.iter().any(|d| d.severity == Severity::Error)
    }
    pub fn into_vec(self) -> Vec<Diagnostic> {
        self.items
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_message_quoting_a_huge_name_is_cut() {
        let mut d = Diagnostics::default();
        let name = "n".repeat(1_000_000);
        d.error("x", &JsonPath::root(), format!("unknown fence \"{name}\""));
        let m = &d.into_vec()[0].message;
        assert!(m.len() < MAX_MESSAGE_CHARS + 40, "{}", m.len());
        assert!(
            m.ends_with("... (998016 more bytes)"),
            "{}",
            &m[m.len() - 40..]
        );
    }

    #[test]
    fn suggestions_stop_when_the_budget_is_spent() {
        reset_suggestion_budget();
        let many: Vec<String> = (0..2000).map(|i| format!("resource_{i:05}")).collect();
        let names: Vec<&str> = many.iter().map(String::as_str).collect();
        assert_eq!(
            suggest("resource_0001x", names.iter().copied()).as_deref(),
            Some("resource_00010")
        );
        // Each call compares ~2000 names of 14 characters: the budget lasts a few hundred.
        let answered = (0..2000)
            .filter(|_| suggest("resource_0001x", names.iter().copied()).is_some())
            .count();
        assert!((100..2000).contains(&answered), "{answered}");
        assert_eq!(suggest("resource_0001x", names.iter().copied()), None);
        reset_suggestion_budget();
        assert!(suggest("resource_0001x", names.iter().copied()).is_some());
        assert_eq!(suggest(&"x".repeat(200), ["x"; 3]), None);
    }

    #[test]
    fn suggests_close_names_only() {
        let names = ["gbuffer_albedo", "gbuffer_normal", "depth"];
        assert_eq!(
            suggest("gbuffer_albdeo", names),
            Some("gbuffer_albedo".into())
        );
        assert_eq!(
            suggest("GBUFFER_NORMAL", names),
            Some("gbuffer_normal".into())
        );
        assert_eq!(suggest("swapchain", names), None);
    }

    #[test]
    fn paths_quote_odd_keys() {
        let p = JsonPath::root()
            .field("passes")
            .index(3)
            .field("bindings")
            .field("my var");
        assert_eq!(p.as_str(), "$.passes[3].bindings[\"my var\"]");
    }
}
