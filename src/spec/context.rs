//! The `FILE:LINE` and dotted-key context of the spec reader's messages: [`SpecError`] and
//! [`Ctx`], which knows the file's text and path, turns spans into 1-based lines and checks
//! scalar values (numbers, strings, booleans, enumerated names, tables) with one message per
//! mistake: "`KEY`: must be EXPECTED, got VALUE".
//!
//! Choices: every message is one line (toml's own multi-line messages are joined with "; ");
//! toml's bare "duplicate key" is given the key's name; a number that is not finite says so.

use super::names::{one_of, pick};
use super::spanned::{Tab, Val, TOML_DATETIME_KEY};
use std::ops::Range;
use std::path::{Path, PathBuf};
use toml::Spanned;

/// Everything that can be wrong with a spec. Each message is one line starting with the file.
#[derive(Debug, thiserror::Error)]
pub enum SpecError {
    #[error("{}: cannot read spec: {source}", path.display())]
    Io {
        path: PathBuf,
        source: std::io::Error,
    },
    #[error("{}:{line}: {message}", path.display())]
    Syntax {
        path: PathBuf,
        line: usize,
        message: String,
    },
    #[error("{}:{line}: `{key}`: {message}", path.display())]
    Invalid {
        path: PathBuf,
        line: usize,
        key: String,
        message: String,
    },
}

pub(super) type Opt = Option<Spanned<Val>>;

pub(super) const MM_POSITIVE: &str = "a positive number of millimetres";
pub(super) const MM_NON_NEGATIVE: &str = "a number of millimetres, zero or more";
pub(super) const NON_EMPTY: &str = "a non-empty string";

pub(super) struct Ctx<'a> {
    pub(super) text: &'a str,
    pub(super) path: &'a Path,
}

impl Ctx<'_> {
    /// 1-based line of a byte offset into the text.
    fn line_at(&self, offset: usize) -> usize {
        let end = offset.min(self.text.len());
        1 + self.text.as_bytes()[..end]
            .iter()
            .filter(|&&b| b == b'\n')
            .count()
    }

    pub(super) fn line(&self, span: Range<usize>) -> usize {
        self.line_at(span.start)
    }

    pub(super) fn syntax(&self, err: &toml::de::Error) -> SpecError {
        let span = err.span();
        let line = span.clone().map_or(1, |s| self.line(s));
        let mut message = one_line(err.message());
        // toml says only "duplicate key"; its span covers the key, so name it.
        if message == "duplicate key" {
            if let Some(key) = span.and_then(|s| self.text.get(s)) {
                let key = key.trim();
                if !key.is_empty() && key.len() <= 80 && !key.contains('\n') {
                    message = format!("duplicate key `{key}`");
                }
            }
        }
        // A date-time where a table belongs reaches the table as toml's private key.
        if message.contains(TOML_DATETIME_KEY) {
            message = "expected a table, got a date-time".to_string();
        }
        SpecError::Syntax {
            path: self.path.to_path_buf(),
            line,
            message,
        }
    }

    /// The first of `keys` that is given is an error, `{key}.{k}` with `why`: keys meant for
    /// another kind of surface, or for another place in the file.
    pub(super) fn refuse(
        &self,
        key: &str,
        keys: &[(&str, Option<Range<usize>>)],
        why: &str,
    ) -> Result<(), SpecError> {
        match keys.iter().find_map(|(k, sp)| sp.clone().map(|sp| (k, sp))) {
            Some((k, sp)) => Err(self.invalid(self.line(sp), &format!("{key}.{k}"), why.into())),
            None => Ok(()),
        }
    }

    /// [`Ctx::refuse`] but for the keys in `except`, which the kind takes with its own
    /// meaning.
    pub(super) fn refuse_except(
        &self,
        key: &str,
        keys: &[(&str, Option<Range<usize>>)],
        except: &[&str],
        why: &str,
    ) -> Result<(), SpecError> {
        let kept: Vec<_> = keys
            .iter()
            .filter(|(k, _)| !except.contains(k))
            .cloned()
            .collect();
        self.refuse(key, &kept, why)
    }

    pub(super) fn invalid(&self, line: usize, key: &str, message: String) -> SpecError {
        SpecError::Invalid {
            path: self.path.to_path_buf(),
            line,
            key: key.to_string(),
            message,
        }
    }

    /// "must be EXPECTED, got VALUE" as an `Invalid` error at the value's line.
    pub(super) fn expected(&self, v: &Spanned<Val>, key: &str, expected: &str) -> SpecError {
        let mut message = format!("must be {expected}, got {}", v.get_ref());
        if matches!(v.get_ref(), Val::Num(n) if !n.is_finite()) {
            message.push_str(" (not a finite number)");
        }
        self.invalid(self.line(v.span()), key, message)
    }

    /// A finite number accepted by `ok`, with its line.
    pub(super) fn number(
        &self,
        v: &Opt,
        key: &str,
        expected: &str,
        ok: impl Fn(f64) -> bool,
    ) -> Result<Option<(f64, usize)>, SpecError> {
        let Some(v) = v else { return Ok(None) };
        match *v.get_ref() {
            Val::Num(n) if n.is_finite() && ok(n) => Ok(Some((n, self.line(v.span())))),
            _ => Err(self.expected(v, key, expected)),
        }
    }

    pub(super) fn string(
        &self,
        v: &Opt,
        key: &str,
        expected: &str,
    ) -> Result<Option<String>, SpecError> {
        let Some(v) = v else { return Ok(None) };
        match v.get_ref() {
            Val::Str(s) if !s.trim().is_empty() => Ok(Some(s.clone())),
            _ => Err(self.expected(v, key, expected)),
        }
    }

    /// A name that becomes part of file names: a plain file name
    /// ([`crate::output::files::check_file_name`]), so a run writes inside its folder.
    pub(super) fn file_name(&self, v: &Opt, key: &str) -> Result<Option<String>, SpecError> {
        let s = self.string(v, key, NON_EMPTY)?;
        if let (Some(s), Some(v)) = (&s, v) {
            if let Err(m) = crate::output::files::check_file_name(s) {
                return Err(self.invalid(self.line(v.span()), key, m));
            }
        }
        Ok(s)
    }

    pub(super) fn boolean(&self, v: &Opt, key: &str) -> Result<Option<bool>, SpecError> {
        let Some(v) = v else { return Ok(None) };
        match v.get_ref() {
            Val::Bool(b) => Ok(Some(*b)),
            _ => Err(self.expected(v, key, "true or false")),
        }
    }

    /// One of an enum's names (ASCII case ignored).
    pub(super) fn choice<T: Copy>(
        &self,
        v: &Opt,
        key: &str,
        table: &[(&str, T)],
    ) -> Result<Option<T>, SpecError> {
        let Some(v) = v else { return Ok(None) };
        let found = match v.get_ref() {
            Val::Str(s) => pick(s, table).ok(),
            _ => None,
        };
        match found {
            Some(t) => Ok(Some(t)),
            None => {
                let names: Vec<&str> = table.iter().map(|(n, _)| *n).collect();
                Err(self.expected(v, key, &one_of(&names)))
            }
        }
    }

    /// The table, `None` if absent, or an error if the key holds another type.
    pub(super) fn table<'t, T>(
        &self,
        t: &'t Option<Spanned<Tab<T>>>,
        key: &str,
    ) -> Result<Option<(&'t T, usize)>, SpecError> {
        let Some(t) = t else { return Ok(None) };
        match t.get_ref() {
            Tab::Table(inner) => Ok(Some((inner, self.line(t.span())))),
            Tab::Wrong(v) => Err(self.invalid(
                self.line(t.span()),
                key,
                format!("must be a table ([{key}]), got {v}"),
            )),
        }
    }
}

/// Joins a multi-line message into one line.
fn one_line(s: &str) -> String {
    s.lines()
        .map(str::trim)
        .filter(|l| !l.is_empty())
        .collect::<Vec<_>>()
        .join("; ")
}
