//! The model text language, as users of the R package write it (docs/methods.md §0.2–§0.3).
//!
//! # Grammar
//! ```text
//! model   := term ( "+" term )*
//! term    := [ INT "*" ] process                    INT = 1..=100 (MAX_MULTIPLIER)
//! process := NAME [ args ]                          WN QN RW DR AR1 GM MA1 ARMA11
//!          | ("AR" | "MA") "(" INT ")" [ args ]     AR(2), MA(3)(0.5, 1)
//!          | "ARMA" "(" INT "," INT ")" [ args ]    ARMA(2,1)(ar1=0.5, ma1=0.3, sigma2=1)
//! args    := "(" [ arg ( "," arg )* ] ")"
//! arg     := NUMBER                                  positional, in docs/methods.md §0.2 order
//!          | PNAME "=" NUMBER                        named; positional ones come first
//! NUMBER  := [+-] digits [ "." digits ] [ (e|E) [+-] digits ]   (".5" and "5." too)
//! ```
//! - Process and parameter names are ASCII case-insensitive; whitespace may appear between any
//!   two tokens; `WN` without `()` is accepted (guess mode).
//! - `k*X(...)` repeats X k times with the same values; only GM, AR1 and SIN may repeat.
//! - Parameter names are those of [`ProcessKind::param_names`] (`phi`, `sigma2`, `sigma2_gm`,
//!   `ar1`, `ma2`, ...); fewer values than parameters leave the rest unspecified (`None`).
//! - ARMA values are given after the orders: `ARMA(p,q)(...)`, likewise `AR(p)(...)`.
//! - Values must be finite and inside their [`ParamDomain`](super::ParamDomain) (variances > 0,
//!   AR1/MA1/ARMA11 coefficients in (-1, 1), GM beta > 0).
//!
//! Errors carry the byte offset and 1-based character column of the offending character;
//! [`ModelParseError::render`] draws the caret:
//! ```
//! use gmwm::{Model, ParseErrorKind};
//! let e = Model::parse("AR1(phi=0.9,, sigma2=1)").unwrap_err();
//! assert_eq!((e.column(), e.kind()), (13, &ParseErrorKind::Syntax));
//! assert_eq!(
//!     e.to_string(),
//!     r#"model "AR1(phi=0.9,, sigma2=1)": at column 13: expected a parameter name, found ",""#
//! );
//! assert_eq!(e.render(), "AR1(phi=0.9,, sigma2=1)\n            ^");
//! ```

use super::Model;
use super::{validate, Component, ModelError, ProcessKind, MAX_MULTIPLIER, MAX_ORDER};
use crate::process::{spec, Orders, KINDS};
use std::fmt;

/// What went wrong in [`Model::parse`]; the position and the expected/found texts are in
/// [`ModelParseError`].
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub enum ParseErrorKind {
    /// The text is empty or blank.
    Empty,
    /// An unexpected token (missing `)`, `,` where a name belongs, trailing garbage, ...).
    Syntax,
    /// A process name that does not exist; `suggestion` is the nearest valid one.
    UnknownProcess {
        /// The name as written.
        name: String,
        /// The closest valid name (edit distance), with its syntax, e.g. `"GM()"`.
        suggestion: Option<String>,
    },
    /// A parameter name the process does not have.
    UnknownParameter {
        /// The name as written.
        name: String,
        /// The process's valid parameter names (docs/methods.md §0.2).
        valid: Vec<String>,
    },
    /// A parameter given twice (by name, or by position and name).
    DuplicateParameter {
        /// The parameter's canonical name.
        name: String,
    },
    /// More positional values than the process has parameters.
    TooManyValues {
        /// The process's parameter count.
        max: usize,
    },
    /// A malformed or non-finite number.
    BadNumber,
    /// A multiplier `k` outside 1..=`MAX_MULTIPLIER`.
    BadMultiplier,
    /// A model rule (docs/methods.md §0.2) or a value domain is violated; the position points at
    /// the offending term or value.
    Rule(ModelError),
}

/// A model text that could not be parsed (or that breaks a model rule), with the position of
/// the offending character.
///
/// Displays as `model "<text>": at column <c>: expected <e>, found <f>[; hint]`. The fields are
/// behind accessors so that the error stays one pointer wide in `Result`s.
#[derive(Debug, Clone, PartialEq)]
pub struct ModelParseError(Box<ErrorData>);

#[derive(Debug, Clone, PartialEq)]
struct ErrorData {
    input: String,
    offset: usize,
    column: usize,
    expected: String,
    found: String,
    hint: Option<String>,
    kind: ParseErrorKind,
}

impl ModelParseError {
    /// The whole input text.
    pub fn input(&self) -> &str {
        &self.0.input
    }

    /// Byte offset of the offending character in [`input`](Self::input) (`input().len()` when
    /// the text ended too early); always a char boundary.
    pub fn offset(&self) -> usize {
        self.0.offset
    }

    /// 1-based column, in characters, of the offending character.
    pub fn column(&self) -> usize {
        self.0.column
    }

    /// What would have been valid there, e.g. `a parameter name`.
    pub fn expected(&self) -> &str {
        &self.0.expected
    }

    /// What was found: quoted text such as `","`, or `end of input`.
    pub fn found(&self) -> &str {
        &self.0.found
    }

    /// A suggested fix, if one is obvious (e.g. `did you mean GM()?`).
    pub fn hint(&self) -> Option<&str> {
        self.0.hint.as_deref()
    }

    /// The kind of error, for callers that act on it.
    pub fn kind(&self) -> &ParseErrorKind {
        &self.0.kind
    }

    /// Two lines: the input (control characters shown as spaces) and a `^` under the offending
    /// character.
    pub fn render(&self) -> String {
        let line: String = self
            .0
            .input
            .chars()
            .map(|c| if c.is_control() { ' ' } else { c })
            .collect();
        format!("{line}\n{}^", " ".repeat(self.0.column.saturating_sub(1)))
    }

    /// The model-rule violation, for [`ParseErrorKind::Rule`].
    pub fn rule(&self) -> Option<&ModelError> {
        match &self.0.kind {
            ParseErrorKind::Rule(e) => Some(e),
            _ => None,
        }
    }
}

impl fmt::Display for ModelParseError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let d = &self.0;
        write!(
            f,
            "model {:?}: at column {}: expected {}, found {}",
            d.input, d.column, d.expected, d.found
        )?;
        if let Some(h) = &d.hint {
            write!(f, "; {h}")?;
        }
        Ok(())
    }
}

/// No source: a rule violation's expectation and value are already in the message (a chain
/// printer would state them twice); [`ModelParseError::rule`] gives it typed.
impl std::error::Error for ModelParseError {}

const NUMBER: &str = "a number such as 0.5, -2 or 7.08e-9";

/// `a process (WN, QN, ..., AR(p), MA(q), ARMA(p,q))`: the kinds of the table, order kinds with
/// their syntax.
fn process_list() -> String {
    let names: Vec<&str> = KINDS
        .iter()
        .map(|&k| {
            let s = spec(k);
            if s.orders.is_some() {
                s.syntax
            } else {
                s.name
            }
        })
        .collect();
    format!("a process ({})", names.join(", "))
}

struct Parser<'a> {
    text: &'a str,
    bytes: &'a [u8],
    pos: usize,
}

type Res<T> = Result<T, ModelParseError>;

/// Parses a model; see the module docs for the grammar. Never panics.
pub(crate) fn parse_model(text: &str) -> Res<Model> {
    let mut p = Parser {
        text,
        bytes: text.as_bytes(),
        pos: 0,
    };
    p.skip_ws();
    if p.peek().is_none() {
        return Err(p.error(
            p.pos,
            ParseErrorKind::Empty,
            "a model such as \"3*GM()+WN()+RW()\"",
            None,
        ));
    }
    let mut components = Vec::new();
    let mut starts = Vec::new();
    loop {
        let start = p.pos;
        let (k, c) = p.term(components.len())?;
        for _ in 0..k {
            components.push(c.clone());
            starts.push(start);
        }
        p.skip_ws();
        match p.peek() {
            None => break,
            Some(b'+') => {
                p.pos += 1;
                p.skip_ws();
            }
            Some(_) => return Err(p.unexpected(p.pos, "\"+\" or the end of the model")),
        }
    }
    match validate(&components) {
        Ok(()) => Ok(Model { components }),
        Err((i, e)) => {
            let at = starts.get(i).copied().unwrap_or(0);
            let (expected, found) = rule_texts(&e);
            Err(p.error_with(at, ParseErrorKind::Rule(e), expected, found, None))
        }
    }
}

/// The expected/found texts of a rule violation found after parsing.
fn rule_texts(e: &ModelError) -> (String, String) {
    match e {
        ModelError::Repeated { kind, count } => (
            format!("{kind} at most once (docs/methods.md §0.2: only GM, AR1 and SIN may repeat)"),
            format!("{kind} {count} times"),
        ),
        ModelError::GmAr1Mixed { gm, ar1 } => (
            "GM or AR1 terms, not both (docs/methods.md §0.2)".to_string(),
            format!("{gm} GM and {ar1} AR1"),
        ),
        ModelError::ArmaFamily { first, second } => (
            "at most one ARMA-family term (MA1, ARMA11, AR(p), MA(q), ARMA(p,q))".to_string(),
            format!("{first} and {second}"),
        ),
        other => ("a valid model".to_string(), other.to_string()),
    }
}

impl<'a> Parser<'a> {
    fn peek(&self) -> Option<u8> {
        self.bytes.get(self.pos).copied()
    }

    fn skip_ws(&mut self) {
        while self.peek().is_some_and(|b| b.is_ascii_whitespace()) {
            self.pos += 1;
        }
    }

    /// Describes the token at `at` for "found ...": a quoted word/number/character, or the end.
    fn found_at(&self, at: usize) -> String {
        let Some(rest) = self.text.get(at..) else {
            return "end of input".to_string();
        };
        let mut chars = rest.char_indices();
        let Some((_, c)) = chars.next() else {
            return "end of input".to_string();
        };
        let end = if c.is_ascii_alphanumeric() || c == '.' {
            rest.find(|ch: char| !(ch.is_ascii_alphanumeric() || ch == '_' || ch == '.'))
                .unwrap_or(rest.len())
        } else {
            c.len_utf8()
        };
        format!("{:?}", &rest[..end])
    }

    #[cold]
    fn error_with(
        &self,
        at: usize,
        kind: ParseErrorKind,
        expected: String,
        found: String,
        hint: Option<String>,
    ) -> ModelParseError {
        let at = at.min(self.text.len());
        // offsets only ever stop on ASCII bytes or before the first non-ASCII one, so `at` is a
        // char boundary; fall back to a byte count otherwise
        let column = self.text.get(..at).map_or(at, |s| s.chars().count()) + 1;
        ModelParseError(Box::new(ErrorData {
            input: self.text.to_string(),
            offset: at,
            column,
            expected,
            found,
            hint,
            kind,
        }))
    }

    #[cold]
    fn error(
        &self,
        at: usize,
        kind: ParseErrorKind,
        expected: &str,
        hint: Option<String>,
    ) -> ModelParseError {
        self.error_with(at, kind, expected.to_string(), self.found_at(at), hint)
    }

    #[cold]
    fn unexpected(&self, at: usize, expected: &str) -> ModelParseError {
        self.error(at, ParseErrorKind::Syntax, expected, None)
    }

    fn expect(&mut self, byte: u8, expected: &str) -> Res<()> {
        self.skip_ws();
        if self.peek() == Some(byte) {
            self.pos += 1;
            Ok(())
        } else {
            Err(self.unexpected(self.pos, expected))
        }
    }

    /// `[A-Za-z][A-Za-z0-9_]*`
    fn ident(&mut self) -> Option<(usize, &'a str)> {
        let start = self.pos;
        if !self.peek().is_some_and(|b| b.is_ascii_alphabetic()) {
            return None;
        }
        while self
            .peek()
            .is_some_and(|b| b.is_ascii_alphanumeric() || b == b'_')
        {
            self.pos += 1;
        }
        Some((start, &self.text[start..self.pos]))
    }

    /// `[0-9]+` as a usize in `lo..=hi`, else `kind` error with `expected`.
    fn integer(
        &mut self,
        lo: usize,
        hi: usize,
        kind: ParseErrorKind,
        expected: &str,
    ) -> Res<usize> {
        self.skip_ws();
        let start = self.pos;
        while self.peek().is_some_and(|b| b.is_ascii_digit()) {
            self.pos += 1;
        }
        if start == self.pos {
            return Err(self.unexpected(start, expected));
        }
        // a following '.' or letter makes it a non-integer ("2.5*GM()", "2x")
        if self
            .peek()
            .is_some_and(|b| b == b'.' || b.is_ascii_alphabetic())
        {
            return Err(self.error(start, kind, expected, None));
        }
        match self.text[start..self.pos].parse::<usize>() {
            Ok(v) if (lo..=hi).contains(&v) => Ok(v),
            _ => Err(self.error(start, kind, expected, None)),
        }
    }

    /// One term; `index` is the 0-based index its (first) component will have in the model.
    fn term(&mut self, index: usize) -> Res<(usize, Component)> {
        let mut k = 1;
        if self.peek().is_some_and(|b| b.is_ascii_digit()) {
            k = self.integer(
                1,
                MAX_MULTIPLIER,
                ParseErrorKind::BadMultiplier,
                "a multiplier from 1 to 100",
            )?;
            self.expect(b'*', "\"*\" after the multiplier")?;
            self.skip_ws();
        }
        let Some((name_at, name)) = self.ident() else {
            return Err(self.unexpected(self.pos, &process_list()));
        };
        let upper = name.to_ascii_uppercase();
        let Some(&listed) = KINDS.iter().find(|&&k| spec(k).name == upper) else {
            return Err(self.unknown_process(name_at, name));
        };
        let kind = match &spec(listed).orders {
            None => listed,
            Some(o) => {
                let example = o.example;
                self.expect(b'(', &format!("\"(\" and the order, as in {example}"))?;
                let first = self.order(o)?;
                let (p, q) = match (o.ar, o.ma) {
                    (true, true) => {
                        self.expect(b',', &format!("\",\" and the MA order, as in {example}"))?;
                        (first, self.order(o)?)
                    }
                    (true, false) => (first, 0),
                    _ => (0, first),
                };
                let kind = (o.make)(p, q);
                self.expect(b')', "\")\" after the order")?;
                if let Err(e) = kind.check_orders() {
                    let (expected, found) = ("orders with p + q >= 1".to_string(), kind.name());
                    return Err(self.error_with(
                        name_at,
                        ParseErrorKind::Rule(e),
                        expected,
                        format!("{found:?}"),
                        Some("use WN() for white noise".to_string()),
                    ));
                }
                kind
            }
        };
        let mut values = vec![None; kind.n_params()];
        let after_name = self.pos;
        self.skip_ws();
        if self.peek() == Some(b'(') {
            self.pos += 1;
            self.args(index, kind, &mut values)?;
        } else {
            self.pos = after_name;
        }
        Ok((k, Component { kind, values }))
    }

    /// One order of an order kind (AR/MA/ARMA): `o.min..=MAX_ORDER`.
    fn order(&mut self, o: &Orders) -> Res<usize> {
        self.skip_ws();
        let at = self.pos;
        let expected = format!(
            "an order from {} to {MAX_ORDER}, as in {}",
            o.min, o.example
        );
        if !self.peek().is_some_and(|b| b.is_ascii_digit()) {
            return Err(self.unexpected(at, &expected));
        }
        while self.peek().is_some_and(|b| b.is_ascii_digit()) {
            self.pos += 1;
        }
        if self
            .peek()
            .is_some_and(|b| b == b'.' || b.is_ascii_alphabetic())
        {
            return Err(self.unexpected(at, &expected));
        }
        // digits only, so the text parses unless it overflows usize
        let order = self.text[at..self.pos]
            .parse::<usize>()
            .unwrap_or(usize::MAX);
        if (o.min..=MAX_ORDER).contains(&order) {
            return Ok(order);
        }
        // the kind as far as read: the bad order in the first written slot
        let kind = if o.ar {
            (o.make)(order, 0)
        } else {
            (o.make)(0, order)
        };
        let rule = ModelError::BadOrder {
            kind: kind.name(),
            order,
            expected: o.expected,
        };
        Err(self.error(at, ParseErrorKind::Rule(rule), &expected, None))
    }

    #[cold]
    fn unknown_process(&self, at: usize, name: &str) -> ModelParseError {
        let upper = name.to_ascii_uppercase();
        // "AR2" / "MA3" / "ARMA21" are orders written into the name
        let digits = |prefix: &str| -> Option<&str> {
            upper
                .strip_prefix(prefix)
                .filter(|d| !d.is_empty() && d.bytes().all(|b| b.is_ascii_digit()))
        };
        let suggestion = if let Some(d) = digits("ARMA").filter(|d| d.len() == 2) {
            Some(format!("ARMA({},{})", &d[..1], &d[1..]))
        } else if let Some(d) = digits("AR").filter(|_| !upper.starts_with("ARMA")) {
            Some(format!("AR({d})"))
        } else if let Some(d) = digits("MA") {
            Some(format!("MA({d})"))
        } else if upper == "SARIMA" {
            Some("ARMA(p,q)".to_string())
        } else {
            KINDS
                .iter()
                .map(|&k| {
                    let (n, syntax) = (spec(k).name, spec(k).syntax);
                    // ties go to the name with the same first letter ("GN" -> GM, not WN)
                    let other_start = upper.as_bytes().first() != n.as_bytes().first();
                    (edit_distance(&upper, n), other_start, syntax)
                })
                .filter(|(d, _, _)| *d <= 2)
                .min_by_key(|(d, o, _)| (*d, *o))
                .map(|(_, _, s)| s.to_string())
        };
        let hint = suggestion.as_ref().map(|s| format!("did you mean {s}?"));
        self.error_with(
            at,
            ParseErrorKind::UnknownProcess {
                name: name.to_string(),
                suggestion,
            },
            process_list(),
            format!("{name:?}"),
            hint,
        )
    }

    /// The argument list after `(`, through the closing `)`.
    fn args(&mut self, component: usize, kind: ProcessKind, values: &mut [Option<f64>]) -> Res<()> {
        self.skip_ws();
        if self.peek() == Some(b')') {
            self.pos += 1;
            return Ok(());
        }
        let names = kind.param_names();
        let mut positional = 0;
        let mut named = false;
        loop {
            self.skip_ws();
            let at = self.pos;
            let index;
            if let Some((name_at, name)) = self.ident() {
                let Some(i) = kind.param_index(name) else {
                    return Err(self.error_with(
                        name_at,
                        ParseErrorKind::UnknownParameter {
                            name: name.to_string(),
                            valid: names.clone(),
                        },
                        format!("a parameter of {kind} ({})", names.join(", ")),
                        format!("{name:?}"),
                        None,
                    ));
                };
                if values[i].is_some() {
                    return Err(self.error_with(
                        name_at,
                        ParseErrorKind::DuplicateParameter {
                            name: names[i].clone(),
                        },
                        format!("each parameter of {kind} once"),
                        format!("{:?} again", names[i]),
                        None,
                    ));
                }
                self.expect(b'=', &format!("\"=\" and a value after {:?}", names[i]))?;
                named = true;
                index = i;
            } else if self
                .peek()
                .is_some_and(|b| b.is_ascii_digit() || matches!(b, b'.' | b'+' | b'-'))
            {
                if named {
                    return Err(self.error(
                        at,
                        ParseErrorKind::Syntax,
                        "a parameter name",
                        Some("positional values must come before named ones".to_string()),
                    ));
                }
                if positional >= values.len() {
                    return Err(self.error_with(
                        at,
                        ParseErrorKind::TooManyValues { max: values.len() },
                        format!(
                            "at most {} values for {kind} ({})",
                            values.len(),
                            names.join(", ")
                        ),
                        format!("{} as value {}", self.found_at(at), positional + 1),
                        None,
                    ));
                }
                index = positional;
                positional += 1;
            } else {
                let expected = if named {
                    "a parameter name"
                } else {
                    "a parameter name or a value"
                };
                return Err(self.unexpected(at, expected));
            }
            self.skip_ws();
            let value_at = self.pos;
            let v = self.number()?;
            if let Some(domain) = kind.param_domain(index) {
                if !domain.contains(v) {
                    return Err(self.error_with(
                        value_at,
                        ParseErrorKind::Rule(ModelError::BadParameter {
                            component,
                            kind: kind.name(),
                            name: names[index].clone(),
                            value: v,
                            expected: domain.expected(),
                        }),
                        format!("{} for {} of {kind}", domain.expected(), names[index]),
                        format!("{:?}", &self.text[value_at..self.pos]),
                        None,
                    ));
                }
            }
            values[index] = Some(v);
            self.skip_ws();
            match self.peek() {
                Some(b',') => self.pos += 1,
                Some(b')') => {
                    self.pos += 1;
                    return Ok(());
                }
                _ => return Err(self.unexpected(self.pos, "\",\" or \")\"")),
            }
        }
    }

    /// `[+-] digits [. digits] [(e|E) [+-] digits]`, finite.
    fn number(&mut self) -> Res<f64> {
        let start = self.pos;
        let digits = |p: &mut Self| {
            let s = p.pos;
            while p.peek().is_some_and(|b| b.is_ascii_digit()) {
                p.pos += 1;
            }
            p.pos - s
        };
        if matches!(self.peek(), Some(b'+' | b'-')) {
            self.pos += 1;
        }
        let mut n = digits(self);
        if self.peek() == Some(b'.') {
            self.pos += 1;
            n += digits(self);
        }
        if n == 0 {
            // "-", ".", "+)": point at what is there
            return Err(self.error(start, ParseErrorKind::BadNumber, NUMBER, None));
        }
        if matches!(self.peek(), Some(b'e' | b'E')) {
            self.pos += 1;
            if matches!(self.peek(), Some(b'+' | b'-')) {
                self.pos += 1;
            }
            n = digits(self);
        }
        // letters glued to the number ("1x", "2e3f", "1.2.3") make it malformed
        let glued = |b: u8| b.is_ascii_alphanumeric() || b == b'.' || b == b'_';
        if n == 0 || self.peek().is_some_and(glued) {
            while self.peek().is_some_and(glued) {
                self.pos += 1;
            }
            return Err(self.error_with(
                start,
                ParseErrorKind::BadNumber,
                NUMBER.to_string(),
                format!("{:?}", &self.text[start..self.pos]),
                None,
            ));
        }
        match self.text[start..self.pos].parse::<f64>() {
            Ok(v) if v.is_finite() => Ok(v),
            _ => Err(self.error_with(
                start,
                ParseErrorKind::BadNumber,
                "a finite number".to_string(),
                format!("{:?}", &self.text[start..self.pos]),
                None,
            )),
        }
    }
}

/// Levenshtein distance between two ASCII-uppercased names.
fn edit_distance(a: &str, b: &str) -> usize {
    let b: Vec<char> = b.chars().collect();
    let mut prev: Vec<usize> = (0..=b.len()).collect();
    for (i, ca) in a.chars().enumerate() {
        let mut cur = vec![i + 1; b.len() + 1];
        for (j, &cb) in b.iter().enumerate() {
            let sub = prev[j] + usize::from(ca != cb);
            cur[j + 1] = sub.min(prev[j + 1] + 1).min(cur[j] + 1);
        }
        prev = cur;
    }
    prev[b.len()]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn edit_distance_matches_hand_values() {
        assert_eq!(edit_distance("GN", "GM"), 1);
        assert_eq!(edit_distance("", "WN"), 2);
        assert_eq!(edit_distance("ARMA", "AR"), 2);
        assert_eq!(edit_distance("KITTEN", "SITTING"), 3);
    }
}
