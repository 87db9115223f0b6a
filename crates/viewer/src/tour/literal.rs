//! A lenient reader of JSON and of JavaScript object literals (Marzipano's `data.js`:
//! unquoted keys, single-quoted strings, trailing commas, comments), keeping each value's
//! line so every problem found later can name its place in the file.
//!
//! Bounded: nesting deeper than [`MAX_DEPTH`] is refused (no stack overflow on hostile
//! input), a string longer than [`MAX_STRING_BYTES`] too; numbers are parsed by Rust's `f64` parser (non-finite results refused).

use serde_json::Value;

/// Nesting deeper than this is refused.
pub const MAX_DEPTH: usize = 64;

/// A string longer than this (bytes) is refused ([`lut_core::limits::MAX_TOUR_STRING_BYTES`]).
pub const MAX_STRING_BYTES: usize = lut_core::limits::MAX_TOUR_STRING_BYTES;

/// A value with the line (1-based) where it starts.
#[derive(Debug, Clone, PartialEq)]
pub struct Lit {
    /// The line the value starts on.
    pub line: usize,
    /// The value.
    pub kind: LitKind,
}

/// What a [`Lit`] is.
#[derive(Debug, Clone, PartialEq)]
pub enum LitKind {
    /// `null` (or `undefined`).
    Null,
    /// `true` / `false`.
    Bool(bool),
    /// A finite number.
    Num(f64),
    /// A string.
    Str(String),
    /// An array.
    Arr(Vec<Lit>),
    /// An object: keys in file order (a repeated key: the last wins on lookup, as in
    /// JavaScript).
    Obj(Vec<(String, Lit)>),
}

impl Lit {
    /// The member `key` of an object (the last one of that name), `None` otherwise.
    pub fn get(&self, key: &str) -> Option<&Lit> {
        match &self.kind {
            LitKind::Obj(m) => m.iter().rev().find(|(k, _)| k == key).map(|(_, v)| v),
            _ => None,
        }
    }

    /// A string value.
    pub fn as_str(&self) -> Option<&str> {
        match &self.kind {
            LitKind::Str(s) => Some(s),
            _ => None,
        }
    }

    /// A number value.
    pub fn as_f64(&self) -> Option<f64> {
        match self.kind {
            LitKind::Num(v) => Some(v),
            _ => None,
        }
    }

    /// What kind of value this is, for messages ("a string", "an object", ...).
    pub fn what(&self) -> &'static str {
        match self.kind {
            LitKind::Null => "null",
            LitKind::Bool(_) => "a boolean",
            LitKind::Num(_) => "a number",
            LitKind::Str(_) => "a string",
            LitKind::Arr(_) => "an array",
            LitKind::Obj(_) => "an object",
        }
    }

    /// The value as JSON (kept for members a tour does not interpret, so a saved tour
    /// keeps them).
    pub fn to_json(&self) -> Value {
        match &self.kind {
            LitKind::Null => Value::Null,
            LitKind::Bool(b) => Value::Bool(*b),
            LitKind::Num(v) => serde_json::Number::from_f64(*v)
                .map(Value::Number)
                .unwrap_or(Value::Null),
            LitKind::Str(s) => Value::String(s.clone()),
            LitKind::Arr(a) => Value::Array(a.iter().map(Lit::to_json).collect()),
            LitKind::Obj(m) => {
                Value::Object(m.iter().map(|(k, v)| (k.clone(), v.to_json())).collect())
            }
        }
    }
}

/// A syntax error: its line and what was wrong.
#[derive(Debug, Clone, PartialEq)]
pub struct SyntaxError {
    /// 1-based line.
    pub line: usize,
    /// What was expected or found.
    pub message: String,
}

impl std::fmt::Display for SyntaxError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "line {}: {}", self.line, self.message)
    }
}

/// Parse one value (JSON or a JavaScript object literal) filling the whole text (comments
/// and white space around it allowed).
///
/// # Errors
/// The first syntax error, with its line.
pub fn parse(text: &str) -> Result<Lit, SyntaxError> {
    let mut p = Parser {
        s: text.as_bytes(),
        i: 0,
        line: 1,
    };
    p.skip_ws()?;
    let v = p.value(0)?;
    p.skip_ws()?;
    if p.i < p.s.len() {
        return Err(p.err("text after the end of the value"));
    }
    Ok(v)
}

/// Marzipano's `data.js`: `var APP_DATA = { ... };` (also `const`/`let`/`window.APP_DATA =`),
/// possibly followed by other statements; the object literal is parsed and its line
/// numbers are those of the file.
///
/// # Errors
/// No `APP_DATA =` assignment, or a syntax error in its value.
pub fn parse_app_data(text: &str) -> Result<Lit, SyntaxError> {
    // The first `APP_DATA` assigned (a comment may name it before).
    let assigned = text
        .match_indices("APP_DATA")
        .map(|(at, _)| at)
        .find(|&at| {
            let rest = text[at + "APP_DATA".len()..].trim_start();
            rest.starts_with('=') && !rest.starts_with("==")
        });
    let Some(at) = assigned.or_else(|| text.find("APP_DATA")) else {
        return Err(SyntaxError {
            line: 1,
            message: "no `APP_DATA =` assignment (not a Marzipano data.js)".into(),
        });
    };
    let rest = &text[at + "APP_DATA".len()..];
    let Some(eq) = rest.find('=') else {
        return Err(SyntaxError {
            line: line_of(text, at),
            message: "`APP_DATA` is not assigned a value".into(),
        });
    };
    let start = at + "APP_DATA".len() + eq + 1;
    let mut p = Parser {
        s: text.as_bytes(),
        i: start,
        line: line_of(text, start),
    };
    p.skip_ws()?;
    let v = p.value(0)?;
    // The statement ends here: a `;`, or the end, or another statement.
    Ok(v)
}

fn line_of(text: &str, at: usize) -> usize {
    1 + text.as_bytes()[..at]
        .iter()
        .filter(|&&b| b == b'\n')
        .count()
}

struct Parser<'a> {
    s: &'a [u8],
    i: usize,
    line: usize,
}

impl Parser<'_> {
    fn err(&self, m: impl Into<String>) -> SyntaxError {
        SyntaxError {
            line: self.line,
            message: m.into(),
        }
    }

    fn peek(&self) -> Option<u8> {
        self.s.get(self.i).copied()
    }

    fn bump(&mut self) -> Option<u8> {
        let c = self.peek()?;
        self.i += 1;
        if c == b'\n' {
            self.line += 1;
        }
        Some(c)
    }

    fn skip_ws(&mut self) -> Result<(), SyntaxError> {
        loop {
            match self.peek() {
                Some(b' ' | b'\t' | b'\r' | b'\n') => {
                    self.bump();
                }
                // A byte-order mark.
                Some(0xEF) if self.s[self.i..].starts_with(&[0xEF, 0xBB, 0xBF]) => self.i += 3,
                Some(b'/') if self.s.get(self.i + 1) == Some(&b'/') => {
                    while !matches!(self.peek(), None | Some(b'\n')) {
                        self.bump();
                    }
                }
                Some(b'/') if self.s.get(self.i + 1) == Some(&b'*') => {
                    let line = self.line;
                    self.i += 2;
                    loop {
                        match self.bump() {
                            None => {
                                return Err(SyntaxError {
                                    line,
                                    message: "a comment is not closed".into(),
                                })
                            }
                            Some(b'*') if self.peek() == Some(b'/') => {
                                self.i += 1;
                                break;
                            }
                            _ => {}
                        }
                    }
                }
                _ => return Ok(()),
            }
        }
    }

    fn value(&mut self, depth: usize) -> Result<Lit, SyntaxError> {
        if depth > MAX_DEPTH {
            return Err(self.err(format!("nested deeper than {MAX_DEPTH} levels")));
        }
        let line = self.line;
        let kind = match self.peek() {
            None => return Err(self.err("the file ends where a value was expected")),
            Some(b'{') => self.object(depth)?,
            Some(b'[') => self.array(depth)?,
            Some(q @ (b'"' | b'\'')) => LitKind::Str(self.string(q)?),
            Some(c) if c == b'-' || c == b'+' || c == b'.' || c.is_ascii_digit() => {
                LitKind::Num(self.number()?)
            }
            Some(c) if c.is_ascii_alphabetic() || c == b'_' || c == b'$' => {
                let w = self.word();
                match w.as_str() {
                    "true" => LitKind::Bool(true),
                    "false" => LitKind::Bool(false),
                    "null" | "undefined" => LitKind::Null,
                    _ => {
                        return Err(
                            self.err(format!("unexpected word `{w}` where a value was expected"))
                        )
                    }
                }
            }
            Some(c) => {
                return Err(self.err(format!(
                    "unexpected {} where a value was expected",
                    shown(c)
                )))
            }
        };
        Ok(Lit { line, kind })
    }

    fn word(&mut self) -> String {
        let start = self.i;
        while matches!(self.peek(), Some(c) if c.is_ascii_alphanumeric() || c == b'_' || c == b'$')
        {
            self.i += 1;
        }
        String::from_utf8_lossy(&self.s[start..self.i]).into_owned()
    }

    fn number(&mut self) -> Result<f64, SyntaxError> {
        let start = self.i;
        while matches!(self.peek(), Some(c) if c.is_ascii_alphanumeric() || matches!(c, b'.' | b'-' | b'+'))
        {
            self.i += 1;
        }
        let t = std::str::from_utf8(&self.s[start..self.i]).unwrap_or("?");
        let t2 = t.strip_prefix('+').unwrap_or(t);
        match t2.parse::<f64>() {
            Ok(v) if v.is_finite() => Ok(v),
            Ok(_) => Err(self.err(format!("number {t} is out of range"))),
            Err(_) => Err(self.err(format!("`{t}` is not a number"))),
        }
    }

    fn string(&mut self, quote: u8) -> Result<String, SyntaxError> {
        let line = self.line;
        self.i += 1;
        let mut out: Vec<u8> = Vec::new();
        loop {
            match self.bump() {
                None | Some(b'\n') => {
                    return Err(SyntaxError {
                        line,
                        message: "a string is not closed on its line".into(),
                    })
                }
                Some(c) if c == quote => break,
                Some(b'\\') => match self.bump() {
                    Some(b'n') => out.push(b'\n'),
                    Some(b't') => out.push(b'\t'),
                    Some(b'r') => out.push(b'\r'),
                    Some(b'b') => out.push(8),
                    Some(b'f') => out.push(12),
                    Some(b'u') => {
                        let c = self.hex4()?;
                        // A surrogate pair.
                        let c = if (0xD800..0xDC00).contains(&c)
                            && self.s[self.i..].starts_with(b"\\u")
                        {
                            self.i += 2;
                            let lo = self.hex4()?;
                            0x10000 + ((c - 0xD800) << 10) + (lo.wrapping_sub(0xDC00) & 0x3FF)
                        } else {
                            c
                        };
                        let ch = char::from_u32(c).unwrap_or('\u{FFFD}');
                        let mut b = [0u8; 4];
                        out.extend_from_slice(ch.encode_utf8(&mut b).as_bytes());
                    }
                    Some(b'\n') => {}
                    Some(c) => out.push(c),
                    None => return Err(self.err("a string is not closed")),
                },
                Some(c) => out.push(c),
            }
            if out.len() > MAX_STRING_BYTES {
                return Err(SyntaxError {
                    line,
                    message: format!("a string longer than the limit of {MAX_STRING_BYTES} bytes"),
                });
            }
        }
        String::from_utf8(out).map_err(|_| SyntaxError {
            line,
            message: "a string is not valid UTF-8".into(),
        })
    }

    fn hex4(&mut self) -> Result<u32, SyntaxError> {
        let t = self
            .s
            .get(self.i..self.i + 4)
            .and_then(|b| std::str::from_utf8(b).ok())
            .and_then(|t| u32::from_str_radix(t, 16).ok())
            .ok_or_else(|| self.err("a \\u escape needs four hex digits"))?;
        self.i += 4;
        Ok(t)
    }

    fn array(&mut self, depth: usize) -> Result<LitKind, SyntaxError> {
        self.bump();
        let mut items = Vec::new();
        loop {
            self.skip_ws()?;
            if self.peek() == Some(b']') {
                self.bump();
                return Ok(LitKind::Arr(items));
            }
            items.push(self.value(depth + 1)?);
            self.skip_ws()?;
            match self.bump() {
                Some(b',') => {}
                Some(b']') => return Ok(LitKind::Arr(items)),
                Some(c) => {
                    return Err(self.err(format!("expected , or ] in an array, found {}", shown(c))))
                }
                None => return Err(self.err("the file ends inside an array")),
            }
        }
    }

    fn object(&mut self, depth: usize) -> Result<LitKind, SyntaxError> {
        self.bump();
        let mut members = Vec::new();
        loop {
            self.skip_ws()?;
            let key = match self.peek() {
                Some(b'}') => {
                    self.bump();
                    return Ok(LitKind::Obj(members));
                }
                Some(q @ (b'"' | b'\'')) => self.string(q)?,
                Some(c) if c.is_ascii_alphanumeric() || c == b'_' || c == b'$' => self.word(),
                Some(c) => {
                    return Err(self.err(format!("expected a key in an object, found {}", shown(c))))
                }
                None => return Err(self.err("the file ends inside an object")),
            };
            self.skip_ws()?;
            if self.bump() != Some(b':') {
                return Err(self.err(format!("expected : after the key \"{key}\"")));
            }
            self.skip_ws()?;
            let v = self.value(depth + 1)?;
            members.push((key, v));
            self.skip_ws()?;
            match self.bump() {
                Some(b',') => {}
                Some(b'}') => return Ok(LitKind::Obj(members)),
                Some(c) => {
                    return Err(
                        self.err(format!("expected , or }} in an object, found {}", shown(c)))
                    )
                }
                None => return Err(self.err("the file ends inside an object")),
            }
        }
    }
}

fn shown(c: u8) -> String {
    if c.is_ascii_graphic() {
        format!("`{}`", c as char)
    } else {
        format!("byte 0x{c:02x}")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn json_and_js_literals_with_lines() {
        let v =
            parse("{\n \"a\": 1,\n b: [true, 'x', null,],\n // c\n c: {d: -2.5e1},\n}").unwrap();
        assert_eq!(v.get("a").unwrap().line, 2);
        assert_eq!(v.get("b").unwrap().line, 3);
        assert_eq!(v.get("c").unwrap().get("d").unwrap().as_f64(), Some(-25.0));
        assert_eq!(v.get("c").unwrap().line, 5);
        let j = v.to_json();
        assert_eq!(j["b"][1], "x");
    }

    #[test]
    fn app_data_is_found_and_the_rest_ignored() {
        let t = "// tour\nvar APP_DATA = {\n  scenes: [ { id: \"a\", }, ],\n  name: 'T',\n};\nvar X = 1;\n";
        let v = parse_app_data(t).unwrap();
        assert_eq!(v.get("name").unwrap().as_str(), Some("T"));
        assert_eq!(v.get("scenes").unwrap().line, 3);
    }

    #[test]
    fn errors_name_their_line_and_never_overflow() {
        let e = parse("{\n\"a\": 1,\n\"b\": }").unwrap_err();
        assert_eq!(e.line, 3, "{e}");
        let e = parse("{\"a\": 1e999}").unwrap_err();
        assert!(e.message.contains("out of range"), "{e}");
        let deep = "[".repeat(100_000);
        assert!(parse(&deep).unwrap_err().message.contains("nested deeper"));
        assert!(parse("{\"a\": \"x").is_err());
        assert!(parse("1 2").is_err());
        assert!(parse_app_data("var X = {};").is_err());
        assert_eq!(
            parse("\"\\u00e9\\ud83d\\ude00\"").unwrap().as_str(),
            Some("é😀")
        );
    }

    #[test]
    fn strings_are_bounded_by_the_limit() {
        // A string of the limit reads; one byte more (also through escapes) is refused
        // with the limit in the message, on the string's line.
        let at = "x".repeat(MAX_STRING_BYTES);
        assert_eq!(
            parse(&format!("{{\"a\": \"{at}\"}}"))
                .unwrap()
                .get("a")
                .unwrap()
                .as_str(),
            Some(at.as_str())
        );
        for over in [format!("{at}x"), format!("{at}\\n")] {
            let e = parse(&format!("{{\n\"a\": '{over}'}}")).unwrap_err();
            assert_eq!(e.line, 2, "{e}");
            assert!(e.message.contains(&MAX_STRING_BYTES.to_string()), "{e}");
        }
    }
}
